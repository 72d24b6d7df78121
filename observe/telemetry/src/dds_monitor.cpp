// `hiltwin monitor`'s DDS side (dds_monitor.h). Tasks are found the way `ros2 topic list`
// finds topics: through the built-in DCPSPublication topic, which lists every writer on the
// domain with its topic and type name. A writer of `rt/<ns>/timing` typed
// hiltwin_msgs::msg::dds_::Timing_ is a hiltwin task; the monitor then reads that topic
// (transient-local, so the task's last record arrives at once).
#include "hiltwin/telemetry/dds_monitor.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <map>
#include <stdexcept>
#include <string_view>
#include <thread>

#include "dds_common.h"
#include "ros_types.h"

namespace hiltwin::telemetry {
namespace {

using Clock = std::chrono::steady_clock;  // CLOCK_MONOTONIC: ages never jump with the wall clock

// "rt/<ns>/timing" -> "<ns>", "" for any other topic.
std::string NamespaceOfTimingTopic(std::string_view topic) {
  constexpr std::string_view kPrefix = "rt/";
  constexpr std::string_view kSuffix = "/timing";
  if (topic.size() <= kPrefix.size() + kSuffix.size() || !topic.starts_with(kPrefix) ||
      !topic.ends_with(kSuffix)) {
    return {};
  }
  return std::string(topic.substr(kPrefix.size(), topic.size() - kPrefix.size() - kSuffix.size()));
}

MonitorEntry EntryOf(const std::string& ns, const hiltwin_msgs_msg_dds__Timing_& t) {
  MonitorEntry e;
  e.ns = ns;
  e.role = t.role != nullptr ? t.role : "";
  e.rate_hz = t.rate_hz;
  e.time_s = t.time_s;
  e.cycle = t.cycle;
  e.cycles_planned = t.cycles_planned;
  e.deadline_misses = t.deadline_misses;
  e.latency_p99_us = t.latency_p99_us;
  if (t.distance_to_violation >= 0) {
    e.distance_to_violation = static_cast<std::uint32_t>(t.distance_to_violation);
  }
  e.verdict = t.verdict != nullptr ? t.verdict : "";
  e.state = t.state != nullptr ? t.state : "";
  e.final = t.final;
  return e;
}

// Whether any reader `writer` matched takes commands: a hiltwin task's command reader says so
// in its user data (dds_common.h); a reader that does not say (another program's) may.
bool AnyReaderTakesCommands(dds_entity_t writer) {
  std::array<dds_instance_handle_t, 16> handles{};
  const dds_return_t n = dds_get_matched_subscriptions(writer, handles.data(), handles.size());
  const std::size_t matched = n > 0 ? std::min(static_cast<std::size_t>(n), handles.size()) : 0;
  bool takes = matched == 0;  // none left to ask: the acknowledgement decides
  for (std::size_t i = 0; i < matched && !takes; ++i) {
    dds_builtintopic_endpoint_t* reader = dds_get_matched_subscription_data(writer, handles[i]);
    if (reader == nullptr) continue;
    takes = dds::UserDataOf(reader->qos) != dds::kCommandsRefused;
    dds_builtintopic_free_endpoint(reader);
  }
  return takes;
}

}  // namespace

struct DdsMonitor::State {
  struct Task {
    dds_entity_t reader = 0;
    std::optional<MonitorEntry> latest;
    Clock::time_point arrived;
  };

  std::uint32_t domain = 0;
  dds::Entity participant;
  dds_entity_t publications = 0;      // reader of the built-in DCPSPublication topic
  std::map<std::string, Task> tasks;  // by namespace, hence sorted

