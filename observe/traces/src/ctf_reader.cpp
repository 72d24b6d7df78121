// ReadCtfTrace: an LTTng CTF trace of the `hiltwin` provider, read with libbabeltrace2's graph
// API: source.ctf.fs (every stream of every trace below the folder) -> filter.utils.muxer (one
// sequence in time order) -> a simple sink of ours that decodes each hiltwin event into the
// TimingTrace. The babeltrace2 CLI's text is never parsed.
//
// C callbacks must not throw: the sink keeps the first exception and returns an error status,
// and ReadCtfTrace rethrows it once the graph has stopped.
#include <babeltrace2/babeltrace.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include "hiltwin/lifecycle/lifecycle.h"
#include "hiltwin/traces/trace_readers.h"
#include "hiltwin/tracing/trace_codes.h"
#include "trace_reading.h"

namespace hiltwin::analysis {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kProvider = "hiltwin:";
/// The key of the one process of a trace recorded without the vpid context.
constexpr std::int64_t kNoVpid = -1;
// Codes of the lifecycle enums, from their last enumerator (lifecycle.h has no count).
constexpr std::uint64_t kStateCount =
    static_cast<std::uint64_t>(lifecycle::State::kSafeStop) + 1;
constexpr std::uint64_t kEventCount =
    static_cast<std::uint64_t>(lifecycle::Event::kPeerStopped) + 1;
/// bt_graph_run returning AGAIN this often in a row (1 ms apart) means it will not finish.
constexpr int kMaxGraphRetries = 10'000;

struct GraphUnref {
  void operator()(bt_graph* graph) const noexcept { bt_graph_put_ref(graph); }
};
struct PluginUnref {
  void operator()(const bt_plugin* plugin) const noexcept { bt_plugin_put_ref(plugin); }
};
struct ValueUnref {
  void operator()(bt_value* value) const noexcept { bt_value_put_ref(value); }
};
struct ErrorRelease {
  void operator()(const bt_error* error) const noexcept { bt_error_release(error); }
};
using GraphRef = std::unique_ptr<bt_graph, GraphUnref>;
using PluginRef = std::unique_ptr<const bt_plugin, PluginUnref>;
using ValueRef = std::unique_ptr<bt_value, ValueUnref>;

std::string OneLine(const char* text) {
  std::string line = text == nullptr ? "" : text;
  for (char& c : line) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return line;
}

/// The causes of this thread's libbabeltrace2 error, the first (most specific) first, joined
/// by "; ". The library's own causes (component addresses and statuses) are left out when a
/// component said what was wrong: the component's are the ones that name the stream file.
std::string TakeBabeltraceError() {
  const std::unique_ptr<const bt_error, ErrorRelease> error(bt_current_thread_take_error());
  if (!error) return "libbabeltrace2 gave no reason";
  std::string all;
  std::string from_components;
  const auto append = [](std::string& to, const std::string& message) {
    if (message.empty()) return;
    if (!to.empty()) to += "; ";
    to += message;
  };
  const std::uint64_t count = bt_error_get_cause_count(error.get());
  for (std::uint64_t i = 0; i < count; ++i) {
    const bt_error_cause* cause = bt_error_borrow_cause_by_index(error.get(), i);
    const std::string message = OneLine(bt_error_cause_get_message(cause));
    append(all, message);
    if (bt_error_cause_get_actor_type(cause) != BT_ERROR_CAUSE_ACTOR_TYPE_UNKNOWN) {
      append(from_components, message);
    }
  }
  if (!from_components.empty()) return from_components;
  return all.empty() ? "libbabeltrace2 gave no reason" : all;
}

/// CLOCK_MONOTONIC ns of an event. Not bt_clock_snapshot_get_ns_from_origin: LTTng gives its
/// clock class an offset to the Unix epoch, and these times must line up with the executive's
/// own and the kernel's (CLOCK_MONOTONIC, timing_trace.h), so the offset stays out.
std::optional<std::int64_t> MonotonicNsOf(const bt_message* message) {
  if (bt_message_event_borrow_stream_class_default_clock_class_const(message) == nullptr) {
    return std::nullopt;
  }
  const bt_clock_snapshot* snapshot = bt_message_event_borrow_default_clock_snapshot_const(message);
  const std::uint64_t cycles = bt_clock_snapshot_get_value(snapshot);
  const std::uint64_t frequency_hz =
      bt_clock_class_get_frequency(bt_clock_snapshot_borrow_clock_class_const(snapshot));
  constexpr std::uint64_t kNsPerS = 1'000'000'000;
  std::uint64_t ns = cycles;
  if (frequency_hz != kNsPerS && frequency_hz != 0) {
    __extension__ using Wide = unsigned __int128;
    const Wide wide = static_cast<Wide>(cycles / frequency_hz) * kNsPerS +
                      static_cast<Wide>(cycles % frequency_hz) * kNsPerS / frequency_hz;
    if (wide > static_cast<Wide>(INT64_MAX)) return std::nullopt;
    ns = static_cast<std::uint64_t>(wide);
  }
  if (!std::in_range<std::int64_t>(ns)) return std::nullopt;
  return static_cast<std::int64_t>(ns);
}

/// Where an event is, for messages: "DIR: event #N in time order (hiltwin:cycle, vpid P)".
struct EventPlace {
  const std::string* dir = nullptr;
  std::uint64_t number = 0;  ///< 1-based, over every event of the trace, as babeltrace2 lists them
  std::string_view name;
  std::int64_t vpid = kNoVpid;

