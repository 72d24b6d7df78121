// `--telemetry dds[:DOMAIN]`: one task's telemetry as ROS 2 topics (sinks.h), stamped in ROS
// time (docs/telemetry.md, "Time stamps"). Every call after Open comes from the telemetry
// thread, so the sink needs no lock; Publish and PollCommands never throw and never wait on the
// network.
// The trust boundary (docs/telemetry.md, "Who may command a task"): any participant on the
// domain can write rt/<ns>/command, so commands reach the session only with --accept-commands,
// and a task warns when another task publishes under its namespace.
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "dds_common.h"
#include "hiltwin/telemetry/codes.h"
#include "hiltwin/telemetry/sinks.h"
#include "ros_types.h"

namespace hiltwin::telemetry {
namespace {

using runtime::RemoteCommand;

// A task time in seconds as builtin_interfaces/Time (sec, nanosec in [0, 1e9)).
builtin_interfaces_msg_dds__Time_ StampOf(double time_s) noexcept {
  constexpr double kNsPerS = 1e9;
  if (!std::isfinite(time_s) || time_s < 0.0) return {0, 0};
  double whole_s = std::floor(time_s);
  double ns = std::round((time_s - whole_s) * kNsPerS);
  if (ns >= kNsPerS) {  // 0.9999999999 s rounds up to the next second
    whole_s += 1.0;
    ns = 0.0;
  }
  return {static_cast<std::int32_t>(whole_s), static_cast<std::uint32_t>(ns)};
}

// ROS time on the real clock: system time, as a ROS 2 node without use_sim_time stamps.
builtin_interfaces_msg_dds__Time_ SystemStamp() noexcept {
  timespec now{};
  if (clock_gettime(CLOCK_REALTIME, &now) != 0) return {0, 0};
  return {static_cast<std::int32_t>(now.tv_sec), static_cast<std::uint32_t>(now.tv_nsec)};
}

// A heading about z as a unit quaternion (x, y, z, w).
geometry_msgs_msg_dds__Quaternion_ YawQuaternion(double theta_rad) noexcept {
  return {0.0, 0.0, std::sin(theta_rad / 2.0), std::cos(theta_rad / 2.0)};
}

// "hiltwin task pid=P host=H": the timing writer's user data, so a task that finds another one
// under its namespace can say which.
std::string TaskUserData() {
  std::array<char, 256> host{};
  if (gethostname(host.data(), host.size() - 1) != 0) host[0] = '\0';
  return "hiltwin task pid=" + std::to_string(getpid()) + " host=" + host.data();
}

// "pid P on H" from TaskUserData's text, "" from any other.
std::string WhoOf(const std::string& user_data) {
  constexpr std::string_view kPrefix = "hiltwin task pid=";
  const std::size_t host = user_data.find(" host=");
  if (!user_data.starts_with(kPrefix) || host == std::string::npos) return {};
  return "pid " + user_data.substr(kPrefix.size(), host - kPrefix.size()) + " on " +
         user_data.substr(host + 6);
}

class DdsSink final : public runtime::TelemetrySink {
 public:
  explicit DdsSink(const DdsEndpoint& endpoint)
      : domain_(endpoint.domain),
        accept_commands_(endpoint.accept_commands),
        participant_(dds::CreateParticipant(
            endpoint.domain, "--telemetry dds:" + std::to_string(endpoint.domain))) {}

  void Open(const runtime::TelemetryShape& shape, const std::string& ns) override;
  void Publish(const runtime::TelemetryRecord& record) noexcept override;
  void PollCommands(const runtime::CommandPort& port) noexcept override;
  [[nodiscard]] std::string Describe() const override;

 private:
  // Odometry's pose at a record's time, kept for the next record's twist.
  struct PoseAt {
    double time_s, x_m, y_m, theta_rad;
  };

