// A hostile third process for the wire's trust tests (issue 16): maps a running wire's segment
// and writes garbage of one kind into it, again and again for HOLD_MS (the sides overwrite
// their own fields every cycle, so one write could fall between two reads).
//   hiltwin_io_wire_vandal NAME KIND [HOLD_MS]
// KIND: random  random bytes over the whole segment
//       torn    the newest encoder period's seqlock left odd (half-written) for good
//       index   the ring's newest index far ahead
//       pid     a live unrelated process (init, pid 1) forged into the twin's entry
//       pwm     a PWM word over full scale
//       magic   the header's magic changed
//       period  the newest encoder period rewritten with divider 0 (a consistent seqlock)
// Prints "done" and exits 0; exit 2 for bad arguments, 1 when the segment cannot be mapped.
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <thread>

#include "hiltwin/io/wire_bus.h"
#include "hiltwin/io/wire_segment.h"

namespace {

using hiltwin::io::kEncoderLineHistory;
using hiltwin::io::WireSegment;

void Vandalise(WireSegment& segment, const std::string& kind, std::mt19937_64& random) {
  const std::uint64_t newest = segment.encoder_newest.load();
  auto& slot = segment.encoder_periods[newest % kEncoderLineHistory];
  if (kind == "random") {
    auto* bytes = reinterpret_cast<unsigned char*>(&segment);
    for (std::size_t i = 0; i < sizeof(WireSegment); ++i) {
      bytes[i] = static_cast<unsigned char>(random() & 0xFFU);
    }
  } else if (kind == "torn") {
    slot.sequence.store(2 * newest + 1);
  } else if (kind == "index") {
    segment.encoder_newest.store(newest + 1'000'000'000'000ULL);
  } else if (kind == "pid") {
    segment.twin.pid.store(1);
  } else if (kind == "pwm") {
    segment.pwm_words.store(0x3FFFULL);  // channel 0: magnitude 16383
  } else if (kind == "magic") {
    segment.magic.store(0xBAD);
  } else if (kind == "period") {
    std::array<std::uint64_t, hiltwin::io::wire::kPeriodWords> words{};
    if (hiltwin::lockfree::SeqlockRead(slot, newest, words)) {
      words[1] &= 0xFFFF'FFFF'0000'0000ULL;  // divider 0
      hiltwin::lockfree::SeqlockWrite(slot, newest, words);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  static const char* const kKinds[] = {"random", "torn", "index", "pid", "pwm", "magic", "period"};
  const std::string kind = argc >= 3 ? argv[2] : "";
  bool known = false;
  for (const char* k : kKinds) known = known || kind == k;
  if (argc < 3 || argc > 4 || !known) {
    std::fprintf(stderr,
                 "usage: %s NAME random|torn|index|pid|pwm|magic|period [HOLD_MS]\n", argv[0]);
    return 2;
  }
  const int hold_ms = argc == 4 ? std::atoi(argv[3]) : 300;
  const std::string path = hiltwin::io::WireBus::SegmentName(argv[1]);
  const int fd = ::shm_open(path.c_str(), O_RDWR, 0);
  if (fd < 0) {
    std::fprintf(stderr, "cannot open /dev/shm%s: %s\n", path.c_str(), std::strerror(errno));
    return 1;
  }
  void* map = ::mmap(nullptr, sizeof(WireSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (map == MAP_FAILED) {
    std::fprintf(stderr, "cannot map /dev/shm%s: %s\n", path.c_str(), std::strerror(errno));
    return 1;
  }
  auto& segment = *static_cast<WireSegment*>(map);
  std::mt19937_64 random(16);
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(hold_ms);
  do {
    Vandalise(segment, kind, random);
    // Random bytes and a changed magic need writing once: the sides stop at the next check.
    if (kind == "random" || kind == "magic") break;
    std::this_thread::sleep_for(std::chrono::microseconds(50));
  } while (std::chrono::steady_clock::now() < end);
  ::munmap(map, sizeof(WireSegment));
  std::printf("done\n");
  return 0;
}