  [[nodiscard]] std::string Where() const {
    std::string where =
        *dir + ": event #" + std::to_string(number) + " in time order (" + std::string(name);
    if (vpid != kNoVpid) where += ", vpid " + std::to_string(vpid);
    return where + ")";
  }
};

/// One event's payload fields, read by name into the integer type the reader keeps.
class Payload {
 public:
  Payload(const bt_event* event, const EventPlace& place)
      : fields_(bt_event_borrow_payload_field_const(event)), place_(place) {}

  template <typename T>
  [[nodiscard]] T Get(const char* name) const {
    const bt_field* field =
        fields_ == nullptr ? nullptr
                           : bt_field_structure_borrow_member_field_by_name_const(fields_, name);
    if (field == nullptr) {
      throw TraceReadError(place_.Where() + " has no field `" + name +
                           "`: the trace was recorded by another hiltwin version");
    }
    const bt_field_class_type type = bt_field_get_class_type(field);
    std::string text;
    if (bt_field_class_type_is(type, BT_FIELD_CLASS_TYPE_UNSIGNED_INTEGER)) {
      const std::uint64_t value = bt_field_integer_unsigned_get_value(field);
      if (std::in_range<T>(value)) return static_cast<T>(value);
      text = std::to_string(value);
    } else if (bt_field_class_type_is(type, BT_FIELD_CLASS_TYPE_SIGNED_INTEGER)) {
      const std::int64_t value = bt_field_integer_signed_get_value(field);
      if (std::in_range<T>(value)) return static_cast<T>(value);
      text = std::to_string(value);
    } else {
      throw TraceReadError(place_.Where() + ": field `" + name + "` is not an integer");
    }
    throw TraceReadError(place_.Where() + ": field `" + name + "` = " + text + " is out of range");
  }

  /// A code field, refused when it is `count` or more (a newer hiltwin's code, or garbage).
  [[nodiscard]] std::int64_t Code(const char* name, std::uint64_t count) const {
    const auto code = Get<std::uint64_t>(name);
    if (code >= count) {
      throw TraceReadError(place_.Where() + ": unknown " + name + " code " + std::to_string(code) +
                           " (known: 0 to " + std::to_string(count - 1) +
                           "); was it recorded by a newer hiltwin?");
    }
    return static_cast<std::int64_t>(code);
  }

  [[nodiscard]] const EventPlace& place() const noexcept { return place_; }

