#include "hiltwin/io/wire_bus.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <thread>

#include "hiltwin/io/conversions.h"

namespace hiltwin::io {

namespace {
constexpr std::uint64_t kMagic = 0x6869'6C74'7769'7265ULL;  // "hiltwire"
constexpr std::uint32_t kLayoutVersion = 3;  // 2: encoder periods in a ring; 3: stop causes
constexpr std::uint32_t kFresh = 0;
constexpr std::uint32_t kInitialising = 1;
constexpr std::uint32_t kReady = 2;
/// twin_sampling_ns when the twin is not inside a transfer.
constexpr std::int64_t kNotSampling = std::numeric_limits<std::int64_t>::max();
}  // namespace

/// One process's presence on the wire.
struct WireSide {
  std::atomic<std::uint64_t> heartbeat;
  std::atomic<std::int64_t> last_beat_ns;
  std::atomic<std::int64_t> step_ns;
  std::atomic<std::int32_t> pid;
  std::atomic<std::uint32_t> attached;
  std::atomic<std::uint32_t> sessions;
  std::atomic<std::uint32_t> stop_cause;  ///< a StopCause; kNone while running
};

/// One encoder period in the ring; each slot is a single-writer seqlock of its own.
struct WirePeriod {
  std::atomic<std::uint64_t> sequence;  ///< 2·index when complete, 2·index + 1 while written
  std::atomic<std::int64_t> start_ns;
  std::atomic<std::uint32_t> subticks;
  std::atomic<std::uint32_t> divider;
  std::atomic<std::uint64_t> start_counts;  ///< 4 × 16-bit two's complement
  std::atomic<std::uint64_t> pulses;        ///< 4 × 16 bits (at most 8192 each)
  std::atomic<std::uint32_t> directions;    ///< 4 × 8-bit two's complement
};

/// The shared segment. Zero-filled memory is a valid initial state of every field.
struct WireSegment {
  std::atomic<std::uint32_t> init_state;
  std::atomic<std::uint32_t> attach_count;
  std::atomic<std::uint64_t> magic;
  std::atomic<std::uint32_t> version;
  std::atomic<std::uint32_t> size;
  WireSide ecs;
  WireSide twin;
  /// ECS -> twin: four packed PWM words (direction, pin, magnitude), 16 bits each.
  std::atomic<std::uint64_t> pwm_words;
  std::atomic<std::uint32_t> twin_pins;  ///< bit c = digital output c of the twin
  /// Twin -> ECS encoder lines: the twin's emulator periods, newest index last published.
  std::atomic<std::uint64_t> encoder_newest;
  /// The twin's clock when it began the transfer in progress (kNotSampling outside one): a
  /// period it is about to publish starts no earlier, so the ECS replays edges only up to here.
  std::atomic<std::int64_t> twin_sampling_ns;
  WirePeriod encoder_periods[kEncoderLineHistory];
};
static_assert(std::atomic<std::uint64_t>::is_always_lock_free &&
                  std::atomic<std::int64_t>::is_always_lock_free &&
                  std::atomic<std::uint32_t>::is_always_lock_free,
              "the wire needs address-free (lock-free) atomics to work across processes");

namespace {

/// kill(pid, 0) succeeds, or fails only for lack of permission: the process exists.
bool ProcessAlive(std::int32_t pid) noexcept { return ::kill(pid, 0) == 0 || errno == EPERM; }

std::uint64_t Pack16(std::size_t c, std::uint16_t value) noexcept {
  return std::uint64_t{value} << (16U * c);
}
std::uint16_t Unpack16(std::uint64_t packed, std::size_t c) noexcept {
  return static_cast<std::uint16_t>((packed >> (16U * c)) & 0xFFFFU);
}

/// What this side reports when the peer announced `cause` (static text, for the run report).
const char* PeerStopMessage(bool ecs_side, std::uint32_t cause) noexcept {
  // Rows: StopCause (kNone unused); columns: seen from the twin, seen from the ECS.
  static constexpr const char* kText[][2] = {
      {"wire: the ECS stopped", "wire: the twin stopped"},
      {"wire: the ECS finished its run", "wire: the twin finished its run"},
      {"wire: the ECS was stopped (signal or stop command)",
       "wire: the twin was stopped (signal or stop command)"},
      {"wire: the ECS aborted its run on its QoS policy",
       "wire: the twin aborted its run on its QoS policy"},
      {"wire: the ECS stopped on a fault (see its report)",
       "wire: the twin stopped on a fault (see its report)"},
      {"wire: the ECS stopped because its peer had stopped",
       "wire: the twin stopped because its peer had stopped"},
  };
  const std::size_t row = cause < std::size(kText) ? cause : 0;
  return kText[row][ecs_side ? 1 : 0];
}

}  // namespace

class WireBus::PwmWire final : public PwmSignalSource {
 public:
  explicit PwmWire(const WireSegment& seg) noexcept : seg_(seg) {}
  void DutyAt(std::int64_t /*t_ns*/, std::array<double, kChannels>& duty_out) noexcept override {
    const std::uint64_t words = seg_.pwm_words.load(std::memory_order_acquire);
    for (std::size_t c = 0; c < kChannels; ++c) {
      duty_out[c] = PwmToDuty(PwmValueFromWord(UnpackPwm(Unpack16(words, c))));
    }
  }

