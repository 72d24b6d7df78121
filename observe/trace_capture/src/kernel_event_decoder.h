#pragma once
// tep_record -> analysis::KernelEvent for the events the kernel recorder enables.

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "hiltwin/traces/kernel_events.h"
#include "tracefs_api.h"

namespace hiltwin::trace_capture {

/// One event the recorder asks tracefs for.
struct KernelEventSource {
  const char* system;
  const char* name;
  analysis::KernelEventKind kind;
};

/// Every event the recorder enables, in the order of kernel_events.h.
[[nodiscard]] const std::vector<KernelEventSource>& KernelEventSources();

/// Turns raw records into KernelEvents, by field name (tep_get_field_val/raw), so a kernel
/// that moves a field still decodes. Keeps the task running on each CPU (from sched_switch),
/// because page_fault_user carries only the faulting pid and the current task is its comm.
class KernelEventDecoder {
 public:
  /// Looks the sources up in `tep` (the formats of this kernel); unknown ones never match.
  explicit KernelEventDecoder(tep_handle* tep);

  /// Appends the record's event to `out` when it is one of the sources.
  void Decode(tep_event* event, tep_record* record, int cpu,
              std::vector<analysis::KernelEvent>& out);

 private:
  struct Known {
    int id;
    analysis::KernelEventKind kind;
  };
  struct Current {
    int pid = -1;
    std::string comm;
  };
  void FillSwitch(tep_event* event, tep_record* record, int cpu, analysis::KernelEvent& out);
  void FillWakeup(tep_event* event, tep_record* record, analysis::KernelEvent& out) const;
  void FillPageFault(tep_event* event, tep_record* record, int cpu,
                     analysis::KernelEvent& out) const;

  tep_handle* tep_;
  std::vector<Known> known_;
  std::unordered_map<int, Current> current_;  // by CPU
};

}  // namespace hiltwin::trace_capture