 private:
  const bt_field* fields_;
  const EventPlace& place_;
};

/// The vpid context field of an event, when the session added it.
std::int64_t VpidOf(const bt_event* event) {
  const bt_field* context = bt_event_borrow_common_context_field_const(event);
  if (context == nullptr || bt_field_get_class_type(context) != BT_FIELD_CLASS_TYPE_STRUCTURE) {
    return kNoVpid;
  }
  const bt_field* vpid = bt_field_structure_borrow_member_field_by_name_const(context, "vpid");
  if (vpid == nullptr) return kNoVpid;
  const bt_field_class_type type = bt_field_get_class_type(vpid);
  if (bt_field_class_type_is(type, BT_FIELD_CLASS_TYPE_SIGNED_INTEGER)) {
    return bt_field_integer_signed_get_value(vpid);
  }
  if (bt_field_class_type_is(type, BT_FIELD_CLASS_TYPE_UNSIGNED_INTEGER)) {
    const std::uint64_t value = bt_field_integer_unsigned_get_value(vpid);
    return std::in_range<std::int64_t>(value) ? static_cast<std::int64_t>(value) : kNoVpid;
  }
  return kNoVpid;
}

/// What the trace holds of one process until the reader knows which process it keeps.
struct ProcessTrace {
  TimingTrace trace;
  bool loop_started = false;
  bool later_run = false;  ///< a second loop_start: what follows belongs to another run
  std::optional<std::uint64_t> first_cycle_event;  ///< event number of its first cycle
};

/// Turns the time-ordered messages into the TimingTrace of one process.
class TraceBuilder {
 public:
  /// `pid` > 0: keep that process; otherwise the first to start its loop.
  TraceBuilder(const std::string& dir, int pid) : dir_(dir) {
    if (pid > 0) chosen_ = pid;
  }

  void OnMessage(const bt_message* message);
  [[nodiscard]] TimingTrace Finish();

 private:
  void OnEvent(const bt_message* message);
  /// The process an event of `vpid` goes to; null when it is left out.
  ProcessTrace* Route(std::int64_t vpid, bool loop_start);
  static void Apply(ProcessTrace& process, std::string_view name, const Payload& payload,
                    std::int64_t time_ns);
  static void OnLoopStart(ProcessTrace& process, const Payload& payload);
  static void OnQosRule(TimingTrace& trace, const Payload& payload);
  static void OnCycle(ProcessTrace& process, const Payload& payload);
  /// The TracedEvent kinds; other names (a newer hiltwin's events) are skipped.
  static void OnRareEvent(TimingTrace& trace, std::string_view name, const Payload& payload,
                          std::int64_t time_ns);