 private:
  const WireSegment& seg_;
};

/// Twin side: publishes the board's emulator periods into the ring. ECS side: reads them.
class WireBus::EncoderWire final : public EncoderLineSink, public EncoderLineSource {
 public:
  explicit EncoderWire(WireSegment& seg) noexcept : seg_(seg) {}

  void OnPeriod(const std::array<PulseSegment, kChannels>& channels) noexcept override {
    const std::uint64_t index = seg_.encoder_newest.load(std::memory_order_relaxed) + 1;
    WirePeriod& slot = seg_.encoder_periods[index % kEncoderLineHistory];
    std::uint64_t starts = 0;
    std::uint64_t pulses = 0;
    std::uint32_t directions = 0;
    for (std::size_t c = 0; c < kChannels; ++c) {
      starts |= Pack16(c, static_cast<std::uint16_t>(channels[c].start_counts));
      pulses |= Pack16(c, static_cast<std::uint16_t>(channels[c].pulses));
      directions |= static_cast<std::uint32_t>(static_cast<std::uint8_t>(channels[c].direction))
                    << (8U * c);
    }
    slot.sequence.store(2 * index + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    slot.start_ns.store(channels[0].start_ns, std::memory_order_relaxed);
    slot.subticks.store(channels[0].subticks, std::memory_order_relaxed);
    slot.divider.store(channels[0].divider, std::memory_order_relaxed);
    slot.start_counts.store(starts, std::memory_order_relaxed);
    slot.pulses.store(pulses, std::memory_order_relaxed);
    slot.directions.store(directions, std::memory_order_relaxed);
    slot.sequence.store(2 * index, std::memory_order_release);
    seg_.encoder_newest.store(index, std::memory_order_release);
  }

  LineView Lines(std::int64_t /*t_ns*/) noexcept override {
    LineView view;
    // seq_cst pairs with the twin's store: a sample that begins after this load reads its clock
    // after the ECS read its own, so it cannot cancel edges the ECS replays now.
    view.known_until_ns = seg_.twin_sampling_ns.load(std::memory_order_seq_cst);
    view.newest = seg_.encoder_newest.load(std::memory_order_acquire);
    return view;
  }

  bool Period(std::uint64_t index, EncoderPeriod& out) noexcept override {
    if (index == 0) return false;
    const WirePeriod& slot = seg_.encoder_periods[index % kEncoderLineHistory];
    // Not 2·index: overwritten by a newer period (or being overwritten). No retry needed: an
    // index the reader asks for was complete before encoder_newest named it.
    const std::uint64_t before = slot.sequence.load(std::memory_order_acquire);
    if (before != 2 * index) return false;
    const std::int64_t start_ns = slot.start_ns.load(std::memory_order_relaxed);
    const std::uint32_t subticks = slot.subticks.load(std::memory_order_relaxed);
    const std::uint32_t divider = slot.divider.load(std::memory_order_relaxed);
    const std::uint64_t starts = slot.start_counts.load(std::memory_order_relaxed);
    const std::uint64_t pulses = slot.pulses.load(std::memory_order_relaxed);
    const std::uint32_t directions = slot.directions.load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (slot.sequence.load(std::memory_order_relaxed) != before) return false;
    out.index = index;
    for (std::size_t c = 0; c < kChannels; ++c) {
      PulseSegment& s = out.channels[c];
      s.start_counts = static_cast<std::int16_t>(Unpack16(starts, c));
      s.pulses = Unpack16(pulses, c);
      s.direction = static_cast<std::int8_t>((directions >> (8U * c)) & 0xFFU);
      s.start_ns = start_ns;
      s.subticks = subticks;
      s.divider = divider;
    }
    return true;
  }

 private:
  WireSegment& seg_;
};

std::string WireBus::SegmentName(const std::string& name) {
  bool ok = !name.empty() && name.size() <= 64 && name[0] != '.';
  for (const char ch : name) {
    const bool allowed = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                         (ch >= '0' && ch <= '9') || ch == '_' || ch == '-' || ch == '.';
    ok = ok && allowed;
  }
  if (!ok) {
    throw std::invalid_argument("wire name '" + name +
                                "' is not 1-64 characters of letters, digits, '_', '-', '.' "
                                "(not starting with '.'); e.g. wire:bench1");
  }
  return "/hiltwin-wire-" + name;
}

void WireBus::Unlink(const std::string& name) { ::shm_unlink(SegmentName(name).c_str()); }

namespace {

/// Opens (creating if needed), sizes and maps the named segment.
WireSegment* MapSegment(const std::string& segment_name, const std::string& label) {
  const int fd = ::shm_open(segment_name.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0660);
  if (fd < 0) {
    throw std::runtime_error("cannot open shared memory " + segment_name + " for " + label +
                             ": " + std::strerror(errno) + "; check /dev/shm is mounted and writable");
  }
  struct stat info {};
  const auto size = static_cast<off_t>(sizeof(WireSegment));
  if (::fstat(fd, &info) != 0 || (info.st_size != 0 && info.st_size != size) ||
      (info.st_size == 0 && ::ftruncate(fd, size) != 0)) {
    const int error = errno;
    ::close(fd);
    throw std::runtime_error("shared memory " + segment_name + " has the wrong size or cannot " +
                             "be sized (" + std::strerror(error) + "); it may be from another " +
                             "hiltwin version: remove /dev/shm" + segment_name + " and retry");
  }
  void* map = ::mmap(nullptr, sizeof(WireSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (map == MAP_FAILED) {
    throw std::runtime_error("cannot map " + segment_name + ": " + std::strerror(errno));
  }
  return static_cast<WireSegment*>(map);
}

/// Whoever comes first lays the segment out; the other waits (start-up only, bounded). False
/// when the segment is not a wire of this layout version.
bool LayOutOrCheck(WireSegment& segment) {
  std::uint32_t expected = kFresh;
  if (segment.init_state.compare_exchange_strong(expected, kInitialising)) {
    segment.magic.store(kMagic, std::memory_order_relaxed);
    segment.version.store(kLayoutVersion, std::memory_order_relaxed);
    segment.size.store(static_cast<std::uint32_t>(sizeof(WireSegment)), std::memory_order_relaxed);
    segment.init_state.store(kReady, std::memory_order_release);
  } else {
    for (int i = 0; i < 1000 && segment.init_state.load(std::memory_order_acquire) != kReady; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  return segment.init_state.load(std::memory_order_acquire) == kReady &&
         segment.magic.load() == kMagic && segment.version.load() == kLayoutVersion &&
         segment.size.load() == sizeof(WireSegment);
}

}  // namespace

WireBus::WireBus(const std::string& name, Image side, std::optional<Image> board_image)
    : label_("wire:" + name),
      segment_name_(SegmentName(name)),
      side_(side),
      board_(board_image.value_or(side), &clock_) {
  segment_ = MapSegment(segment_name_, label_);
  if (!LayOutOrCheck(*segment_)) {
    ::munmap(segment_, sizeof(WireSegment));
    segment_ = nullptr;
    throw std::runtime_error("shared memory " + segment_name_ + " is not a hiltwin wire of this " +
                             "version; remove /dev/shm" + segment_name_ + " and retry");
  }
  Attach();
  pwm_wire_ = std::make_unique<PwmWire>(*segment_);
  encoder_wire_ = std::make_unique<EncoderWire>(*segment_);
  if (side_ == Image::kIcoboardInverse) {
    segment_->twin_sampling_ns.store(kNotSampling);  // a crashed twin may have left it set
    board_.SetPwmSource(pwm_wire_.get());
    board_.SetEncoderSink(encoder_wire_.get());
  } else {
    board_.SetEncoderSource(encoder_wire_.get());
  }
}

void WireBus::Attach() {
  WireSide& self = side_ == Image::kIcoboard ? segment_->ecs : segment_->twin;
  WireSide& peer = side_ == Image::kIcoboard ? segment_->twin : segment_->ecs;
  const std::int32_t previous_pid = self.pid.load();
  if (self.attached.load() != 0 && previous_pid > 0 && ProcessAlive(previous_pid)) {
    ::munmap(segment_, sizeof(WireSegment));
    segment_ = nullptr;
    throw std::runtime_error(label_ + " already has a" +
                             (side_ == Image::kIcoboard ? "n ECS" : " twin") +
                             " attached (pid " + std::to_string(previous_pid) +
                             "); stop it first or use another wire name");
  }
  // A peer that crashed never detached: its flags would make this process report "stopped
  // updating its heartbeat" (or "detached") although no peer has been there since it started.
  std::int32_t peer_pid = peer.pid.load();
  if (peer_pid > 0 && !ProcessAlive(peer_pid) && peer.pid.compare_exchange_strong(peer_pid, 0)) {
    peer.attached.store(0);
    peer.sessions.store(0);
    peer.stop_cause.store(0);
    // A new peer stores its pid before its flags: if one arrived while these were cleared,
    // give its presence back.
    if (peer.pid.load() != 0) {
      peer.attached.store(1);
      peer.sessions.fetch_add(1);
    }
  }
  self.pid.store(::getpid());
  self.stop_cause.store(static_cast<std::uint32_t>(StopCause::kNone));
  self.step_ns.store(0);
  self.last_beat_ns.store(clock_.NowNs());
  self.heartbeat.fetch_add(1);
  self.attached.store(1);
  self.sessions.fetch_add(1);
  segment_->attach_count.fetch_add(1);
}

WireBus::~WireBus() {
  if (segment_ == nullptr) return;
  WireSide& self = side_ == Image::kIcoboard ? segment_->ecs : segment_->twin;
  const WireSide& peer = side_ == Image::kIcoboard ? segment_->twin : segment_->ecs;
  self.attached.store(0);
  segment_->attach_count.fetch_sub(1);
  // The last one out removes the segment. A peer that crashed never detached, so its pid is
  // checked too; a running peer keeps its mapping even if the name is removed under it.
  const std::int32_t peer_pid = peer.pid.load();
  const bool peer_alive = peer.attached.load() != 0 && peer_pid > 0 && ProcessAlive(peer_pid);
  if (!peer_alive) ::shm_unlink(segment_name_.c_str());
  ::munmap(segment_, sizeof(WireSegment));
}

void WireBus::Publish(std::int64_t now_ns) noexcept {
  WireSegment& seg = *segment_;
  if (side_ == Image::kIcoboard) {
    std::uint64_t words = 0;
    for (std::size_t c = 0; c < kChannels; ++c) {
      words |= Pack16(c, PackPwm(PwmWordFromValue(board_.pwm_output()[c], board_.pins_out()[c])));
    }
    seg.pwm_words.store(words, std::memory_order_release);
  } else {
    std::uint32_t pins = 0;  // the encoder periods went out through the sink already
    for (std::size_t c = 0; c < kChannels; ++c) {
      if (board_.pins_out()[c]) pins |= 1U << c;
    }
    seg.twin_pins.store(pins, std::memory_order_release);
  }
  Beat(now_ns);
}

void WireBus::Beat(std::int64_t now_ns) noexcept {
  WireSide& self = side_ == Image::kIcoboard ? segment_->ecs : segment_->twin;
  self.step_ns.store(board_.step_ns(), std::memory_order_relaxed);
  self.last_beat_ns.store(now_ns, std::memory_order_relaxed);
  self.heartbeat.fetch_add(1, std::memory_order_release);
}

BusStatus WireBus::Poll() noexcept {
  Beat(clock_.NowNs());
  return PeerStatus();
}

void WireBus::AnnounceStop(StopCause cause) noexcept {
  WireSide& self = side_ == Image::kIcoboard ? segment_->ecs : segment_->twin;
  self.stop_cause.store(static_cast<std::uint32_t>(cause), std::memory_order_release);
}

BusStatus WireBus::PeerStatus() const noexcept {
  const WireSide& peer = side_ == Image::kIcoboard ? segment_->twin : segment_->ecs;
  const bool ecs_side = side_ == Image::kIcoboard;
  if (peer.sessions.load(std::memory_order_acquire) == 0) {
    return {BusResult::kPeerAbsent, ecs_side ? "wire: no twin process has attached yet"
                                             : "wire: no ECS process has attached yet"};
  }
  if (const std::uint32_t cause = peer.stop_cause.load(std::memory_order_acquire); cause != 0) {
    return {BusResult::kPeerStopped, PeerStopMessage(ecs_side, cause)};
  }
  if (peer.attached.load(std::memory_order_acquire) == 0) {
    return {BusResult::kPeerLost, ecs_side ? "wire: the twin process detached (it stopped); "
                                             "restart it, either side may start first"
                                           : "wire: the ECS process detached (it stopped); "
                                             "restart it, either side may start first"};
  }
  const std::int64_t step_ns = peer.step_ns.load(std::memory_order_relaxed);
  std::int64_t timeout_ns = 20 * step_ns;
  if (timeout_ns < kWireMinHeartbeatTimeoutNs) timeout_ns = kWireMinHeartbeatTimeoutNs;
  const std::int64_t age_ns = clock_.NowNs() - peer.last_beat_ns.load(std::memory_order_acquire);
  if (age_ns > timeout_ns) {
    return {BusResult::kPeerLost,
            ecs_side ? "wire: the twin process stopped updating its heartbeat (crashed, hung or "
                       "killed); restart it, either side may start first"
                     : "wire: the ECS process stopped updating its heartbeat (crashed, hung or "
                       "killed); restart it, either side may start first"};
  }
  return {};
}

template <typename Transfers>
BusStatus WireBus::RunOnBoard(Transfers&& transfers) noexcept {
  WireSegment& seg = *segment_;
  std::array<bool, kChannels> pins{};
  if (side_ == Image::kIcoboardInverse) {
    const std::uint64_t words = seg.pwm_words.load(std::memory_order_acquire);
    for (std::size_t c = 0; c < kChannels; ++c) pins[c] = UnpackPwm(Unpack16(words, c)).pin;
  } else {
    const std::uint32_t bits = seg.twin_pins.load(std::memory_order_acquire);
    for (std::size_t c = 0; c < kChannels; ++c) pins[c] = ((bits >> c) & 1U) != 0;
  }
  board_.SetDigitalInputs(pins);
  const bool twin = side_ == Image::kIcoboardInverse;
  // The board samples (and publishes its period) while acting on the request; the fetch's NOOP
  // changes nothing on the wire, so one window around both keeps the ECS's replay bound valid.
  if (twin) seg.twin_sampling_ns.store(clock_.NowNs(), std::memory_order_seq_cst);
  transfers();
  if (twin) seg.twin_sampling_ns.store(kNotSampling, std::memory_order_seq_cst);
  Publish(clock_.NowNs());
  return PeerStatus();
}

BusStatus WireBus::Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept {
  return RunOnBoard([&]() noexcept { board_.Exchange(mosi, miso); });
}

BusStatus WireBus::TransferPair(const FrameBytes& request, FrameBytes& request_miso,
                                const FrameBytes& fetch, FrameBytes& answer) noexcept {
  return RunOnBoard([&]() noexcept {
    board_.Exchange(request, request_miso);
    board_.Exchange(fetch, answer);
  });
}

bool WireBus::ReadEncoderPeriod(std::uint64_t index, EncoderPeriod& out) const noexcept {
  return encoder_wire_->Period(index, out);
}

}  // namespace hiltwin::io
