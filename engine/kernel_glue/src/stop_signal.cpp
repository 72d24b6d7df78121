#include "hiltwin/kernel_glue/stop_signal.h"

#include <atomic>
#include <cerrno>
#include <csignal>
#include <system_error>

namespace hiltwin::kernel_glue {
namespace {

// The only state a signal handler touches: a lock-free atomic, which is async-signal-safe
// (a lock-based one could deadlock inside the handler). 0: no stop; otherwise the signal.
std::atomic<int> g_stop_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);
std::atomic<bool> g_handlers_installed{false};

// The latest PauseRequest, as an int (lock-free, so the handler may write it).
std::atomic<int> g_pause_request{0};

extern "C" void OnPauseSignal(int signal_number) {
  g_pause_request.store(static_cast<int>(signal_number == SIGUSR1 ? PauseRequest::kPause
                                                                  : PauseRequest::kResume));
}

extern "C" void OnStopSignal(int signal_number) {
  int expected = 0;
  // Keep the first cause when two different signals arrive.
  g_stop_signal.compare_exchange_strong(expected, signal_number);
}

void Install(int signal_number) {
  struct sigaction action {};
  action.sa_handler = &OnStopSignal;
  sigemptyset(&action.sa_mask);
  // SA_RESETHAND: the second signal takes the default action (terminate). SA_RESTART: library
  // calls outside the loop are not cut short by EINTR; the loop polls the flag instead.
  action.sa_flags = static_cast<int>(SA_RESETHAND | SA_RESTART);
  if (sigaction(signal_number, &action, nullptr) != 0) {
    throw std::system_error(errno, std::generic_category(), "sigaction for stop signals");
  }
}

}  // namespace

void InstallPauseSignalHandlers() {
  for (const int signal_number : {SIGUSR1, SIGUSR2}) {
    struct sigaction action {};
    action.sa_handler = &OnPauseSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;  // repeatable: pause and resume as often as wanted
    if (sigaction(signal_number, &action, nullptr) != 0) {
      throw std::system_error(errno, std::generic_category(), "sigaction for pause signals");
    }
  }
}

PauseRequest TakePauseRequest() noexcept {
  return static_cast<PauseRequest>(g_pause_request.exchange(0));
}

void InstallStopSignalHandlers() {
  // SIGHUP too: a closed terminal or a dropped SSH session must end a run as cleanly as
  // SIGTERM, not kill it with an empty report and its shared memory behind.
  for (const int signal_number : kStopSignals) Install(signal_number);
  g_handlers_installed.store(true);
}

bool StopRequested() noexcept { return g_stop_signal.load(std::memory_order_relaxed) != 0; }

int StopSignal() noexcept { return g_stop_signal.load(std::memory_order_relaxed); }

const char* StopSignalName(int signal_number) noexcept {
  switch (signal_number) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    case -1: return "a stop request";
    default: return "no stop signal";
  }
}

void RequestStop() noexcept {
  int expected = 0;
  g_stop_signal.compare_exchange_strong(expected, -1);
}

void ResetStopRequest() {
  g_stop_signal.store(0);
  if (g_handlers_installed.load()) InstallStopSignalHandlers();
}

}  // namespace hiltwin::kernel_glue
