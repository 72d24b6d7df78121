#pragma once
/// SIGINT/SIGTERM/SIGHUP as a stop request: the handler only sets a lock-free flag, which the
/// loop polls once per cycle (scheduler::Executive::SetStopCheck(&StopRequested)), so the
/// current cycle finishes and the run stops cleanly with its report written. SIGHUP (a closed
/// terminal, a dropped SSH session) is a stop like SIGTERM.
///
/// The handlers are one-shot (SA_RESETHAND): the first of these signals asks for a stop, a
/// second one of the same signal gets the default action and kills the process, so a stuck
/// program can always be stopped with a second Ctrl-C.

#include <array>
#include <csignal>

namespace hiltwin::kernel_glue {

/// The signals that ask for a stop.
inline constexpr std::array<int, 3> kStopSignals = {SIGINT, SIGTERM, SIGHUP};

/// Installs the handlers of kStopSignals (again, if already installed: this re-arms them).
/// Throws std::system_error when sigaction fails.
void InstallStopSignalHandlers();

/// True once a stop signal was received (or RequestStop was called). Async-signal-safe.
[[nodiscard]] bool StopRequested() noexcept;

/// The signal that asked for the stop (SIGINT, SIGTERM, SIGHUP), 0 for none, -1 for
/// RequestStop.
[[nodiscard]] int StopSignal() noexcept;

/// "SIGINT", "SIGTERM", "SIGHUP" for a StopSignal(); "a stop request" for -1, "no stop signal"
/// for 0 (and any other number).
[[nodiscard]] const char* StopSignalName(int signal_number) noexcept;

/// Asks for a stop from code (e.g. a command or a watchdog) the same way a signal does.
void RequestStop() noexcept;

/// Clears the request and re-arms the handlers if they were installed (for tests and for
/// programs that run several loops in turn).
void ResetStopRequest();

/// A pause or resume asked for by signal: SIGUSR1 pauses, SIGUSR2 resumes (`kill -USR1 PID`).
enum class PauseRequest { kNone, kPause, kResume };

/// Installs the SIGUSR1/SIGUSR2 handlers, which only record the latest request in a lock-free
/// flag. Throws std::system_error when sigaction fails.
void InstallPauseSignalHandlers();

/// The latest pause or resume request since the last call, and clears it. Async-signal-safe.
[[nodiscard]] PauseRequest TakePauseRequest() noexcept;

}  // namespace hiltwin::kernel_glue
