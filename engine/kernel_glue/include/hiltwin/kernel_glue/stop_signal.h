#pragma once
/// SIGINT/SIGTERM as a stop request: the handler only sets a lock-free flag, which the loop
/// polls once per cycle (scheduler::Executive::SetStopCheck(&StopRequested)), so the current
/// cycle finishes and the run stops cleanly with its report written.
///
/// The handlers are one-shot (SA_RESETHAND): the first SIGINT or SIGTERM asks for a stop, a
/// second one of the same signal gets the default action and kills the process, so a stuck
/// program can always be stopped with a second Ctrl-C.

namespace hiltwin::kernel_glue {

/// Installs the SIGINT and SIGTERM handlers (again, if already installed: this re-arms them).
/// Throws std::system_error when sigaction fails.
void InstallStopSignalHandlers();

/// True once SIGINT or SIGTERM was received (or RequestStop was called). Async-signal-safe.
[[nodiscard]] bool StopRequested() noexcept;

/// The signal that asked for the stop (SIGINT, SIGTERM), 0 for none, -1 for RequestStop.
[[nodiscard]] int StopSignal() noexcept;

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