  void Discover();
  void AddTask(const std::string& ns);
};

void DdsMonitor::State::Discover() {
  dds::TakeAll<dds_builtintopic_endpoint_t>(publications, [this](const auto& ep, const auto&) {
    if (ep.topic_name == nullptr || ep.type_name == nullptr) return;
    if (std::string_view(ep.type_name) != dds::kTimingTypeName) return;
    const std::string ns = NamespaceOfTimingTopic(ep.topic_name);
    if (!ns.empty() && !tasks.contains(ns)) AddTask(ns);
  });
}

void DdsMonitor::State::AddTask(const std::string& ns) {
  const dds_entity_t pp = participant.get();
  const std::string name = dds::TopicName(ns, "timing");
  const dds::QosPtr qos = dds::MakeQos(1, dds::Durability::kTransientLocal);
  const dds_entity_t topic = dds::CreateTopic(pp, &hiltwin_msgs_msg_dds__Timing__desc, name);
  tasks[ns].reader =
      dds::Check(dds_create_reader(pp, topic, qos.get(), nullptr), "DDS reader " + name);
}

DdsMonitor::DdsMonitor(std::uint32_t domain) : state_(new State) {
  try {
    state_->domain = domain;
    state_->participant = dds::CreateParticipant(domain, "DDS domain " + std::to_string(domain));
    state_->publications = dds::CreatePublicationReader(state_->participant.get());
  } catch (...) {
    delete state_;
    throw;
  }
}

DdsMonitor::~DdsMonitor() { delete state_; }

std::vector<MonitorEntry> DdsMonitor::Poll() {
  state_->Discover();
  const Clock::time_point now = Clock::now();
  std::vector<MonitorEntry> entries;
  for (auto& item : state_->tasks) {
    const std::string& ns = item.first;
    State::Task& task = item.second;
    dds::TakeAll<hiltwin_msgs_msg_dds__Timing_>(task.reader, [&](const auto& t, const auto&) {
      task.latest = EntryOf(ns, t);
      task.arrived = now;
    });
    if (!task.latest) continue;  // discovered, no record yet
    MonitorEntry entry = *task.latest;
    entry.age_s = std::chrono::duration<double>(now - task.arrived).count();
    entries.push_back(std::move(entry));
  }
  return entries;
}

std::vector<std::string> DdsMonitor::Namespaces() const {
  std::vector<std::string> names;
  for (const auto& [ns, task] : state_->tasks) names.push_back(ns);
  return names;
}

std::string DdsMonitor::SendCommand(const std::string& ns, runtime::RemoteCommand command,
                                    double timeout_s) {
  const Clock::time_point deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                        std::chrono::duration<double>(timeout_s));
  constexpr auto kPollPeriod = std::chrono::milliseconds(20);
  const std::string name = dds::TopicName(ns, "command");
  const dds_entity_t pp = state_->participant.get();
  const dds::Entity writer(
      dds::Check(dds_create_writer(pp, dds::CreateTopic(pp, &std_msgs_msg_dds__Int32__desc, name),
                                   dds::MakeQos(8, dds::Durability::kVolatile).get(), nullptr),
                 "DDS writer " + name));
  dds_publication_matched_status_t matched{};
  while (dds_get_publication_matched_status(writer.get(), &matched) >= 0 &&
         matched.current_count == 0) {
    if (Clock::now() >= deadline) {
      return "no reader on " + name + " matched within " + std::to_string(timeout_s) +
             " s: the task does not take commands over DDS, or it is gone";
    }
    std::this_thread::sleep_for(kPollPeriod);
  }
  // Sent even when refused: the task then says on its stderr that someone tried.
  const bool refused = !AnyReaderTakesCommands(writer.get());
  const std_msgs_msg_dds__Int32_ sample{static_cast<std::int32_t>(command)};
  const dds_return_t rc = dds_write(writer.get(), &sample);
  if (rc < 0) return "writing " + name + " failed: " + dds_strretcode(rc);
  // Reliable delivery: the reader acknowledges once the sample is in its history.
  constexpr dds_duration_t kAckTimeout = DDS_SECS(2);
  const dds_return_t acked = dds_wait_for_acks(writer.get(), kAckTimeout);
  if (acked < 0) {
    return std::string("the reader on ") + name + " did not acknowledge " +
           runtime::ToString(command) + " within 2 s (" + dds_strretcode(acked) + ")";
  }
  if (refused) {
    return std::string("the task refused ") + runtime::ToString(command) +
           ": it was started without --accept-commands, so it takes no commands from the DDS "
           "domain (it says so on its stderr); start it with --accept-commands to command it "
           "(docs/telemetry.md, \"Who may command a task\")";
  }
  return {};
}

}  // namespace hiltwin::telemetry
