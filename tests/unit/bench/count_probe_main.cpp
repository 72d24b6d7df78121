// The probe CountInstructions is tested on: `count_probe N [spin|none]` runs a loop of N
// iterations between two ToggleCounting() calls (nothing with "none"); with "spin", a second
// thread meanwhile spins outside any bracket, which must not be counted.
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <thread>

#include "callgrind_count.h"

namespace {

[[gnu::noinline]] void Loop(unsigned long n) {
  for (unsigned long i = 0; i < n; ++i) asm volatile("" ::: "memory");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  const unsigned long n = std::strtoul(argv[1], nullptr, 10);
  const char* mode = argc > 2 ? argv[2] : "";
  if (std::strcmp(mode, "none") == 0) {
    Loop(n);
    return 0;
  }
  std::atomic<bool> started{false};
  std::atomic<bool> stop{false};
  std::thread spinner;
  if (std::strcmp(mode, "spin") == 0) {
    spinner = std::thread([&] {
      started = true;
      while (!stop) Loop(1000);
    });
    while (!started) std::this_thread::yield();
  }
  hiltwin::bench::ToggleCounting();
  Loop(n);
  std::this_thread::yield();  // in both modes, so the spinner surely runs inside the bracket
  hiltwin::bench::ToggleCounting();
  stop = true;
  if (spinner.joinable()) spinner.join();
  return 0;
}
