// dds_probe: a DDS subscriber in its own process, as `ros2 topic echo` would be, for the
// integration tests. It reads one namespace's pose, odom, joint_states and timing, and the
// domain's tf and clock, and prints one JSON line per event on stdout:
//   {"event":"ready"}                                   readers created
//   {"event":"publication","topic":T,"type":N}          a writer of an rt/ topic was discovered
//   {"topic":"pose","type":N,"x":..,"y":..,"theta":..}  one sample (type as discovered)
//   {"topic":"odom",...}, {"topic":"tf",...} (one line per transform), {"topic":"clock",...},
//   {"topic":"joint_states",...}, {"topic":"timing",...}
//   {"event":"end","final":true|false}                  exit
// It exits --after-final seconds after the task's final timing record, or after --duration.
#include <dds/dds.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

#include "ros_types.h"

namespace {

using Json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

struct Args {
  std::uint32_t domain = 0;
  std::string ns;
  double duration_s = 20.0;
  double after_final_s = 1.0;
};

Args Parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string_view flag = argv[i];
    const char* value = argv[i + 1];
    if (flag == "--domain") a.domain = static_cast<std::uint32_t>(std::atoi(value));
    if (flag == "--ns") a.ns = value;
    if (flag == "--duration") a.duration_s = std::atof(value);
    if (flag == "--after-final") a.after_final_s = std::atof(value);
  }
  if (a.ns.empty()) {
    std::fprintf(stderr, "usage: dds_probe --domain N --ns NS [--duration S] [--after-final S]\n");
    std::exit(2);  // NOLINT(concurrency-mt-unsafe): single-threaded tool
  }
  return a;
}

void Emit(const Json& line) {
  std::printf("%s\n", line.dump().c_str());
  std::fflush(stdout);
}

// A reader with ROS 2's subscription defaults (reliable; /clock: best effort, as rclcpp's
// ClockQoS), keeping every sample for the test.
dds_entity_t Reader(dds_entity_t pp, const dds_topic_descriptor_t* desc, const std::string& name,
                    bool transient_local, bool best_effort = false) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, best_effort ? DDS_RELIABILITY_BEST_EFFORT : DDS_RELIABILITY_RELIABLE,
                       DDS_SECS(1));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1000);
  if (transient_local) dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  const dds_entity_t topic = dds_create_topic(pp, desc, name.c_str(), nullptr, nullptr);
  const dds_entity_t reader = dds_create_reader(pp, topic, qos, nullptr);
  dds_delete_qos(qos);
  if (topic < 0 || reader < 0) {
    std::fprintf(stderr, "dds_probe: cannot read %s: %s\n", name.c_str(),
                 dds_strretcode(reader < 0 ? reader : topic));
    std::exit(1);  // NOLINT(concurrency-mt-unsafe): single-threaded tool
  }
  return reader;
}

// Calls fn(sample) for every sample with data that `reader` holds.
template <typename Sample, typename Fn>
void TakeAll(dds_entity_t reader, Fn&& fn) {
  for (;;) {
    void* sample = nullptr;
    dds_sample_info_t info{};
    if (dds_take(reader, &sample, &info, 1, 1) <= 0) return;
    if (info.valid_data) fn(*static_cast<const Sample*>(sample));
    dds_return_loan(reader, &sample, 1);
  }
}

