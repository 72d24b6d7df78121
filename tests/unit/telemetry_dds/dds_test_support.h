#pragma once
// In-process DDS peers for the sink and monitor tests: a participant of the test's own with
// typed readers and writers, over the shipped loopback configuration.
#include <dds/dds.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include "fakes/test_paths.h"
#include "hiltwin/runtime/telemetry.h"
#include "ros_types.h"

namespace hiltwin::test {

/// Every DDS test runs over config/cyclonedds-loopback.xml (set before the first participant).
inline void UseLoopbackDds() {
  // Before any participant exists: Cyclone reads the variable when a domain is created.
  const std::string uri = "file://" + std::string(HILTWIN_DDS_CONFIG);
  ::setenv("CYCLONEDDS_URI", uri.c_str(), 1);  // NOLINT(concurrency-mt-unsafe)
}

/// A namespace no other process on this machine uses (a second checkout's tests, say).
inline std::string UniqueNamespace(const std::string& leaf) {
  return "t" + std::to_string(::getpid()) + "/" + leaf;
}

/// Polls `done` every 5 ms until it holds or `timeout_ms` passes (generous on a loaded machine).
inline bool WaitFor(const std::function<bool()>& done, int timeout_ms = 5000) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (!done()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

/// The twin's telemetry shape: a pose and two wheel joints. `virtual_clock` sets the stamps:
/// the task's time when true, system time when false.
inline runtime::TelemetryShape TwinShape(bool virtual_clock = true) {
  runtime::TelemetryShape shape;
  shape.role = "twin";
  shape.has_pose = true;
  shape.joint_names = {"left_wheel_joint", "right_wheel_joint"};
  shape.virtual_clock = virtual_clock;
  return shape;
}

/// One of the twin's records with every field set to a value a test can read back exactly.
inline runtime::TelemetryRecord TwinRecord(const std::string& ns) {
  runtime::TelemetryRecord r;
  r.ns = ns;
  r.role = "twin";
  r.rate_hz = 1000.0;
  r.time_s = 12.25;
  r.cycle = 12'250;
  r.cycles_planned = 20'000;
  r.state = lifecycle::State::kRun;
  r.deadline_misses = 3;
  r.latency_p99_us = 41.5;
  r.latency_max_us = 97.25;
  r.latency_samples = 1000;
  r.distance_to_violation = std::nullopt;
  r.verdict_so_far = qos::Verdict::kPass;
  r.task.has_pose = true;
  r.task.x_m = 0.5;
  r.task.y_m = -0.25;
  r.task.theta_rad = 1.125;
  r.task.joint_count = 2;
  r.task.joint_position_rad = {3.5, -1.75, 0.0, 0.0};
  r.task.joint_position_m = {0.35, -0.175, 0.0, 0.0};
  r.joint_names = {"left_wheel_joint", "right_wheel_joint"};
  return r;
}

/// The test's own participant on `domain`.
class Peer {
 public:
  explicit Peer(std::uint32_t domain)
      : participant_(
            dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr)) {}
  ~Peer() {
    if (participant_ > 0) dds_delete(participant_);
  }
  Peer(const Peer&) = delete;
  Peer& operator=(const Peer&) = delete;

  [[nodiscard]] dds_entity_t participant() const { return participant_; }

  /// A reliable reader (transient-local when `late_joiner`, to get a writer's last sample).
  dds_entity_t Reader(const dds_topic_descriptor_t* desc, const std::string& topic,
                      bool late_joiner = false) const {
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 100);
    if (late_joiner) dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
    const dds_entity_t t = dds_create_topic(participant_, desc, topic.c_str(), nullptr, nullptr);
    const dds_entity_t r = dds_create_reader(participant_, t, qos, nullptr);
    dds_delete_qos(qos);
    return r;
  }

  dds_entity_t Writer(const dds_topic_descriptor_t* desc, const std::string& topic) const {
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    const dds_entity_t t = dds_create_topic(participant_, desc, topic.c_str(), nullptr, nullptr);
    const dds_entity_t w = dds_create_writer(participant_, t, qos, nullptr);
    dds_delete_qos(qos);
    return w;
  }

 private:
  dds_entity_t participant_;
};

/// Takes one sample of `reader` into `out` (deep copy through `copy`); false when none.
template <typename Sample, typename Copy>
bool TakeOne(dds_entity_t reader, Copy&& copy) {
  void* sample = nullptr;
  dds_sample_info_t info{};
  const dds_return_t n = dds_take(reader, &sample, &info, 1, 1);
  if (n <= 0) return false;
  const bool valid = info.valid_data;
  if (valid) copy(*static_cast<const Sample*>(sample));
  dds_return_loan(reader, &sample, n);
  return valid;
}

/// Sends this process's stderr to a file for the object's life; unlike gtest's CaptureStderr,
/// what was written so far can be read at any time (to wait for a line).
class StderrFile {
 public:
  StderrFile() : path_("/tmp/hiltwin-stderr-XXXXXX"), saved_(::dup(STDERR_FILENO)) {
    std::fflush(stderr);
    const int fd = ::mkstemp(path_.data());
    if (fd < 0 || saved_ < 0 || ::dup2(fd, STDERR_FILENO) < 0) {
      throw std::runtime_error("cannot send stderr to a file");
    }
    ::close(fd);
  }
  ~StderrFile() {
    std::fflush(stderr);
    ::dup2(saved_, STDERR_FILENO);
    ::close(saved_);
    ::unlink(path_.c_str());
  }
  StderrFile(const StderrFile&) = delete;
  StderrFile& operator=(const StderrFile&) = delete;

  [[nodiscard]] std::string Text() const {
    std::fflush(stderr);
    std::ifstream in(path_);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

 private:
  std::string path_;
  int saved_;
};

/// True once `writer` has a matched reader.
inline bool Matched(dds_entity_t writer) {
  dds_publication_matched_status_t status{};
  return dds_get_publication_matched_status(writer, &status) >= 0 && status.current_count > 0;
}

}  // namespace hiltwin::test