  const std::string& dir_;
  std::map<std::int64_t, ProcessTrace> processes_;
  std::optional<std::int64_t> chosen_;  ///< vpid of the first process to start its loop
  std::set<std::int64_t> others_;       ///< vpids of the processes left out
  std::uint64_t events_ = 0;
  std::uint64_t discarded_events_ = 0;
  std::uint64_t discarded_packets_ = 0;
};

void TraceBuilder::OnMessage(const bt_message* message) {
  std::uint64_t count = 0;
  switch (bt_message_get_type(message)) {
    case BT_MESSAGE_TYPE_EVENT:
      OnEvent(message);
      break;
    case BT_MESSAGE_TYPE_DISCARDED_EVENTS:
      // Per stream, not per process: with per-user buffers every process shares the streams.
      if (bt_message_discarded_events_get_count(message, &count) ==
          BT_PROPERTY_AVAILABILITY_AVAILABLE) {
        discarded_events_ += count;
      }
      break;
    case BT_MESSAGE_TYPE_DISCARDED_PACKETS:
      if (bt_message_discarded_packets_get_count(message, &count) ==
          BT_PROPERTY_AVAILABILITY_AVAILABLE) {
        discarded_packets_ += count;
      }
      break;
    default:
      break;
  }
}

void TraceBuilder::OnEvent(const bt_message* message) {
  ++events_;
  const bt_event* event = bt_message_event_borrow_event_const(message);
  const char* raw_name = bt_event_class_get_name(bt_event_borrow_class_const(event));
  const std::string_view name = raw_name == nullptr ? std::string_view() : raw_name;
  if (!name.starts_with(kProvider)) return;
  const std::string_view short_name = name.substr(kProvider.size());
  const std::int64_t vpid = VpidOf(event);
  ProcessTrace* process = Route(vpid, short_name == "loop_start");
  if (process == nullptr) return;
  const EventPlace place{&dir_, events_, name, vpid};
  const Payload payload(event, place);
  Apply(*process, short_name, payload, MonotonicNsOf(message).value_or(0));
}

ProcessTrace* TraceBuilder::Route(std::int64_t vpid, bool loop_start) {
  if (chosen_ && vpid != *chosen_) {
    others_.insert(vpid);
    return nullptr;
  }
  if (loop_start && !chosen_) {
    // The first process to start its loop is the one kept; nothing earlier can overtake it.
    chosen_ = vpid;
    for (auto it = processes_.begin(); it != processes_.end();) {
      if (it->first == vpid) {
        ++it;
        continue;
      }
      others_.insert(it->first);
      it = processes_.erase(it);
    }
  }
  ProcessTrace& process = processes_[vpid];
  if (loop_start && process.loop_started && !process.later_run) {
    process.later_run = true;  // e.g. `hiltwin tune`: one process, several runs
  }
  if (process.later_run) {
    if (loop_start) ++process.trace.other_runs;
    return nullptr;
  }
  return &process;
}

void TraceBuilder::Apply(ProcessTrace& process, std::string_view name, const Payload& payload,
                         std::int64_t time_ns) {
  if (name == "cycle") {
    OnCycle(process, payload);
  } else if (name == "loop_start") {
    OnLoopStart(process, payload);
  } else if (name == "qos_rule") {
    OnQosRule(process.trace, payload);
  } else if (name == "loop_end") {
    process.trace.complete = true;
  } else {
    OnRareEvent(process.trace, name, payload, time_ns);
  }
}

void TraceBuilder::OnLoopStart(ProcessTrace& process, const Payload& payload) {
  TimingTrace& trace = process.trace;
  process.loop_started = true;
  trace.period_ns = payload.Get<std::int64_t>("period_ns");
  trace.deadline_ns = payload.Get<std::int64_t>("deadline_ns");
  trace.planned_cycles = payload.Get<std::uint64_t>("planned_cycles");
  LoopThread loop;
  loop.tid = payload.Get<int>("tid");
  loop.cpu = payload.Get<int>("cpu");
  loop.policy = payload.Get<int>("policy");
  loop.priority = payload.Get<int>("priority");
  trace.loop = loop;
  if (trace.period_ns <= 0 || trace.deadline_ns <= 0) {
    throw TraceReadError(payload.place().Where() + ": period_ns " +
                         std::to_string(trace.period_ns) + " and deadline_ns " +
                         std::to_string(trace.deadline_ns) + " must be positive");
  }
}

void TraceBuilder::OnQosRule(TimingTrace& trace, const Payload& payload) {
  const auto index = payload.Get<std::uint32_t>("rule");
  if (index != trace.rules.size()) {
    throw TraceReadError(payload.place().Where() + ": rule " + std::to_string(index) + " after " +
                         std::to_string(trace.rules.size()) +
                         " rules; hiltwin:qos_rule events come in rule order from 0");
  }
  trace.rules.push_back(
      detail::DecodeRule(payload.Get<std::uint64_t>("kind"), payload.Get<std::uint32_t>("m"),
                         payload.Get<std::uint32_t>("k"), payload.Get<std::uint32_t>("n"),
                         payload.Get<std::uint32_t>("max_miss_ppm"), payload.place().Where()));
}

void TraceBuilder::OnCycle(ProcessTrace& process, const Payload& payload) {
  TracedCycle cycle;
  scheduler::TimingSample& sample = cycle.sample;
  sample.cycle = payload.Get<std::uint64_t>("k");
  sample.release_ns = payload.Get<std::int64_t>("release_ns");
  sample.wake_ns = payload.Get<std::int64_t>("wake_ns");
  sample.start_ns = payload.Get<std::int64_t>("start_ns");
  sample.end_ns = payload.Get<std::int64_t>("end_ns");
  sample.io_ns = payload.Get<std::int64_t>("io_ns");
  sample.releases_skipped = payload.Get<std::uint32_t>("skipped");
  sample.missed = payload.Code("missed", 2) == 1;
  cycle.judged = payload.Code("judged", 2) == 1;
  std::vector<TracedCycle>& cycles = process.trace.cycles;
  if (!cycles.empty() && sample.cycle <= cycles.back().sample.cycle) {
    throw TraceReadError(payload.place().Where() + ": cycle k = " + std::to_string(sample.cycle) +
                         " after k = " + std::to_string(cycles.back().sample.cycle) +
                         "; a process's cycles must come in increasing k");
  }
  if (!process.first_cycle_event) process.first_cycle_event = payload.place().number;
  cycles.push_back(cycle);
}

void TraceBuilder::OnRareEvent(TimingTrace& trace, std::string_view name, const Payload& payload,
                               std::int64_t time_ns) {
  TracedEvent event;
  event.time_ns = time_ns;
  if (name == "deadline_miss") {
    event.kind = TracedEventKind::kDeadlineMiss;
    event.a = payload.Get<std::int64_t>("lateness_ns");
  } else if (name == "overrun_injected") {
    event.kind = TracedEventKind::kOverrunInjected;
    event.a = payload.Get<std::int64_t>("extra_ns");
  } else if (name == "qos_violation") {
    event.kind = TracedEventKind::kQosViolation;
    event.a = payload.Get<std::int64_t>("rule");
    event.b = payload.Get<std::int64_t>("violations");
  } else if (name == "state_transition") {
    event.kind = TracedEventKind::kStateTransition;
    event.a = payload.Code("from", kStateCount);
    event.b = payload.Code("to", kStateCount);
    event.c = payload.Code("event", kEventCount);
  } else if (name == "io_error") {
    event.kind = TracedEventKind::kIoError;
    event.a = payload.Code("kind", tracing::kIoErrorKindCount);
  } else {
    return;  // before reading k: a newer hiltwin's event may not have one
  }
  event.k = payload.Get<std::uint64_t>("k");
  trace.events.push_back(event);
}

TimingTrace TraceBuilder::Finish() {
  if (!chosen_) {
    // No loop_start (the session began after the loop did): the first process to run a cycle.
    std::optional<std::uint64_t> first;
    for (const auto& [vpid, process] : processes_) {
      if (process.first_cycle_event && (!first || *process.first_cycle_event < *first)) {
        first = process.first_cycle_event;
        chosen_ = vpid;
      }
    }
  }
  const auto it = chosen_ ? processes_.find(*chosen_) : processes_.end();
  if (it == processes_.end() || it->second.trace.cycles.empty()) {
    throw TraceReadError(
        dir_ + ": the LTTng trace holds no hiltwin:cycle event" +
        (chosen_ && *chosen_ != kNoVpid
             ? " of process " + std::to_string(*chosen_) + " (the first to start its loop)"
             : std::string()) +
        "; was `hiltwin:*` enabled (lttng enable-event --userspace "
        "'hiltwin:*') while the run was going?");
  }
  for (const auto& [vpid, process] : processes_) {
    if (vpid != *chosen_) others_.insert(vpid);
  }
  TimingTrace trace = std::move(it->second.trace);
  trace.source = TraceSource::kLttng;
  trace.path = dir_;
  trace.discarded_events = discarded_events_;
  trace.discarded_packets = discarded_packets_;
  trace.pid = *chosen_ == kNoVpid ? 0 : static_cast<int>(*chosen_);
  trace.other_processes = static_cast<std::uint32_t>(others_.size());
  return trace;
}

/// The sink's user data: where events go, and the first exception a callback caught.
struct SinkState {
  TraceBuilder* builder = nullptr;
  std::exception_ptr failure;
};

bt_graph_simple_sink_component_consume_func_status Consume(bt_message_iterator* iterator,
                                                           void* user_data) noexcept {
  auto& sink = *static_cast<SinkState*>(user_data);
  bt_message_array_const messages = nullptr;
  std::uint64_t count = 0;
  switch (bt_message_iterator_next(iterator, &messages, &count)) {
    case BT_MESSAGE_ITERATOR_NEXT_STATUS_OK:
      break;
    case BT_MESSAGE_ITERATOR_NEXT_STATUS_END:
      return BT_GRAPH_SIMPLE_SINK_COMPONENT_CONSUME_FUNC_STATUS_END;
    case BT_MESSAGE_ITERATOR_NEXT_STATUS_AGAIN:
      return BT_GRAPH_SIMPLE_SINK_COMPONENT_CONSUME_FUNC_STATUS_AGAIN;
    case BT_MESSAGE_ITERATOR_NEXT_STATUS_MEMORY_ERROR:
      return BT_GRAPH_SIMPLE_SINK_COMPONENT_CONSUME_FUNC_STATUS_MEMORY_ERROR;
    default:
      return BT_GRAPH_SIMPLE_SINK_COMPONENT_CONSUME_FUNC_STATUS_ERROR;
  }
  std::uint64_t i = 0;
  try {
    for (; i < count; ++i) {
      sink.builder->OnMessage(messages[i]);
      bt_message_put_ref(messages[i]);
    }
  } catch (...) {
    sink.failure = std::current_exception();
    for (; i < count; ++i) bt_message_put_ref(messages[i]);
    return BT_GRAPH_SIMPLE_SINK_COMPONENT_CONSUME_FUNC_STATUS_ERROR;
  }
  return BT_GRAPH_SIMPLE_SINK_COMPONENT_CONSUME_FUNC_STATUS_OK;
}

/// source.ctf.fs -> filter.utils.muxer -> our sink. The plugins stay loaded while the graph
/// lives (members are destroyed in reverse order: the graph first).
class CtfGraph {
 public:
  /// `traces`: the folders below `dir` that hold one CTF trace each.
  CtfGraph(const std::string& dir, const std::vector<std::string>& traces, SinkState& sink);
  /// Runs the graph to its end; throws TraceReadError with libbabeltrace2's reasons.
  void Run();

