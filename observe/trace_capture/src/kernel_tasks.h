#pragma once
// The threads a kernel recording saw, with their scheduling class read after the recording.

#include <vector>

#include "hiltwin/traces/kernel_events.h"

namespace hiltwin::trace_capture {

/// Fills the comm of events that lack one (page faults before the faulting task was switched
/// in) from the other events' names for that pid, else from /proc.
void FillMissingComms(std::vector<analysis::KernelEvent>& events);

/// Every pid the events name (not 0, the idle task: it is no thread one can ask about), with
/// its last comm and its policy and rt priority as read now; policy empty when it is gone.
[[nodiscard]] std::vector<analysis::KernelTask> TasksSeen(
    const std::vector<analysis::KernelEvent>& events);

/// "SCHED_FIFO" for SCHED_FIFO, ...; "policy <n>" for one this table does not know.
[[nodiscard]] std::string PolicyName(int policy);

}  // namespace hiltwin::trace_capture
