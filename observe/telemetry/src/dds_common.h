#pragma once
// Small helpers over Cyclone DDS's C API shared by the DDS sink and the monitor: an owning
// entity handle, the domain check, participant creation with a message that says how to fix
// it, the QoS every hiltwin endpoint uses, and the ROS 2 topic names.

#include <dds/dds.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

namespace hiltwin::telemetry::dds {

/// Highest domain id: Cyclone's default port mapping (7400 + 250·domain + offsets) must stay
/// below 65536, which is also ROS_DOMAIN_ID's documented range.
inline constexpr std::uint32_t kMaxDomain = 232;

/// Owns one DDS entity. Deleting a participant deletes every entity it created, so the sink
/// and the monitor own only their participant (and the monitor its short-lived writer).
class Entity {
 public:
  Entity() = default;
  explicit Entity(dds_entity_t id) noexcept : id_(id) {}
  ~Entity() { Reset(); }
  Entity(Entity&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
  Entity& operator=(Entity&& other) noexcept {
    if (this != &other) {
      Reset();
      id_ = std::exchange(other.id_, 0);
    }
    return *this;
  }
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;

  [[nodiscard]] dds_entity_t get() const noexcept { return id_; }
  void Reset() noexcept {
    if (id_ > 0) static_cast<void>(dds_delete(id_));
    id_ = 0;
  }

 private:
  dds_entity_t id_ = 0;
};

/// Throws std::invalid_argument naming `flag` (e.g. "--telemetry dds:300") when `domain` is
/// outside 0..kMaxDomain.
void CheckDomain(std::uint32_t domain, const std::string& flag);

/// Joins `domain`; throws std::runtime_error naming `flag`, Cyclone's reason and the fix
/// (CYCLONEDDS_URI and the shipped loopback configuration).
[[nodiscard]] Entity CreateParticipant(std::uint32_t domain, const std::string& flag);

/// `rc` when it is a valid entity, else throws std::runtime_error "<what>: <Cyclone's reason>".
dds_entity_t Check(dds_entity_t rc, const std::string& what);

/// Volatile: samples go to the readers matched now. Transient-local: a reader that joins
/// later gets the writer's last `depth` samples at once (the monitor's timing view).
enum class Durability { kVolatile, kTransientLocal };

using QosPtr = std::unique_ptr<dds_qos_t, decltype(&dds_delete_qos)>;

/// Reliable, KEEP_LAST(depth) and a max_blocking_time of 0: with KEEP_LAST the writer's
/// history never fills, and if Cyclone ever throttles, dds_write fails at once instead of
/// holding the telemetry thread.
[[nodiscard]] QosPtr MakeQos(std::int32_t depth, Durability durability);

/// A topic of `participant` with a ROS 2 name; throws std::runtime_error naming it.
dds_entity_t CreateTopic(dds_entity_t participant, const dds_topic_descriptor_t* descriptor,
                         const std::string& name);

/// "rt/<ns>/<leaf>": ROS 2's mapping of topic /<ns>/<leaf> onto DDS.
[[nodiscard]] std::string TopicName(const std::string& ns, const char* leaf);

/// The ROS 2 type name of hiltwin's timing topic (module hiltwin_msgs::msg::dds_, struct Timing_).
inline constexpr const char* kTimingTypeName = "hiltwin_msgs::msg::dds_::Timing_";

/// The user data of a task's command reader: whether it takes commands (--accept-commands).
/// Discovery carries it to every writer that matches, so a sender learns of a refusal before
/// the task's stderr, on another machine, says so.
inline constexpr std::string_view kCommandsAccepted = "hiltwin commands=accepted";
inline constexpr std::string_view kCommandsRefused = "hiltwin commands=refused";

/// Takes every sample `reader` holds, calling `fn(sample, info)` for each that has data.
template <typename Sample, typename Fn>
void TakeAll(dds_entity_t reader, Fn&& fn) {
  constexpr std::size_t kBatch = 16;
  for (;;) {
    std::array<void*, kBatch> samples{};  // null: Cyclone lends its own buffers
    std::array<dds_sample_info_t, kBatch> infos{};
    const dds_return_t n = dds_take(reader, samples.data(), infos.data(), kBatch, kBatch);
    if (n <= 0) return;
    const auto taken = static_cast<std::size_t>(n);
    for (std::size_t i = 0; i < taken; ++i) {
      if (infos[i].valid_data) fn(*static_cast<const Sample*>(samples[i]), infos[i]);
    }
    static_cast<void>(dds_return_loan(reader, samples.data(), n));
    if (taken < kBatch) return;
  }
}

/// A reader of the built-in DCPSPublication topic: every writer on the domain, with its topic,
/// type, participant and QoS (how `ros2 topic list` finds topics).
[[nodiscard]] dds_entity_t CreatePublicationReader(dds_entity_t participant);

/// Sets `text` as the user data of `qos`.
void SetUserData(dds_qos_t* qos, std::string_view text);

/// The user data of a discovered endpoint's QoS ("" when it has none).
[[nodiscard]] std::string UserDataOf(const dds_qos_t* qos);

}  // namespace hiltwin::telemetry::dds