 private:
  [[nodiscard]] PluginRef FindPlugin(const char* name) const;
  [[noreturn]] void Fail(const std::string& what) const;
  const bt_component_source* AddSource(const std::vector<std::string>& traces);
  const bt_component_filter* AddMuxer();
  void Connect(const bt_component_source* source, const bt_component_filter* muxer,
               const bt_component_sink* sink);

  const std::string& dir_;
  SinkState& sink_;
  PluginRef ctf_;
  PluginRef utils_;
  GraphRef graph_;
};

CtfGraph::CtfGraph(const std::string& dir, const std::vector<std::string>& traces, SinkState& sink)
    : dir_(dir),
      sink_(sink),
      ctf_(FindPlugin("ctf")),
      utils_(FindPlugin("utils")),
      graph_(bt_graph_create(0)) {
  if (!graph_) throw std::bad_alloc();
  const bt_component_source* source = AddSource(traces);
  const bt_component_filter* muxer = AddMuxer();
  const bt_component_sink* own = nullptr;
  if (bt_graph_add_simple_sink_component(graph_.get(), "hiltwin-trace-reader", nullptr, Consume,
                                         nullptr, &sink_,
                                         &own) != BT_GRAPH_ADD_COMPONENT_STATUS_OK) {
    Fail("cannot add the reader's sink");
  }
  Connect(source, muxer, own);
}

PluginRef CtfGraph::FindPlugin(const char* name) const {
  const bt_plugin* plugin = nullptr;
  // Environment, user and system directories and static plugins; a broken plugin elsewhere
  // must not stop us, so load errors are not fatal.
  const bt_plugin_find_status status =
      bt_plugin_find(name, BT_TRUE, BT_TRUE, BT_TRUE, BT_TRUE, BT_FALSE, &plugin);
  if (status != BT_PLUGIN_FIND_STATUS_OK || plugin == nullptr) {
    bt_current_thread_clear_error();
    throw TraceReadError("cannot read the LTTng trace in " + dir_ + ": libbabeltrace2's `" + name +
                         "` plugin is not installed (Debian: apt-get install babeltrace2)");
  }
  return PluginRef(plugin);
}

void CtfGraph::Fail(const std::string& what) const {
  throw TraceReadError("cannot read the LTTng trace in " + dir_ + ": " + what + ": " +
                       TakeBabeltraceError());
}

const bt_component_source* CtfGraph::AddSource(const std::vector<std::string>& traces) {
  const bt_component_class_source* fs_class =
      bt_plugin_borrow_source_component_class_by_name_const(ctf_.get(), "fs");
  if (fs_class == nullptr) Fail("the ctf plugin has no `fs` source");
  const ValueRef params(bt_value_map_create());
  bt_value* inputs = nullptr;
  if (!params || bt_value_map_insert_empty_array_entry(params.get(), "inputs", &inputs) !=
                     BT_VALUE_MAP_INSERT_ENTRY_STATUS_OK) {
    throw std::bad_alloc();
  }
  // One source for every trace: it merges those of one tracing session (same UUID).
  for (const std::string& trace : traces) {
    if (bt_value_array_append_string_element(inputs, trace.c_str()) !=
        BT_VALUE_ARRAY_APPEND_ELEMENT_STATUS_OK) {
      throw std::bad_alloc();
    }
  }
  const bt_component_source* source = nullptr;
  // A truncated or damaged stream file is found here: source.ctf.fs indexes every packet.
  if (bt_graph_add_source_component(graph_.get(), fs_class, "source-ctf-fs", params.get(),
                                    bt_logging_get_global_level(),
                                    &source) != BT_GRAPH_ADD_COMPONENT_STATUS_OK) {
    Fail("source.ctf.fs refused it (a stream file truncated or damaged?)");
  }
  return source;
}

const bt_component_filter* CtfGraph::AddMuxer() {
  const bt_component_class_filter* muxer_class =
      bt_plugin_borrow_filter_component_class_by_name_const(utils_.get(), "muxer");
  if (muxer_class == nullptr) Fail("the utils plugin has no `muxer` filter");
  const bt_component_filter* muxer = nullptr;
  if (bt_graph_add_filter_component(graph_.get(), muxer_class, "muxer", nullptr,
                                    bt_logging_get_global_level(),
                                    &muxer) != BT_GRAPH_ADD_COMPONENT_STATUS_OK) {
    Fail("cannot add filter.utils.muxer");
  }
  return muxer;
}

void CtfGraph::Connect(const bt_component_source* source, const bt_component_filter* muxer,
                       const bt_component_sink* sink) {
  // One output port per stream; the muxer adds a free input port each time one is connected.
  const std::uint64_t streams = bt_component_source_get_output_port_count(source);
  for (std::uint64_t i = 0; i < streams; ++i) {
    const std::uint64_t free_port = bt_component_filter_get_input_port_count(muxer) - 1;
    if (bt_graph_connect_ports(
            graph_.get(), bt_component_source_borrow_output_port_by_index_const(source, i),
            bt_component_filter_borrow_input_port_by_index_const(muxer, free_port),
            nullptr) != BT_GRAPH_CONNECT_PORTS_STATUS_OK) {
      Fail("cannot connect stream " + std::to_string(i) + " to the muxer");
    }
  }
  if (bt_graph_connect_ports(graph_.get(),
                             bt_component_filter_borrow_output_port_by_index_const(muxer, 0),
                             bt_component_sink_borrow_input_port_by_index_const(sink, 0),
                             nullptr) != BT_GRAPH_CONNECT_PORTS_STATUS_OK) {
    Fail("cannot connect the muxer to the reader's sink");
  }
}

void CtfGraph::Run() {
  bt_graph_run_status status = bt_graph_run(graph_.get());
  for (int again = 0; status == BT_GRAPH_RUN_STATUS_AGAIN; ++again) {
    if (again == kMaxGraphRetries) {
      throw TraceReadError("cannot read the LTTng trace in " + dir_ +
                           ": libbabeltrace2 kept asking to try again; is the session still "
                           "recording into it? Stop it (lttng stop) first");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    status = bt_graph_run(graph_.get());
  }
  if (sink_.failure) {
    bt_current_thread_clear_error();
    std::rethrow_exception(sink_.failure);
  }
  if (status == BT_GRAPH_RUN_STATUS_MEMORY_ERROR) {
    bt_current_thread_clear_error();
    throw std::bad_alloc();
  }
  if (status != BT_GRAPH_RUN_STATUS_OK) Fail("reading its streams failed (a stream file damaged?)");
}

/// The CTF traces below `dir`: every folder with a `metadata` file, in name order. LTTng puts
/// one per user (or process) and ABI under DIR/ust/; source.ctf.fs wants each named.
std::vector<std::string> FindCtfTraces(const fs::path& dir) {
  std::vector<std::string> traces;
  std::error_code error;
  fs::recursive_directory_iterator it(dir, fs::directory_options::skip_permission_denied, error);
  for (; !error && it != fs::recursive_directory_iterator(); it.increment(error)) {
    std::error_code type_error;
    if (it->path().filename() == "metadata" && it->is_regular_file(type_error)) {
      traces.push_back(it->path().parent_path().string());
    }
  }
  std::sort(traces.begin(), traces.end());
  return traces;
}

}  // namespace

TimingTrace ReadCtfTrace(const std::string& dir, int pid) {
  std::error_code error;
  if (!fs::is_directory(dir, error)) {
    throw TraceReadError("no LTTng trace in " + dir +
                         ": it is not a folder; pass the folder `hiltwin trace --output DIR` "
                         "recorded, or a timing log file");
  }
  const std::vector<std::string> traces = FindCtfTraces(dir);
  if (traces.empty()) {
    throw TraceReadError("no LTTng trace in " + dir +
                         ": no CTF `metadata` file below it; record one with `hiltwin trace "
                         "--output DIR` or pass a timing log file");
  }
  TraceBuilder builder(dir, pid);
  SinkState sink{&builder, nullptr};
  CtfGraph graph(dir, traces, sink);
  graph.Run();
  return builder.Finish();
}

}  // namespace hiltwin::analysis
