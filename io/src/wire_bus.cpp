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
#include <stdexcept>
#include <thread>

#include "hiltwin/io/conversions.h"

namespace hiltwin::io {

namespace {
constexpr std::uint64_t kMagic = 0x6869'6C74'7769'7265ULL;  // "hiltwire"
constexpr std::uint32_t kLayoutVersion = 1;
constexpr std::uint32_t kFresh = 0;
constexpr std::uint32_t kInitialising = 1;
constexpr std::uint32_t kReady = 2;
constexpr int kSeqlockAttempts = 16;
}  // namespace

/// One process's presence on the wire.
struct WireSide {
  std::atomic<std::uint64_t> heartbeat;
  std::atomic<std::int64_t> last_beat_ns;
  std::atomic<std::int64_t> step_ns;
  std::atomic<std::int32_t> pid;
  std::atomic<std::uint32_t> attached;
  std::atomic<std::uint32_t> sessions;
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
  /// Twin -> ECS encoder lines, guarded by a single-writer seqlock.
  std::atomic<std::uint32_t> encoder_sequence;
  std::atomic<std::int64_t> encoder_start_ns;
  std::atomic<std::uint32_t> encoder_subticks;
  std::atomic<std::uint32_t> encoder_divider;
  std::atomic<std::uint64_t> encoder_start_counts;  ///< 4 × 16-bit two's complement
  std::atomic<std::uint64_t> encoder_pulses;        ///< 4 × 16 bits
  std::atomic<std::uint32_t> encoder_directions;    ///< 4 × 8-bit two's complement
  std::atomic<std::uint32_t> twin_pins;             ///< bit c = digital output c of the twin
};
static_assert(std::atomic<std::uint64_t>::is_always_lock_free &&
                  std::atomic<std::int64_t>::is_always_lock_free &&
                  std::atomic<std::uint32_t>::is_always_lock_free,
              "the wire needs address-free (lock-free) atomics to work across processes");

namespace {

std::uint64_t Pack16(std::size_t c, std::uint16_t value) noexcept {
  return std::uint64_t{value} << (16U * c);
}
std::uint16_t Unpack16(std::uint64_t packed, std::size_t c) noexcept {
  return static_cast<std::uint16_t>((packed >> (16U * c)) & 0xFFFFU);
}

/// The encoder lines as the ECS side last read them.
struct EncoderSnapshot {
  std::array<PulseSegment, kChannels> segments{};
  std::uint32_t pins = 0;
};

bool ReadEncoder(const WireSegment& seg, EncoderSnapshot& out) noexcept {
  for (int attempt = 0; attempt < kSeqlockAttempts; ++attempt) {
    const std::uint32_t before = seg.encoder_sequence.load(std::memory_order_acquire);
    if ((before & 1U) != 0) continue;  // writer inside
    const std::int64_t start_ns = seg.encoder_start_ns.load(std::memory_order_relaxed);
    const std::uint32_t subticks = seg.encoder_subticks.load(std::memory_order_relaxed);
    const std::uint32_t divider = seg.encoder_divider.load(std::memory_order_relaxed);
    const std::uint64_t starts = seg.encoder_start_counts.load(std::memory_order_relaxed);
    const std::uint64_t pulses = seg.encoder_pulses.load(std::memory_order_relaxed);
    const std::uint32_t directions = seg.encoder_directions.load(std::memory_order_relaxed);
    const std::uint32_t pins = seg.twin_pins.load(std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_acquire);
    if (seg.encoder_sequence.load(std::memory_order_relaxed) != before) continue;
    for (std::size_t c = 0; c < kChannels; ++c) {
      PulseSegment& s = out.segments[c];
      s.start_counts = static_cast<std::int16_t>(Unpack16(starts, c));
      s.pulses = Unpack16(pulses, c);
      s.direction = static_cast<std::int8_t>((directions >> (8U * c)) & 0xFFU);
      s.start_ns = start_ns;
      s.subticks = subticks;
      s.divider = divider;
    }
    out.pins = pins;
    return true;
  }
  return false;
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

class WireBus::EncoderWire final : public EncoderLineSource {
 public:
  EncoderWire(const WireSegment& seg, std::uint64_t& fallbacks) noexcept
      : seg_(seg), fallbacks_(fallbacks) {}
  void CountsAt(std::int64_t t_ns, std::array<std::int32_t, kChannels>& counts_out) noexcept override {
    if (!ReadEncoder(seg_, snapshot_)) ++fallbacks_;
    for (std::size_t c = 0; c < kChannels; ++c) counts_out[c] = snapshot_.segments[c].PositionAt(t_ns);
  }
  [[nodiscard]] std::uint32_t pins() const noexcept { return snapshot_.pins; }

 private:
  const WireSegment& seg_;
  std::uint64_t& fallbacks_;
  EncoderSnapshot snapshot_{};
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

WireBus::WireBus(const std::string& name, Image side)
    : label_("wire:" + name), segment_name_(SegmentName(name)), side_(side), board_(side, &clock_) {
  const int fd = ::shm_open(segment_name_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0660);
  if (fd < 0) {
    throw std::runtime_error("cannot open shared memory " + segment_name_ + " for " + label_ +
                             ": " + std::strerror(errno) + "; check /dev/shm is mounted and writable");
  }
  struct stat info {};
  const auto size = static_cast<off_t>(sizeof(WireSegment));
  if (::fstat(fd, &info) != 0 || (info.st_size != 0 && info.st_size != size) ||
      (info.st_size == 0 && ::ftruncate(fd, size) != 0)) {
    const int error = errno;
    ::close(fd);
    throw std::runtime_error("shared memory " + segment_name_ + " has the wrong size or cannot " +
                             "be sized (" + std::strerror(error) + "); it may be from another " +
                             "hiltwin version: remove /dev/shm" + segment_name_ + " and retry");
  }
  void* map = ::mmap(nullptr, sizeof(WireSegment), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (map == MAP_FAILED) {
    throw std::runtime_error("cannot map " + segment_name_ + ": " + std::strerror(errno));
  }
  segment_ = static_cast<WireSegment*>(map);

  // Whoever comes first lays the segment out; the other waits (start-up only, bounded).
  std::uint32_t expected = kFresh;
  if (segment_->init_state.compare_exchange_strong(expected, kInitialising)) {
    segment_->magic.store(kMagic, std::memory_order_relaxed);
    segment_->version.store(kLayoutVersion, std::memory_order_relaxed);
    segment_->size.store(static_cast<std::uint32_t>(sizeof(WireSegment)), std::memory_order_relaxed);
    segment_->init_state.store(kReady, std::memory_order_release);
  } else {
    for (int i = 0; i < 1000 && segment_->init_state.load(std::memory_order_acquire) != kReady; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  if (segment_->init_state.load(std::memory_order_acquire) != kReady ||
      segment_->magic.load() != kMagic || segment_->version.load() != kLayoutVersion ||
      segment_->size.load() != sizeof(WireSegment)) {
    ::munmap(segment_, sizeof(WireSegment));
    segment_ = nullptr;
    throw std::runtime_error("shared memory " + segment_name_ + " is not a hiltwin wire of this " +
                             "version; remove /dev/shm" + segment_name_ + " and retry");
  }

  WireSide& self = side_ == Image::kIcoboard ? segment_->ecs : segment_->twin;
  const std::int32_t previous_pid = self.pid.load();
  if (self.attached.load() != 0 && previous_pid > 0 &&
      (::kill(previous_pid, 0) == 0 || errno == EPERM)) {
    ::munmap(segment_, sizeof(WireSegment));
    segment_ = nullptr;
    throw std::runtime_error(label_ + " already has a" +
                             (side_ == Image::kIcoboard ? "n ECS" : " twin") +
                             " attached (pid " + std::to_string(previous_pid) +
                             "); stop it first or use another wire name");
  }
  self.pid.store(::getpid());
  self.step_ns.store(0);
  self.last_beat_ns.store(clock_.NowNs());
  self.heartbeat.fetch_add(1);
  self.attached.store(1);
  self.sessions.fetch_add(1);
  segment_->attach_count.fetch_add(1);

  pwm_wire_ = std::make_unique<PwmWire>(*segment_);
  encoder_wire_ = std::make_unique<EncoderWire>(*segment_, seqlock_fallbacks_);
  if (side_ == Image::kIcoboardInverse) {
    board_.SetPwmSource(pwm_wire_.get());
  } else {
    board_.SetEncoderSource(encoder_wire_.get());
  }
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
  const bool peer_alive = peer.attached.load() != 0 && peer_pid > 0 &&
                          (::kill(peer_pid, 0) == 0 || errno == EPERM);
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
    std::uint64_t starts = 0;
    std::uint64_t pulses = 0;
    std::uint32_t directions = 0;
    std::uint32_t pins = 0;
    for (std::size_t c = 0; c < kChannels; ++c) {
      const PulseSegment& s = board_.encoder(c).segment();
      starts |= Pack16(c, static_cast<std::uint16_t>(s.start_counts));
      pulses |= Pack16(c, static_cast<std::uint16_t>(s.pulses));
      directions |= (static_cast<std::uint32_t>(static_cast<std::uint8_t>(s.direction))) << (8U * c);
      if (board_.pins_out()[c]) pins |= 1U << c;
    }
    const PulseSegment& first = board_.encoder(0).segment();
    const std::uint32_t sequence = seg.encoder_sequence.load(std::memory_order_relaxed);
    seg.encoder_sequence.store(sequence + 1, std::memory_order_relaxed);
    std::atomic_thread_fence(std::memory_order_release);
    seg.encoder_start_ns.store(first.start_ns, std::memory_order_relaxed);
    seg.encoder_subticks.store(first.subticks, std::memory_order_relaxed);
    seg.encoder_divider.store(first.divider, std::memory_order_relaxed);
    seg.encoder_start_counts.store(starts, std::memory_order_relaxed);
    seg.encoder_pulses.store(pulses, std::memory_order_relaxed);
    seg.encoder_directions.store(directions, std::memory_order_relaxed);
    seg.twin_pins.store(pins, std::memory_order_relaxed);
    seg.encoder_sequence.store(sequence + 2, std::memory_order_release);
  }
  WireSide& self = side_ == Image::kIcoboard ? seg.ecs : seg.twin;
  self.step_ns.store(board_.step_ns(), std::memory_order_relaxed);
  self.last_beat_ns.store(now_ns, std::memory_order_relaxed);
  self.heartbeat.fetch_add(1, std::memory_order_release);
}

BusStatus WireBus::PeerStatus() const noexcept {
  const WireSide& peer = side_ == Image::kIcoboard ? segment_->twin : segment_->ecs;
  const bool ecs_side = side_ == Image::kIcoboard;
  if (peer.sessions.load(std::memory_order_acquire) == 0) {
    return {BusResult::kPeerAbsent, ecs_side ? "wire: no twin process has attached yet"
                                             : "wire: no ECS process has attached yet"};
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

BusStatus WireBus::Transfer(const FrameBytes& mosi, FrameBytes& miso) noexcept {
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
  board_.Exchange(mosi, miso);
  Publish(clock_.NowNs());
  return PeerStatus();
}

}  // namespace hiltwin::io
