// Raw tracefs records to KernelEvents (field meanings in traces/kernel_events.h).
#include "kernel_event_decoder.h"

#include <array>
#include <cstring>

namespace hiltwin::trace_capture {
namespace {

using analysis::KernelEvent;
using analysis::KernelEventKind;

// sched_switch reports a preempted task with a bit above its state bits (TASK_REPORT_MAX,
// 0x100 since Linux 4.14, "R+" in the text output); the state bits are the low byte. Masking
// leaves 0 for a task that was still runnable, as kernel_events.h promises.
constexpr std::int64_t kTaskStateBits = 0xff;

// The kernel's softirq_to_name[] (the vectors' print format); softirq events carry the number.
constexpr std::array<const char*, 10> kSoftirqNames = {
    "HI", "TIMER", "NET_TX", "NET_RX", "BLOCK", "IRQ_POLL", "TASKLET", "SCHED", "HRTIMER", "RCU"};

// A number field by name; tep reads `size` bytes zero-extended, so the kernel's signed fields
// (pid_t, int, long) are sign-extended here (a pid of -1 must not become 4294967295).
std::int64_t Number(tep_event* event, tep_record* record, const char* name,
                    std::int64_t fallback = 0) {
  tep_format_field* field = tep_find_field(event, name);
  unsigned long long raw = 0;
  if (field == nullptr || tep_read_number_field(field, record->data, &raw) != 0) return fallback;
  if ((field->flags & TEP_FIELD_IS_SIGNED) != 0 && field->size > 0 && field->size < 8) {
    const unsigned long long sign = 1ULL << (static_cast<unsigned>(field->size) * 8U - 1U);
    raw = (raw ^ sign) - sign;
  }
  return static_cast<std::int64_t>(raw);
}

int Int(tep_event* event, tep_record* record, const char* name, int fallback = 0) {
  return static_cast<int>(Number(event, record, name, fallback));
}

// A char array (comm[16]) or a __data_loc string (irq name), up to its NUL.
std::string Text(tep_event* event, tep_record* record, const char* name) {
  int length = 0;
  const auto* raw =
      static_cast<const char*>(tep_get_field_raw(nullptr, event, name, record, &length, 0));
  if (raw == nullptr || length <= 0) return {};
  return {raw, ::strnlen(raw, static_cast<std::size_t>(length))};
}

std::string SoftirqName(int vector) {
  if (vector >= 0 && static_cast<std::size_t>(vector) < kSoftirqNames.size()) {
    return kSoftirqNames[static_cast<std::size_t>(vector)];
  }
  return "vec" + std::to_string(vector);
}

}  // namespace

const std::vector<KernelEventSource>& KernelEventSources() {
  static const std::vector<KernelEventSource> sources = {
      {"sched", "sched_switch", KernelEventKind::kSchedSwitch},
      {"sched", "sched_wakeup", KernelEventKind::kSchedWakeup},
      {"irq", "irq_handler_entry", KernelEventKind::kIrqEntry},
      {"irq", "irq_handler_exit", KernelEventKind::kIrqExit},
      {"irq_vectors", "local_timer_entry", KernelEventKind::kLocalTimerEntry},
      {"irq_vectors", "local_timer_exit", KernelEventKind::kLocalTimerExit},
      {"irq", "softirq_entry", KernelEventKind::kSoftirqEntry},
      {"irq", "softirq_exit", KernelEventKind::kSoftirqExit},
      {"exceptions", "page_fault_user", KernelEventKind::kPageFaultUser},
  };
  return sources;
}

KernelEventDecoder::KernelEventDecoder(tep_handle* tep) : tep_(tep) {
  for (const KernelEventSource& source : KernelEventSources()) {
    const tep_event* event = tep_find_event_by_name(tep, source.system, source.name);
    if (event != nullptr) known_.push_back({event->id, source.kind});
  }
}

void KernelEventDecoder::Decode(tep_event* event, tep_record* record, int cpu,
                                std::vector<KernelEvent>& out) {
  const Known* known = nullptr;
  for (const Known& candidate : known_) {
    if (candidate.id == event->id) known = &candidate;
  }
  if (known == nullptr) return;
  KernelEvent& decoded = out.emplace_back();
  decoded.time_ns = static_cast<std::int64_t>(record->ts);  // trace_clock mono: CLOCK_MONOTONIC
  decoded.cpu = cpu;
  decoded.kind = known->kind;
  switch (known->kind) {
    case KernelEventKind::kSchedSwitch:
      FillSwitch(event, record, cpu, decoded);
      break;
    case KernelEventKind::kSchedWakeup:
      FillWakeup(event, record, decoded);
      break;
    case KernelEventKind::kIrqEntry:
      decoded.irq = Int(event, record, "irq", -1);
      decoded.name = Text(event, record, "name");
      break;
    case KernelEventKind::kIrqExit:
      decoded.irq = Int(event, record, "irq", -1);
      break;
    case KernelEventKind::kSoftirqEntry:
    case KernelEventKind::kSoftirqExit:
      decoded.irq = Int(event, record, "vec", -1);
      decoded.name = SoftirqName(decoded.irq);
      break;
    case KernelEventKind::kPageFaultUser:
      FillPageFault(event, record, cpu, decoded);
      break;
    case KernelEventKind::kLocalTimerEntry:
    case KernelEventKind::kLocalTimerExit:
      break;  // the vector is always the timer's
  }
}

void KernelEventDecoder::FillSwitch(tep_event* event, tep_record* record, int cpu,
                                    KernelEvent& out) {
  out.pid = Int(event, record, "prev_pid");
  out.comm = Text(event, record, "prev_comm");
  out.prio = Int(event, record, "prev_prio");
  out.next_pid = Int(event, record, "next_pid");
  out.next_comm = Text(event, record, "next_comm");
  out.next_prio = Int(event, record, "next_prio");
  out.prev_state = Number(event, record, "prev_state") & kTaskStateBits;
  Current& current = current_[cpu];
  current.pid = out.next_pid;
  current.comm = out.next_comm;
}

void KernelEventDecoder::FillWakeup(tep_event* event, tep_record* record, KernelEvent& out) const {
  out.pid = Int(event, record, "pid");
  out.comm = Text(event, record, "comm");
  out.prio = Int(event, record, "prio");
  out.target_cpu = Int(event, record, "target_cpu", -1);
}

void KernelEventDecoder::FillPageFault(tep_event* event, tep_record* record, int cpu,
                                       KernelEvent& out) const {
  out.pid = tep_data_pid(tep_, record);
  out.address = static_cast<std::uint64_t>(Number(event, record, "address"));
  // The faulting task is the one running; its comm is known once a switch to it was seen
  // (the recorder fills the rest from the other events and /proc after the recording).
  const auto current = current_.find(cpu);
  if (current != current_.end() && current->second.pid == out.pid) out.comm = current->second.comm;
}

}  // namespace hiltwin::trace_capture
