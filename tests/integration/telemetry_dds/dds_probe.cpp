// dds_probe: a DDS subscriber in its own process, as `ros2 topic echo` would be, for the
// integration tests. It reads one namespace's pose, joint_states and timing and prints one
// JSON line per event on stdout:
//   {"event":"ready"}                                   readers created
//   {"event":"publication","topic":T,"type":N}          a writer of an rt/ topic was discovered
//   {"topic":"pose","type":N,"x":..,"y":..,"theta":..}  one sample (type as discovered)
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

dds_entity_t Reader(dds_entity_t pp, const dds_topic_descriptor_t* desc, const std::string& name,
                    bool transient_local) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
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
    timing_ = Reader(pp, &hiltwin_msg_dds__Timing__desc, Topic("timing"), true);
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
    TakeAll<hiltwin_msg_dds__Timing_>(timing_, [&](const auto& s) {
      Emit({{"topic", "timing"},
            {"type", types_[Topic("timing")]},
            {"ns", s.ns},
            {"role", s.role},
            {"cycle", s.cycle},
            {"time_s", s.time_s},
            {"verdict", s.verdict},
            {"state", s.state},
            {"final", s.final}});
      final_ = final_ || s.final;
    });
    return final_;
  }

 private:
  void Discover() {
    TakeAll<dds_builtintopic_endpoint_t>(publications_, [&](const auto& ep) {
      const std::string topic = ep.topic_name != nullptr ? ep.topic_name : "";
      if (!topic.starts_with("rt/") || types_.contains(topic)) return;
      types_[topic] = ep.type_name != nullptr ? ep.type_name : "";
      Emit({{"event", "publication"}, {"topic", topic}, {"type", types_[topic]}});
    });
  }

  Args args_;
  dds_entity_t publications_ = 0, pose_ = 0, joints_ = 0, timing_ = 0;
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