class Probe {
 public:
  Probe(const Args& args, dds_entity_t pp) : args_(args) {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wold-style-cast"  // Cyclone's pseudo-handle macro
    publications_ = dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
#pragma GCC diagnostic pop
    pose_ = Reader(pp, &geometry_msgs_msg_dds__Pose2D__desc, Topic("pose"), false);
    joints_ = Reader(pp, &sensor_msgs_msg_dds__JointState__desc, Topic("joint_states"), false);
    timing_ = Reader(pp, &hiltwin_msgs_msg_dds__Timing__desc, Topic("timing"), true);
    odom_ = Reader(pp, &nav_msgs_msg_dds__Odometry__desc, Topic("odom"), false);
    tf_ = Reader(pp, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf", false);
    clock_ = Reader(pp, &rosgraph_msgs_msg_dds__Clock__desc, "rt/clock", false, true);
  }

  [[nodiscard]] std::string Topic(const char* leaf) const { return "rt/" + args_.ns + "/" + leaf; }

  // Returns true once the final timing record was seen.
  bool Step() {
    Discover();  // first: a sample's writer is always discovered before its data
    TakeAll<geometry_msgs_msg_dds__Pose2D_>(pose_, [&](const auto& s) {
      Emit({{"topic", "pose"},
            {"type", types_[Topic("pose")]},
            {"x", s.x},
            {"y", s.y},
            {"theta", s.theta}});
    });
    TakeAll<sensor_msgs_msg_dds__JointState_>(joints_, [&](const auto& s) {
      Json names = Json::array(), position = Json::array();
      for (std::uint32_t i = 0; i < s.name._length; ++i) names.push_back(s.name._buffer[i]);
      for (std::uint32_t i = 0; i < s.position._length; ++i)
        position.push_back(s.position._buffer[i]);
      Emit({{"topic", "joint_states"},
            {"type", types_[Topic("joint_states")]},
            {"sec", s.header.stamp.sec},
            {"nanosec", s.header.stamp.nanosec},
            {"name", names},
            {"position", position}});
    });
    TakeRos();
    TakeAll<hiltwin_msgs_msg_dds__Timing_>(timing_, [&](const auto& s) {
      Emit({{"topic", "timing"},
            {"type", types_[Topic("timing")]},
            {"ns", s.ns},
            {"role", s.role},
            {"cycle", s.cycle},
            {"time_s", s.time_s},
            {"verdict", s.verdict},
            {"state", s.state},
            {"verdict_code", s.verdict_code},
            {"state_code", s.state_code},
            {"final", s.final}});
      final_ = final_ || s.final;
    });
    return final_;
  }

 private:
  static Json Stamp(const builtin_interfaces_msg_dds__Time_& t) {
    return {{"sec", t.sec}, {"nanosec", t.nanosec}};
  }

  static Json Frame(const std_msgs_msg_dds__Header_& header, const char* child,
                    const geometry_msgs_msg_dds__Vector3_& v,
                    const geometry_msgs_msg_dds__Quaternion_& q) {
    return {{"stamp", Stamp(header.stamp)},
            {"frame_id", header.frame_id},
            {"child_frame_id", child},
            {"x", v.x},
            {"y", v.y},
            {"z", v.z},
            {"q", {q.x, q.y, q.z, q.w}}};
  }

  // Odometry, every transform on rt/tf and the clock: what RViz and Foxglove read.
  void TakeRos() {
    TakeAll<nav_msgs_msg_dds__Odometry_>(odom_, [&](const auto& s) {
      const auto& p = s.pose.pose.position;
      Json line = Frame(s.header, s.child_frame_id, {p.x, p.y, p.z}, s.pose.pose.orientation);
      line["topic"] = "odom";
      line["type"] = types_[Topic("odom")];
      line["vx"] = s.twist.twist.linear.x;
      line["wz"] = s.twist.twist.angular.z;
      Emit(line);
    });
    TakeAll<tf2_msgs_msg_dds__TFMessage_>(tf_, [&](const auto& s) {
      for (std::uint32_t i = 0; i < s.transforms._length; ++i) {
        const auto& t = s.transforms._buffer[i];
        Json line = Frame(t.header, t.child_frame_id, t.transform.translation,
                          t.transform.rotation);
        line["topic"] = "tf";
        line["type"] = types_["rt/tf"];
        Emit(line);
      }
    });
    TakeAll<rosgraph_msgs_msg_dds__Clock_>(clock_, [&](const auto& s) {
      Emit({{"topic", "clock"}, {"type", types_["rt/clock"]}, {"clock", Stamp(s.clock)}});
    });
  }

  void Discover() {
    TakeAll<dds_builtintopic_endpoint_t>(publications_, [&](const auto& ep) {
      const std::string topic = ep.topic_name != nullptr ? ep.topic_name : "";
      if (!topic.starts_with("rt/") || types_.contains(topic)) return;
      types_[topic] = ep.type_name != nullptr ? ep.type_name : "";
      Emit({{"event", "publication"}, {"topic", topic}, {"type", types_[topic]}});
    });
  }

  Args args_;
  dds_entity_t publications_ = 0, pose_ = 0, joints_ = 0, timing_ = 0, odom_ = 0, tf_ = 0,
               clock_ = 0;
  std::map<std::string, std::string> types_;  // topic -> type name, from DCPSPublication
  bool final_ = false;
};

int Main(int argc, char** argv) {
  const Args args = Parse(argc, argv);
  const dds_entity_t pp =
      dds_create_participant(static_cast<dds_domainid_t>(args.domain), nullptr, nullptr);
  if (pp < 0) {
    std::fprintf(stderr, "dds_probe: domain %u: %s\n", args.domain, dds_strretcode(pp));
    return 1;
  }
  Probe probe(args, pp);
  Emit({{"event", "ready"}});
  const auto start = Clock::now();
  std::optional<Clock::time_point> final_at;
  for (;;) {
    if (probe.Step() && !final_at) final_at = Clock::now();
    const auto now = Clock::now();
    if (final_at && now - *final_at >= std::chrono::duration<double>(args.after_final_s)) break;
    if (now - start >= std::chrono::duration<double>(args.duration_s)) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  probe.Step();
  Emit({{"event", "end"}, {"final", final_at.has_value()}});
  dds_delete(pp);
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dds_probe: %s\n", e.what());
    return 1;
  }
}