  dds_entity_t MakeWriter(const dds_topic_descriptor_t* type, const std::string& name,
                          const dds_qos_t* qos) const;
  void OpenPoseWriters(const std::string& ns, const dds_qos_t* stream);
  void PublishPose(const runtime::TelemetryRecord& record,
                   const builtin_interfaces_msg_dds__Time_& stamp) noexcept;
  geometry_msgs_msg_dds__Twist_ TwistSince(const runtime::TelemetryRecord& record) noexcept;
  void PublishJoints(const runtime::TelemetryRecord& record,
                     const builtin_interfaces_msg_dds__Time_& stamp) noexcept;
  void PublishTiming(const runtime::TelemetryRecord& record) noexcept;
  void Write(dds_entity_t writer, const void* sample, const char* leaf) noexcept;
  void Handle(std::int32_t code, const runtime::CommandPort& port) const noexcept;
  void Refuse(std::int32_t code) noexcept;
  void WatchNamespace() noexcept;

  std::uint32_t domain_;
  bool accept_commands_;
  dds::Entity participant_;  // owns every topic, writer and reader below
  bool has_pose_ = false;
  bool virtual_clock_ = false;  // stamps: the task's time, else system time
  bool publishes_clock_ = false;
  std::string ns_;
  std::string odom_frame_;  // "<ns>/odom": several twins on one domain share rt/tf
  std::string base_frame_;  // "<ns>/base_link"
  std::optional<PoseAt> last_pose_;
  std::string timing_topic_;
  std::string command_topic_;
  dds_entity_t pose_writer_ = 0;  // geometry_msgs/Pose2D, deprecated for odom and tf
  dds_entity_t odom_writer_ = 0;
  dds_entity_t tf_writer_ = 0;
  dds_entity_t clock_writer_ = 0;
  dds_entity_t joints_writer_ = 0;
  dds_entity_t timing_writer_ = 0;
  dds_entity_t command_reader_ = 0;
  std::vector<std::string> joint_names_;
  std::vector<char*> joint_name_ptrs_;  // JointState_::name points here (Cyclone's char**)
  std::uint64_t write_failures_ = 0;    // the first is reported, the rest only counted
  std::uint64_t commands_refused_ = 0;  // without --accept-commands: the first is reported
  // Every writer on the domain, watched for another task's timing writer under our namespace
  // until one is found (then deleted: the warning is given once).
  dds_entity_t publications_ = 0;
  dds_guid_t own_guid_{};
};

void DdsSink::Open(const runtime::TelemetryShape& shape, const std::string& ns) {
  if (!ns_.empty()) throw std::runtime_error("DDS telemetry: the sink is already open as " + ns_);
  if (shape.joint_names.size() > runtime::kMaxTelemetryJoints) {
    throw std::runtime_error("DDS telemetry: " + std::to_string(shape.joint_names.size()) +
                             " joints; at most " + std::to_string(runtime::kMaxTelemetryJoints));
  }
  const dds_entity_t pp = participant_.get();
  // Samples are the latest state: a slow reader loses old ones rather than slowing us down.
  // Reliable, volatile, keep last 10: ROS 2's default, as odometry usually is.
  const dds::QosPtr stream = dds::MakeQos(10, dds::Durability::kVolatile);
  // Depth 1 and transient-local: a monitor that joins late sees every task at once.
  const dds::QosPtr latest = dds::MakeQos(1, dds::Durability::kTransientLocal);
  dds::SetUserData(latest.get(), TaskUserData());
  const dds::QosPtr commands = dds::MakeQos(32, dds::Durability::kVolatile);
  dds::SetUserData(commands.get(),
                   accept_commands_ ? dds::kCommandsAccepted : dds::kCommandsRefused);
  has_pose_ = shape.has_pose;
  if (has_pose_) OpenPoseWriters(ns, stream.get());
  virtual_clock_ = shape.virtual_clock;
  // One /clock per time base: a lockstep pair's controller shares its twin's.
  publishes_clock_ = shape.virtual_clock && (!shape.lockstep || shape.role == "twin");
  if (publishes_clock_) {
    // Reliable keep last 1: matches rclcpp's ClockQoS subscribers (best effort) and reliable
    // ones alike, and the final time reaches a matched reader.
    clock_writer_ = MakeWriter(&rosgraph_msgs_msg_dds__Clock__desc, "rt/clock",
                               dds::MakeQos(1, dds::Durability::kVolatile).get());
  }
  joints_writer_ = MakeWriter(&sensor_msgs_msg_dds__JointState__desc,
                              dds::TopicName(ns, "joint_states"), stream.get());
  timing_topic_ = dds::TopicName(ns, "timing");
  timing_writer_ = MakeWriter(&hiltwin_msgs_msg_dds__Timing__desc, timing_topic_, latest.get());
  command_topic_ = dds::TopicName(ns, "command");
  command_reader_ = dds::Check(
      dds_create_reader(pp, dds::CreateTopic(pp, &std_msgs_msg_dds__Int32__desc, command_topic_),
                        commands.get(), nullptr),
      "DDS reader " + command_topic_);
  joint_names_ = shape.joint_names;
  joint_name_ptrs_.clear();
  for (std::string& name : joint_names_) joint_name_ptrs_.push_back(name.data());
  // Discovery takes time, so the namespace is watched from the telemetry thread (WatchNamespace,
  // every record) rather than waited for here: the run starts at once.
  publications_ = dds::CreatePublicationReader(pp);
  dds::Check(dds_get_guid(pp, &own_guid_), "DDS participant GUID");
  ns_ = ns;
}

dds_entity_t DdsSink::MakeWriter(const dds_topic_descriptor_t* type, const std::string& name,
                                 const dds_qos_t* qos) const {
  const dds_entity_t pp = participant_.get();
  return dds::Check(dds_create_writer(pp, dds::CreateTopic(pp, type, name), qos, nullptr),
                    "DDS writer " + name);
}

// Odometry and tf for RViz and Foxglove, Pose2D beside them (deprecated: kept for subscribers
// written against it). rt/tf is every node's, not namespaced, so the frames carry the namespace.
void DdsSink::OpenPoseWriters(const std::string& ns, const dds_qos_t* stream) {
  odom_frame_ = ns + "/odom";
  base_frame_ = ns + "/base_link";
  odom_writer_ = MakeWriter(&nav_msgs_msg_dds__Odometry__desc, dds::TopicName(ns, "odom"), stream);
  pose_writer_ =
      MakeWriter(&geometry_msgs_msg_dds__Pose2D__desc, dds::TopicName(ns, "pose"), stream);
  // tf2_ros's broadcaster QoS: reliable, volatile, keep last 100.
  tf_writer_ = MakeWriter(&tf2_msgs_msg_dds__TFMessage__desc, "rt/tf",
                          dds::MakeQos(100, dds::Durability::kVolatile).get());
}

void DdsSink::Publish(const runtime::TelemetryRecord& record) noexcept {
  if (timing_writer_ <= 0) return;  // not open
  // One stamp for every topic of the record, so tf and odometry agree.
  const builtin_interfaces_msg_dds__Time_ stamp =
      virtual_clock_ ? StampOf(record.time_s) : SystemStamp();
  if (publishes_clock_) {
    const rosgraph_msgs_msg_dds__Clock_ clock{stamp};
    Write(clock_writer_, &clock, "clock");
  }
  // Before the loop's first cycle the record holds no values yet (the mailbox's default): a
  // subscriber's first sample would be an empty JointState and a pose of zeros.
  if (has_pose_ && record.task.has_pose) PublishPose(record, stamp);
  if (record.task.joint_count > 0 || joint_names_.empty()) PublishJoints(record, stamp);
  PublishTiming(record);
}

void DdsSink::PublishPose(const runtime::TelemetryRecord& record,
                          const builtin_interfaces_msg_dds__Time_& stamp) noexcept {
  const runtime::TaskTelemetry& t = record.task;
  const geometry_msgs_msg_dds__Pose2D_ pose{t.x_m, t.y_m, t.theta_rad};
  Write(pose_writer_, &pose, "pose");
  const geometry_msgs_msg_dds__Quaternion_ rotation = YawQuaternion(t.theta_rad);
  nav_msgs_msg_dds__Odometry_ odom{};  // covariances 0: the twin's pose is the model's state
  odom.header = {stamp, odom_frame_.data()};
  odom.child_frame_id = base_frame_.data();
  odom.pose.pose = {{t.x_m, t.y_m, 0.0}, rotation};
  odom.twist.twist = TwistSince(record);
  Write(odom_writer_, &odom, "odom");
  geometry_msgs_msg_dds__TransformStamped_ transform{};
  transform.header = odom.header;
  transform.child_frame_id = base_frame_.data();
  transform.transform = {{t.x_m, t.y_m, 0.0}, rotation};
  const tf2_msgs_msg_dds__TFMessage_ tf{{1, 1, &transform, false}};
  Write(tf_writer_, &tf, "tf");
}

// The body-frame velocity (base_link, as nav_msgs/Odometry's twist) from the pose's change since
// the last record over the task time between them; the chord of an arc points along the
// heading halfway through it. Zero on the first record and while the task time stands still.
geometry_msgs_msg_dds__Twist_ DdsSink::TwistSince(const runtime::TelemetryRecord& r) noexcept {
  geometry_msgs_msg_dds__Twist_ twist{};
  const runtime::TaskTelemetry& t = r.task;
  if (last_pose_ && r.time_s > last_pose_->time_s) {
    const double dt = r.time_s - last_pose_->time_s;
    const double dx = t.x_m - last_pose_->x_m;
    const double dy = t.y_m - last_pose_->y_m;
    const double heading = (t.theta_rad + last_pose_->theta_rad) / 2.0;
    twist.linear.x = (std::cos(heading) * dx + std::sin(heading) * dy) / dt;
    twist.linear.y = (-std::sin(heading) * dx + std::cos(heading) * dy) / dt;
    twist.angular.z = (t.theta_rad - last_pose_->theta_rad) / dt;
  }
  last_pose_ = PoseAt{r.time_s, t.x_m, t.y_m, t.theta_rad};
  return twist;
}

void DdsSink::PublishJoints(const runtime::TelemetryRecord& record,
                            const builtin_interfaces_msg_dds__Time_& stamp) noexcept {
  static char empty[] = "";  // Cyclone's char* fields are not const; it only reads them
  std::array<double, runtime::kMaxTelemetryJoints> position_rad = record.task.joint_position_rad;
  const auto count = static_cast<std::uint32_t>(
      std::min<std::size_t>(record.task.joint_count, joint_name_ptrs_.size()));
  sensor_msgs_msg_dds__JointState_ msg{};
  msg.header.stamp = stamp;
  msg.header.frame_id = empty;
  msg.name = {count, count, joint_name_ptrs_.data(), false};
  msg.position = {count, count, position_rad.data(), false};
  msg.velocity = {0, 0, nullptr, false};
  msg.effort = {0, 0, nullptr, false};
  Write(joints_writer_, &msg, "joint_states");
}

void DdsSink::PublishTiming(const runtime::TelemetryRecord& record) noexcept {
  hiltwin_msgs_msg_dds__Timing_ msg{};
  msg.ns = ns_.data();
  msg.role = const_cast<char*>(record.role.c_str());
  msg.rate_hz = record.rate_hz;
  msg.time_s = record.time_s;
  msg.cycle = record.cycle;
  msg.cycles_planned = record.cycles_planned;
  msg.deadline_misses = record.deadline_misses;
  msg.latency_p99_us = record.latency_p99_us;
  msg.latency_max_us = record.latency_max_us;
  msg.distance_to_violation =
      record.distance_to_violation ? static_cast<std::int64_t>(*record.distance_to_violation) : -1;
  msg.verdict = const_cast<char*>(qos::ToString(record.verdict_so_far));
  msg.state = const_cast<char*>(lifecycle::ToString(record.state));
  msg.final = record.final;
  msg.verdict_code = VerdictCode(record.verdict_so_far);
  msg.state_code = StateCode(record.state);
  Write(timing_writer_, &msg, "timing");
}

void DdsSink::Write(dds_entity_t writer, const void* sample, const char* leaf) noexcept {
  const dds_return_t rc = dds_write(writer, sample);
  if (rc >= 0) return;
  if (write_failures_++ == 0) {
    std::fprintf(stderr,
                 "hiltwin: DDS write on rt/%s/%s failed (%s); telemetry goes on, further "
                 "failures are not reported\n",
                 ns_.c_str(), leaf, dds_strretcode(rc));
  }
}

void DdsSink::PollCommands(const runtime::CommandPort& port) noexcept {
  WatchNamespace();
  if (command_reader_ <= 0) return;
  dds::TakeAll<std_msgs_msg_dds__Int32_>(command_reader_, [&](const auto& sample, const auto&) {
    if (accept_commands_) {
      Handle(sample.data, port);
    } else {
      Refuse(sample.data);
    }
  });
}

// Once per run: a sender that repeats must not flood stderr, and one line says all there is.
void DdsSink::Refuse(std::int32_t code) noexcept {
  if (commands_refused_++ > 0) return;
  const std::optional<RemoteCommand> command = runtime::RemoteCommandOf(code);
  std::array<char, 32> what{};  // no allocation: this function is noexcept
  if (command) {
    std::snprintf(what.data(), what.size(), "%s", runtime::ToString(*command));
  } else {
    std::snprintf(what.data(), what.size(), "command code %d", static_cast<int>(code));
  }
  std::fprintf(stderr,
               "hiltwin: ignored %s on %s: this task was started without --accept-commands, so "
               "it takes no commands from DDS domain %u, where any participant could send "
               "them (docs/telemetry.md, \"Who may command a task\"); further ones are ignored "
               "without a word\n",
               what.data(), command_topic_.c_str(), static_cast<unsigned>(domain_));
}

// Another task's timing writer under our namespace: its topics and ours mix, and a command to
// the namespace reaches both. Taking the new discovery samples costs one call per record.
void DdsSink::WatchNamespace() noexcept {
  if (publications_ <= 0) return;
  try {
    std::optional<std::string> other;  // its user data
    dds::TakeAll<dds_builtintopic_endpoint_t>(publications_, [&](const auto& ep, const auto&) {
      if (other || ep.topic_name == nullptr || timing_topic_ != ep.topic_name) return;
      if (std::memcmp(&ep.participant_key, &own_guid_, sizeof(own_guid_)) == 0) return;  // ours
      other = dds::UserDataOf(ep.qos);
    });
    if (!other) return;
    const std::string who = WhoOf(*other);
    const std::string by = who.empty() ? "" : " (" + who + ")";
    std::fprintf(stderr,
                 "hiltwin: warning: another task already publishes %s on DDS domain %u%s: the "
                 "two tasks' topics mix and a command to %s reaches both; give each task its own "
                 "--namespace\n",
                 timing_topic_.c_str(), static_cast<unsigned>(domain_), by.c_str(), ns_.c_str());
  } catch (...) {  // out of memory: no warning, and the watch ends (below)
  }
  static_cast<void>(dds_delete(publications_));
  publications_ = 0;
}

// One stderr line per command, accepted or not: this runs on the telemetry thread, where
// printing is allowed, and a user who sent a command wants to see what became of it.
void DdsSink::Handle(std::int32_t code, const runtime::CommandPort& port) const noexcept {
  const std::optional<RemoteCommand> command = runtime::RemoteCommandOf(code);
  if (!command) {
    std::fprintf(stderr,
                 "hiltwin: ignored command code %d on %s: not a command (1 INITIALISE, 2 START, "
                 "3 STOP, 4 RESET, 5 PAUSE, 6 QUIT)\n",
                 static_cast<int>(code), command_topic_.c_str());
    return;
  }
  try {
    std::string why;
    if (port && port(*command, why)) {
      std::fprintf(stderr, "hiltwin: %s received on %s\n", runtime::ToString(*command),
                   command_topic_.c_str());
    } else {
      std::fprintf(stderr, "hiltwin: %s on %s refused: %s\n", runtime::ToString(*command),
                   command_topic_.c_str(),
                   why.empty() ? "this task takes no commands" : why.c_str());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hiltwin: %s on %s failed: %s\n", runtime::ToString(*command),
                 command_topic_.c_str(), e.what());
  } catch (...) {
    std::fprintf(stderr, "hiltwin: %s on %s failed\n", runtime::ToString(*command),
                 command_topic_.c_str());
  }
}

std::string DdsSink::Describe() const {
  std::string domain = "DDS domain " + std::to_string(domain_);
  // Before Open the namespace is not known yet; commands print the namespace next to this.
  if (ns_.empty()) return domain + " rt/<namespace>/{odom,pose,joint_states,timing,command}";
  return domain + " rt/" + ns_ +
         (has_pose_ ? "/{odom,pose,joint_states,timing,command} rt/tf"
                    : "/{joint_states,timing,command}") +
         (publishes_clock_ ? " rt/clock" : "");
}

}  // namespace

std::shared_ptr<runtime::TelemetrySink> MakeDdsSink(const DdsEndpoint& endpoint) {
  return std::make_shared<DdsSink>(endpoint);
}

}  // namespace hiltwin::telemetry
