#include "hiltwin/io/wire_bus.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <thread>

#include "hiltwin/io/conversions.h"
#include "hiltwin/io/wire_segment.h"
#include "hiltwin/kernel_glue/shared_memory.h"
#include "wire_guard.h"
#include "wire_lockstep.h"
#include "hiltwin/lockfree/seqlock.h"

namespace hiltwin::io {

namespace {
using namespace wire;
/// Times the peer publishes (a period's start, its heartbeat, its sampling moment) are its
/// CLOCK_MONOTONIC readings, so never later than this side's clock by more than the moment
/// between its reading and this side's: anything a second ahead was not written by a peer.
constexpr std::int64_t kFutureSlackNs = 1'000'000'000;
/// A twin exchange (clock reads, board model, wire) takes longer than this, so the ring's
/// newest index cannot advance faster; used, with a ring's worth of slack, to tell an absurd
/// index from a fast twin.
constexpr std::int64_t kMinTwinExchangeNs = 200;
/// INIT's step is a 32-bit count of ns: a published step beyond it is not a board's.
constexpr std::int64_t kMaxStepNs = 0xFFFF'FFFFLL;
/// A pid that changed while the peer's session count did not is accepted for this long: a
/// new peer stores its pid a few stores before it bumps the session count.
constexpr std::int64_t kIdentitySettleNs = 250'000'000;
constexpr std::uint32_t kLastStopCause = static_cast<std::uint32_t>(StopCause::kPeerStopped);
}  // namespace

namespace {

/// A full barrier between this thread's memory accesses and its clock reads (a clock read is no
/// memory access, so acquire/release cannot order it; arm64 would reorder them). ThreadSanitizer
/// models no fences and g++ 12 refuses them under -fsanitize=thread (-Wtsan); what TSan checks,
/// races on memory, is carried by the atomics' own orderings, so there a compiler-only fence
/// keeps the source order and the instrumented build stays the same program.
void FenceAgainstClockReads() noexcept {
#if defined(__SANITIZE_THREAD__)
  std::atomic_signal_fence(std::memory_order_seq_cst);
#else
  std::atomic_thread_fence(std::memory_order_seq_cst);
#endif
}

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

namespace {

/// Whether `words` (4 × 16-bit PWM words) could come from an ECS board: magnitude at most full
/// scale, and no "negative zero" (PwmWordFromValue never makes one). Names the first bad one.
bool CheckPwmWords(std::uint64_t words, WireGuard* guard) noexcept;

/// Decodes period `index` from its words, checking each field against what a twin board can
/// publish (INIT's ranges, the pulse limit, directions -1/0/+1, a start not in the future).
bool DecodePeriod(const std::array<std::uint64_t, kPeriodWords>& words, std::uint64_t index,
                  std::int64_t now_ns, EncoderPeriod& out, WireGuard* guard) noexcept;

}  // namespace

class WireBus::PwmWire final : public PwmSignalSource {
 public:
  PwmWire(const WireSegment& seg, WireGuard& guard) noexcept : seg_(seg), guard_(guard) {}
  void DutyAt(std::int64_t /*t_ns*/, std::array<double, kChannels>& duty_out) noexcept override {
    duty_out.fill(0.0);  // idle when the wire is corrupted: nothing read from it is used
    if (!guard_.ok()) return;
    const std::uint64_t words = seg_.pwm_words.load(std::memory_order_acquire);
    if (!CheckPwmWords(words, &guard_)) return;
    for (std::size_t c = 0; c < kChannels; ++c) {
      duty_out[c] = PwmToDuty(PwmValueFromWord(UnpackPwm(Unpack16(words, c))));
    }
  }

 private:
  const WireSegment& seg_;
  WireGuard& guard_;
};

/// Twin side: publishes the board's emulator periods into the ring. ECS side: reads them.
class WireBus::EncoderWire final : public EncoderLineSink, public EncoderLineSource {
 public:
  EncoderWire(WireSegment& seg, WireGuard& guard, const kernel_glue::Clock& clock) noexcept
      : seg_(seg), guard_(guard), clock_(clock) {}

  void OnPeriod(const std::array<PulseSegment, kChannels>& channels) noexcept override {
    // Only this twin writes encoder_newest: another value there was written by someone else,
    // and numbering on from it would publish under an index the ECS must refuse.
    const std::uint64_t found = seg_.encoder_newest.load(std::memory_order_relaxed);
    if (found != guard_.published) {
      guard_.Fail("wire: the ring's newest index is %llu, but this twin published up to %llu",
                  static_cast<unsigned long long>(found),
                  static_cast<unsigned long long>(guard_.published));
    }
    const std::uint64_t index = ++guard_.published;
    std::array<std::uint64_t, kPeriodWords> words{};
    words[0] = static_cast<std::uint64_t>(channels[0].start_ns);
    words[1] = std::uint64_t{channels[0].subticks} << 32U | channels[0].divider;
    for (std::size_t c = 0; c < kChannels; ++c) {
      words[2] |= Pack16(c, static_cast<std::uint16_t>(channels[c].start_counts));
      words[3] |= Pack16(c, static_cast<std::uint16_t>(channels[c].pulses));
      words[4] |= std::uint64_t{static_cast<std::uint8_t>(channels[c].direction)} << (8U * c);
    }
    lockfree::SeqlockWrite(seg_.encoder_periods[index % kEncoderLineHistory], index, words);
    seg_.encoder_newest.store(index, std::memory_order_release);
  }

  LineView Lines(std::int64_t t_ns) noexcept override {
    LineView view;  // newest 0: the lines rest where they are (and so after a corruption)
    now_ns_ = t_ns;
    if (!guard_.ok()) return view;
    // seq_cst pairs with the twin's store: a sample that begins after this load reads its clock
    // after the ECS read its own, so it cannot cancel edges the ECS replays now. The fence keeps
    // the load after the caller's clock read (t_ns): a clock read is no memory access, and on
    // arm64's weaker ordering the load could otherwise be satisfied first.
    FenceAgainstClockReads();
    const std::int64_t until_ns = seg_.twin_sampling_ns.load(std::memory_order_seq_cst);
    const std::uint64_t newest = seg_.encoder_newest.load(std::memory_order_acquire);
    // The loads may come long after t_ns was read (this thread preempted): before calling a
    // time "in the future", look at the clock again (only then: the usual path reads it once).
    std::int64_t now_ns = t_ns;
    if (until_ns != kNotSampling && until_ns > now_ns + kFutureSlackNs) now_ns = clock_.NowNs();
    if (until_ns != kNotSampling && (until_ns < 0 || until_ns > now_ns + kFutureSlackNs)) {
      guard_.Fail("wire: the twin's sampling moment %lld ns is not a time of this clock (now %lld)",
                  static_cast<long long>(until_ns), static_cast<long long>(now_ns));
      return view;
    }
    if (!CheckNewest(newest, t_ns)) return view;
    view.known_until_ns = until_ns;
    view.newest = newest;
    return view;
  }

  bool Period(std::uint64_t index, EncoderPeriod& out) noexcept override {
    if (index == 0 || !guard_.ok()) return false;
    // Refused when not version 2·index: overwritten by a newer period, being overwritten, or
    // torn for good. No retry: an index the reader asks for was complete before
    // encoder_newest named it, so a refusal is a loss (a resync), never a reason to wait.
    std::array<std::uint64_t, kPeriodWords> words{};
    if (!lockfree::SeqlockRead(seg_.encoder_periods[index % kEncoderLineHistory], index, words)) return false;
    if (static_cast<std::int64_t>(words[0]) > now_ns_ + kFutureSlackNs) now_ns_ = clock_.NowNs();
    return DecodePeriod(words, index, now_ns_, out, &guard_);
  }

  /// Period() for diagnostics: checked against `now_ns`, nothing latched.
  bool Peek(std::uint64_t index, std::int64_t now_ns, EncoderPeriod& out) const noexcept {
    std::array<std::uint64_t, kPeriodWords> words{};
    if (index == 0 ||
        !lockfree::SeqlockRead(seg_.encoder_periods[index % kEncoderLineHistory], index, words)) {
      return false;
    }
    return DecodePeriod(words, index, now_ns, out, nullptr);
  }

 private:
  /// The newest index never goes back (a restarted twin numbers on) and cannot run further
  /// ahead than a twin exchanging flat out since the last read, plus a ring's worth.
  bool CheckNewest(std::uint64_t newest, std::int64_t t_ns) noexcept {
    const std::uint64_t seen = guard_.newest_seen;
    if (newest < seen) {
      guard_.Fail("wire: the ring's newest index went back from %llu to %llu",
                  static_cast<unsigned long long>(seen), static_cast<unsigned long long>(newest));
      return false;
    }
    // From the clock reading before the last load to one after this load (the usual path uses
    // t_ns, read before it, and reads the clock again only when that bound is exceeded).
    const auto reachable = [&](std::int64_t until_ns) {
      const std::int64_t elapsed_ns =
          until_ns > guard_.newest_seen_ns ? until_ns - guard_.newest_seen_ns : 0;
      return kEncoderLineHistory + static_cast<std::uint64_t>(elapsed_ns / kMinTwinExchangeNs);
    };
    if (newest - seen > reachable(t_ns) && newest - seen > reachable(clock_.NowNs())) {
      const std::int64_t elapsed_ns = clock_.NowNs() - guard_.newest_seen_ns;
      guard_.Fail("wire: the ring's newest index jumped from %llu to %llu within %lld ns",
                  static_cast<unsigned long long>(seen), static_cast<unsigned long long>(newest),
                  static_cast<long long>(elapsed_ns));
      return false;
    }
    guard_.newest_seen = newest;
    guard_.newest_seen_ns = t_ns;
    return true;
  }

  WireSegment& seg_;
  WireGuard& guard_;
  const kernel_glue::Clock& clock_;  ///< the board's clock (wall or lockstep)
  std::int64_t now_ns_ = 0;  ///< the ECS board's time at its current read of the lines
};

namespace {

bool CheckPwmWords(std::uint64_t words, WireGuard* guard) noexcept {
  for (std::size_t c = 0; c < kChannels; ++c) {
    const PwmWord word = UnpackPwm(Unpack16(words, c));
    if (word.magnitude > kPwmMagnitudeMax || (word.negative && word.magnitude == 0)) {
      if (guard != nullptr) {
        guard->Fail("wire: PWM word %zu is 0x%04x (magnitude %u, largest %u, sign %s)", c,
                    unsigned{Unpack16(words, c)}, unsigned{word.magnitude},
                    unsigned{kPwmMagnitudeMax}, word.negative ? "negative" : "positive");
      }
      return false;
    }
  }
  return true;
}

/// The first field of `period` no twin board publishes, as "has <field> <value> (<allowed>)"
/// into `what`; true when there is none.
bool PeriodFieldsPossible(const EncoderPeriod& period, std::int64_t now_ns, char* what,
                          std::size_t size) noexcept {
  const PulseSegment& first = period.channels[0];
  if (first.divider < kMinClockDivider || first.divider > kMaxClockDivider) {
    std::snprintf(what, size, "divider %u (a board uses %u..%u)", first.divider, kMinClockDivider,
                  kMaxClockDivider);
    return false;
  }
  if (first.subticks < 1 || first.subticks > kMaxSubticksPerStep) {
    std::snprintf(what, size, "%u sub-ticks (a board uses 1..%u)", first.subticks,
                  kMaxSubticksPerStep);
    return false;
  }
  if (first.start_ns < 0 || first.start_ns > now_ns + kFutureSlackNs) {
    std::snprintf(what, size, "start %lld ns (this clock reads %lld ns)",
                  static_cast<long long>(first.start_ns), static_cast<long long>(now_ns));
    return false;
  }
  for (std::size_t c = 0; c < kChannels; ++c) {
    const PulseSegment& s = period.channels[c];
    const std::uint32_t limit = std::min(first.subticks, kMaxRepresentablePulses);
    if (s.pulses > limit) {
      std::snprintf(what, size, "%u pulses on channel %zu (at most %u in one period)", s.pulses, c,
                    limit);
      return false;
    }
    if (s.direction < -1 || s.direction > 1) {
      std::snprintf(what, size, "direction %d on channel %zu (-1, 0 or 1)", s.direction, c);
      return false;
    }
    if (s.start_counts < kEncoderFieldMin || s.start_counts > kEncoderFieldMax) {
      std::snprintf(what, size, "start position %d on channel %zu (%d..%d)", s.start_counts, c,
                    kEncoderFieldMin, kEncoderFieldMax);
      return false;
    }
  }
  return true;
}

bool DecodePeriod(const std::array<std::uint64_t, kPeriodWords>& words, std::uint64_t index,
                  std::int64_t now_ns, EncoderPeriod& out, WireGuard* guard) noexcept {
  out.index = index;
  for (std::size_t c = 0; c < kChannels; ++c) {
    PulseSegment& s = out.channels[c];
    s.start_counts = static_cast<std::int16_t>(Unpack16(words[2], c));
    s.pulses = Unpack16(words[3], c);
    s.direction = static_cast<std::int8_t>((words[4] >> (8U * c)) & 0xFFU);
    s.start_ns = static_cast<std::int64_t>(words[0]);
    s.subticks = static_cast<std::uint32_t>(words[1] >> 32U);
    s.divider = static_cast<std::uint32_t>(words[1] & 0xFFFF'FFFFU);
  }
  std::array<char, 128> what{};
  bool possible = PeriodFieldsPossible(out, now_ns, what.data(), what.size());
  if (possible && (words[4] >> 32U) != 0) {
    std::snprintf(what.data(), what.size(), "reserved direction bits 0x%llx set",
                  static_cast<unsigned long long>(words[4] >> 32U));
    possible = false;
  }
  if (!possible && guard != nullptr) {
    guard->Fail("wire: encoder period %llu has %s", static_cast<unsigned long long>(index),
                what.data());
  }
  return possible;
}

}  // namespace

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

std::string WireBus::SegmentPath(const std::string& name) { return "/dev/shm" + SegmentName(name); }

namespace {

std::string OctalMode(unsigned mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", mode & 07777U);
  return text;
}

/// Refuses a segment another user could have written (or can write): it must be a regular file
/// of this effective user with mode 0600 exactly. Empty when it is fine, else why not.
std::string OwnerOnlyProblem(const struct stat& info) {
  const auto mode = static_cast<unsigned>(info.st_mode) & 0777U;
  if (!S_ISREG(info.st_mode)) return "is not a regular file";
  if (info.st_uid != ::geteuid()) {
    return "belongs to uid " + std::to_string(info.st_uid) + ", not to this process's uid " +
           std::to_string(::geteuid());
  }
  if (mode != kWireSegmentMode) {
    return "has mode " + OctalMode(mode) + ", not " + OctalMode(kWireSegmentMode) +
           " (owner-only)";
  }
  return {};
}

[[noreturn]] void RefuseSegment(const std::string& segment_name, const std::string& problem) {
  const std::string path = "/dev/shm" + segment_name;
  throw std::runtime_error(
      "shared memory " + path + " " + problem + ": the wire only uses a segment no other user " +
      "can write into. If it is a stale segment of yours or of another user, remove it (rm " +
      path + ") and retry; otherwise use another wire name");
}

/// The segment's open file, and whether this process created it.
struct SegmentFile {
  int fd = -1;
  bool created = false;
};

/// Creates the segment owner-only, or opens the existing one and checks it is owner-only.
SegmentFile OpenOwnerOnly(const std::string& segment_name, const std::string& label) {
  for (int attempt = 0; attempt < 100; ++attempt) {
    int fd = ::shm_open(segment_name.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC,
                        kWireSegmentMode);
    if (fd >= 0) {
      ::fchmod(fd, kWireSegmentMode);  // the umask may have taken bits off
      return {fd, true};
    }
    if (errno == EEXIST) fd = ::shm_open(segment_name.c_str(), O_RDWR | O_CLOEXEC, 0);
    if (fd < 0 && errno == ENOENT) continue;  // removed between the two calls: create it
    if (fd < 0 && errno == EACCES) {
      struct stat info {};
      if (::stat(("/dev/shm" + segment_name).c_str(), &info) == 0) {
        RefuseSegment(segment_name, OwnerOnlyProblem(info) + " and cannot be opened");
      }
    }
    if (fd < 0) {
      throw std::runtime_error("cannot open shared memory /dev/shm" + segment_name + " for " +
                               label + ": " + std::strerror(errno) +
                               "; check /dev/shm is mounted and writable");
    }
    struct stat info {};
    std::string problem = ::fstat(fd, &info) != 0 ? std::strerror(errno) : OwnerOnlyProblem(info);
    // Its creator may be between shm_open and fchmod (an unusual umask): give it a moment.
    for (int i = 0; i < 100 && !problem.empty() && info.st_size == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      problem = ::fstat(fd, &info) != 0 ? std::strerror(errno) : OwnerOnlyProblem(info);
    }
    if (problem.empty()) return {fd, false};
    ::close(fd);
    RefuseSegment(segment_name, problem);
  }
  throw std::runtime_error("cannot create shared memory /dev/shm" + segment_name +
                           ": it keeps being removed and re-created; retry");
}

/// Closes `file` and throws `message`; a segment this process created is removed first (no
/// other process uses it yet: it is not laid out), so a failed start leaves nothing behind.
[[noreturn]] void AbandonSegment(const SegmentFile& file, const std::string& segment_name,
                                 const std::string& message) {
  ::close(file.fd);
  if (file.created) ::shm_unlink(segment_name.c_str());
  throw std::runtime_error(message);
}

/// Sizes the segment's file and reserves its pages: a tmpfs file that is only sized is sparse,
/// and a full or too small /dev/shm then kills the first process that writes into a page it
/// cannot supply with SIGBUS. A segment of the right size is reserved too (idempotent: pages
/// already there are kept, a hole left by an older version is filled).
void SizeAndReserve(const SegmentFile& file, const std::string& segment_name) {
  const std::string path = "/dev/shm" + segment_name;
  struct stat info {};
  const auto size = static_cast<off_t>(sizeof(WireSegment));
  if (::fstat(file.fd, &info) != 0) {
    AbandonSegment(file, segment_name,
                   "cannot read the size of shared memory " + path + ": " + std::strerror(errno));
  }
  if (info.st_size != 0 && info.st_size != size) {
    AbandonSegment(file, segment_name,
                   "shared memory " + path + " has the wrong size (" +
                       std::to_string(info.st_size) + " bytes, not " + std::to_string(size) +
                       "); it may be from another hiltwin version: remove " + path +
                       " and retry");
  }
  if (const int error = kernel_glue::ReserveFileBytes(file.fd, sizeof(WireSegment));
      error != 0) {
    AbandonSegment(file, segment_name,
                   "cannot reserve " + std::to_string(size) + " bytes for shared memory " + path +
                       ": " + std::strerror(error) + "; /dev/shm is full or too small (df " +
                       "/dev/shm): remove what is stale there (ls /dev/shm) or enlarge it " +
                       "(mount -o remount,size=64M /dev/shm), then retry");
  }
}

/// Opens (creating if needed) owner-only, sizes, reserves and maps the named segment. `fd`
/// receives the open file, which the caller keeps: it holds the side's presence lock.
WireSegment* MapSegment(const std::string& segment_name, const std::string& label, int& fd) {
  const SegmentFile file = OpenOwnerOnly(segment_name, label);
  SizeAndReserve(file, segment_name);
  void* map =
      ::mmap(nullptr, sizeof(WireSegment), PROT_READ | PROT_WRITE, MAP_SHARED, file.fd, 0);
  if (map == MAP_FAILED) {
    AbandonSegment(file, segment_name,
                   "cannot map /dev/shm" + segment_name + ": " + std::strerror(errno));
  }
  fd = file.fd;
  return static_cast<WireSegment*>(map);
}

bool HeaderValid(const WireSegment& segment) noexcept {
  return segment.init_state.load(std::memory_order_acquire) == kReady &&
         segment.magic.load(std::memory_order_relaxed) == kMagic &&
         segment.version.load(std::memory_order_relaxed) == kLayoutVersion &&
         segment.size.load(std::memory_order_relaxed) == sizeof(WireSegment);
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
  return HeaderValid(segment);
}

}  // namespace

namespace {

std::uint32_t ClockCode(WireClock clock) noexcept {
  return clock == WireClock::kLockstep ? kClockLockstep : kClockRealtime;
}

/// The refusal of a peer on the other clock, seen from the twin or the ECS running `own`.
const char* MismatchMessage(bool ecs_side, WireClock own) noexcept {
  static constexpr const char* kText[2][2] = {
      {"wire: the ECS on this wire runs --clock virtual and this twin --clock realtime; start "
       "both sides with the same --clock",
       "wire: the ECS on this wire runs --clock realtime and this twin --clock virtual "
       "(lockstep); start both sides with the same --clock"},
      {"wire: the twin on this wire runs --clock virtual and this ECS --clock realtime; start "
       "both sides with the same --clock",
       "wire: the twin on this wire runs --clock realtime and this ECS --clock virtual "
       "(lockstep); start both sides with the same --clock"}};
  return kText[ecs_side ? 1 : 0][own == WireClock::kLockstep ? 1 : 0];
}

}  // namespace

WireBus::WireBus(const std::string& name, Image side, std::optional<Image> board_image,
                 WireClock clock)
    : label_("wire:" + name),
      segment_name_(SegmentName(name)),
      side_(side),
      clock_kind_(clock),
      lockstep_(clock == WireClock::kLockstep ? std::make_unique<LockstepClock>(*this) : nullptr),
      board_clock_(lockstep_ ? static_cast<const kernel_glue::Clock*>(lockstep_.get()) : &wall_),
      board_(board_image.value_or(side), board_clock_),
      pid_(static_cast<std::int32_t>(::getpid())),
      guard_(std::make_unique<WireGuard>(SegmentPath(name))) {
  segment_ = MapSegment(segment_name_, label_, fd_);
  if (!LayOutOrCheck(*segment_)) {
    Release();
    throw std::runtime_error("shared memory /dev/shm" + segment_name_ + " is not a hiltwin wire " +
                             "of this version; remove /dev/shm" + segment_name_ + " and retry");
  }
  if (ClockMismatch().result != BusResult::kOk) {
    const std::string why = ClockMismatch().reason;
    Release();
    throw std::invalid_argument(why.substr(6));  // without "wire: ": the caller names the wire
  }
  Attach();
  pwm_wire_ = std::make_unique<PwmWire>(*segment_, *guard_);
  encoder_wire_ = std::make_unique<EncoderWire>(*segment_, *guard_, *board_clock_);
  const WireSide& peer = side_ == Image::kIcoboard ? segment_->twin : segment_->ecs;
  guard_->peer_sessions = peer.sessions.load();
  guard_->peer_pid = peer.pid.load();
  guard_->newest_seen = segment_->encoder_newest.load();
  guard_->newest_seen_ns = board_clock_->NowNs();
  guard_->published = guard_->newest_seen;
  if (side_ == Image::kIcoboardInverse) {
    segment_->twin_sampling_ns.store(kNotSampling);  // a crashed twin may have left it set
    board_.SetPwmSource(pwm_wire_.get());
    board_.SetEncoderSink(encoder_wire_.get());
  } else {
    board_.SetEncoderSource(encoder_wire_.get());
  }
}

kernel_glue::Clock* WireBus::lockstep_clock() noexcept { return lockstep_.get(); }

LockstepCounts WireBus::lockstep_counts() const noexcept {
  return lockstep_ ? lockstep_->counts() : LockstepCounts{};
}

BusStatus WireBus::ClockMismatch() const noexcept {
  const WireSide& peer = side_ == Image::kIcoboard ? segment_->twin : segment_->ecs;
  const std::uint32_t peer_clock = peer.clock.load(std::memory_order_acquire);
  // The usual case, on every exchange: the clocks agree (no system call for it).
  if (peer_clock == kClockUnset || peer_clock == ClockCode(clock_kind_)) return {};
  // Only a peer that is there now counts: a stale entry of one that left or died says nothing.
  if (!PeerAlive()) return {};
  return {BusResult::kPeerMismatch, MismatchMessage(side_ == Image::kIcoboard, clock_kind_)};
}

void WireBus::Attach() {
  const bool ecs_side = side_ == Image::kIcoboard;
  WireSide& self = ecs_side ? segment_->ecs : segment_->twin;
  WireSide& peer = ecs_side ? segment_->twin : segment_->ecs;
  // The side is this process's while it holds the side's lock; a process that died (reaped or
  // not) holds none, so whatever its entry still says, the side is free.
  const int error = kernel_glue::TakePresence(fd_, ecs_side ? kEcsPresenceByte : kTwinPresenceByte);
  if (error != 0) {
    const std::int32_t holder = self.pid.load();
    Release();
    if (error != EAGAIN) {
      throw std::runtime_error("cannot lock /dev/shm" + segment_name_ + " for " + label_ + ": " +
                               std::strerror(error));
    }
    throw std::runtime_error(label_ + " already has a" + (ecs_side ? "n ECS" : " twin") +
                             " attached (pid " + std::to_string(holder) +
                             "); stop it first or use another wire name");
  }
  // A peer that died never detached: its flags would make this process report "stopped
  // updating its heartbeat" (or "detached") although no peer has been there since it started.
  // The lock alone: a new peer takes it before it writes its entry (its attached flag may
  // still be the dead one's, or not yet set).
  std::int32_t peer_pid = peer.pid.load();
  if (peer_pid > 0 && !PeerProcessLives() && peer.pid.compare_exchange_strong(peer_pid, 0)) {
    peer.attached.store(0);
    peer.sessions.store(0);
    peer.stop_cause.store(0);
    peer.clock.store(kClockUnset);
    peer.lockstep_ns.store(0);
    // A new peer takes its lock, then stores its pid before its flags: if one arrived while
    // these were cleared, give its presence back.
    if (peer.pid.load() != 0) {
      peer.attached.store(1);
      peer.sessions.fetch_add(1);
    }
  }
  self.pid.store(pid_);
  self.stop_cause.store(static_cast<std::uint32_t>(StopCause::kNone));
  self.step_ns.store(0);
  self.clock.store(ClockCode(clock_kind_));
  self.lockstep_ns.store(0);  // lockstep: its set-up happens at time 0, before its first wait
  self.last_beat_ns.store(kNoBeatYet);  // up at its first beat, once its set-up is done
  self.attached.store(1);
  self.sessions.fetch_add(1);
  segment_->attach_count.fetch_add(1);
}

void WireBus::Release() noexcept {
  ::munmap(segment_, sizeof(WireSegment));
  segment_ = nullptr;
  ::close(fd_);
  fd_ = -1;
}

bool WireBus::PeerProcessLives() const noexcept {
  return kernel_glue::PresenceHeld(
      fd_, side_ == Image::kIcoboard ? kTwinPresenceByte : kEcsPresenceByte);
}

bool WireBus::PeerAlive() const noexcept {
  const WireSide& peer = side_ == Image::kIcoboard ? segment_->twin : segment_->ecs;
  return peer.attached.load() == 1 && PeerProcessLives();
}

WireBus::~WireBus() {
  if (segment_ == nullptr) return;
  WireSide& self = side_ == Image::kIcoboard ? segment_->ecs : segment_->twin;
  if (lockstep_) lockstep_->Leave();  // a peer waiting for this side's turn goes on
  self.attached.store(0);
  segment_->attach_count.fetch_sub(1);
  // The last one out removes the segment. A peer that died never detached, but it holds no
  // presence lock (even while its parent has not reaped it); a running peer keeps its mapping
  // even if the name is removed under it. Both leaving at once: each clears its attached flag
  // (seq_cst) before it reads the other's, so at least one sees the other gone.
  if (!PeerAlive()) ::shm_unlink(segment_name_.c_str());
  Release();  // drops this side's presence lock
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
  if (present_) Beat(now_ns);
}

void WireBus::Beat(std::int64_t now_ns) noexcept {
  WireSide& self = side_ == Image::kIcoboard ? segment_->ecs : segment_->twin;
  self.step_ns.store(board_.step_ns(), std::memory_order_relaxed);
  self.last_beat_ns.store(now_ns, std::memory_order_relaxed);
  self.heartbeat.fetch_add(1, std::memory_order_release);
}

BusStatus WireBus::Poll() noexcept {
  const std::int64_t now_ns = wall_.NowNs();
  CheckSegment(now_ns);
  present_ = true;  // it waits for its peer: its set-up is done
  Beat(now_ns);
  return Status();
}

void WireBus::KeepAlive() noexcept {
  if (!lockstep_) return;
  WireSide& self = side_ == Image::kIcoboard ? segment_->ecs : segment_->twin;
  self.last_beat_ns.store(wall_.NowNs(), std::memory_order_relaxed);
  self.heartbeat.fetch_add(1, std::memory_order_release);
}

void WireBus::AnnounceStop(StopCause cause) noexcept {
  WireSide& self = side_ == Image::kIcoboard ? segment_->ecs : segment_->twin;
  guard_->own_stop_cause = static_cast<std::uint32_t>(cause);
  self.stop_cause.store(static_cast<std::uint32_t>(cause), std::memory_order_release);
  // After the cause: a peer released by this leave reads why at its next exchange.
  if (lockstep_) lockstep_->Leave();
}

bool WireBus::CheckSegment(std::int64_t now_ns) noexcept {
  WireGuard& guard = *guard_;
  if (!guard.ok()) return false;
  const WireSegment& seg = *segment_;
  const bool ecs_side = side_ == Image::kIcoboard;
  const WireSide& self = ecs_side ? seg.ecs : seg.twin;
  const WireSide& peer = ecs_side ? seg.twin : seg.ecs;
  const char* const peer_name = ecs_side ? "twin" : "ECS";
  if (!HeaderValid(seg)) {
    guard.Fail("wire: the segment's header (state %u, magic 0x%llx, version %u, size %u) changed "
               "under this running side",
               seg.init_state.load(), static_cast<unsigned long long>(seg.magic.load()),
               seg.version.load(), seg.size.load());
    return false;
  }
  const std::int32_t own_pid = self.pid.load(std::memory_order_relaxed);
  const std::uint32_t own_cause = self.stop_cause.load(std::memory_order_relaxed);
  const std::uint32_t own_clock = self.clock.load(std::memory_order_relaxed);
  // Only this side writes its lockstep time (in real time it stays 0 from the attach).
  const std::int64_t own_lockstep_ns = self.lockstep_ns.load(std::memory_order_relaxed);
  if (own_pid != pid_ || self.attached.load(std::memory_order_relaxed) != 1 ||
      own_cause != guard.own_stop_cause || own_clock != ClockCode(clock_kind_) ||
      own_lockstep_ns != guard.own_lockstep_ns) {
    guard.Fail("wire: this side's own entry was overwritten (pid %d, expected %d; stop cause %u, "
               "expected %u; clock %u, expected %u; lockstep time %lld, expected %lld)",
               own_pid, pid_, own_cause, guard.own_stop_cause, own_clock,
               ClockCode(clock_kind_), static_cast<long long>(own_lockstep_ns),
               static_cast<long long>(guard.own_lockstep_ns));
    return false;
  }
  const std::uint32_t cause = peer.stop_cause.load(std::memory_order_relaxed);
  const std::uint32_t attached = peer.attached.load(std::memory_order_relaxed);
  const std::int64_t step_ns = peer.step_ns.load(std::memory_order_relaxed);
  const std::int64_t beat_ns = peer.last_beat_ns.load(std::memory_order_relaxed);
  if (beat_ns > now_ns + kFutureSlackNs) now_ns = wall_.NowNs();  // preempted since now_ns?
  const std::uint32_t peer_clock = peer.clock.load(std::memory_order_relaxed);
  const std::int64_t peer_lockstep_ns = peer.lockstep_ns.load(std::memory_order_relaxed);
  if (cause > kLastStopCause || attached > 1 || step_ns < 0 || step_ns > kMaxStepNs ||
      beat_ns < 0 || beat_ns > now_ns + kFutureSlackNs || peer_clock > kClockLockstep ||
      peer_lockstep_ns < kLockstepRunning) {
    guard.Fail("wire: the %s's entry holds impossible values (stop cause %u, attached %u, step "
               "%lld ns, heartbeat at %lld ns with this clock at %lld ns, clock %u, lockstep "
               "time %lld ns)",
               peer_name, cause, attached, static_cast<long long>(step_ns),
               static_cast<long long>(beat_ns), static_cast<long long>(now_ns), peer_clock,
               static_cast<long long>(peer_lockstep_ns));
    return false;
  }
  return CheckPeerIdentity(now_ns);
}

bool WireBus::CheckPeerIdentity(std::int64_t now_ns) noexcept {
  WireGuard& guard = *guard_;
  const bool ecs_side = side_ == Image::kIcoboard;
  const WireSide& peer = ecs_side ? segment_->twin : segment_->ecs;
  const char* const peer_name = ecs_side ? "twin" : "ECS";
  const std::uint32_t sessions = peer.sessions.load(std::memory_order_acquire);
  const std::int32_t pid = peer.pid.load(std::memory_order_relaxed);
  if (sessions < guard.peer_sessions) {
    guard.Fail("wire: the %s's session count went back from %u to %u", peer_name,
               guard.peer_sessions, sessions);
    return false;
  }
  if (sessions > guard.peer_sessions) {  // a new peer process (it stored its pid first)
    guard.peer_sessions = sessions;
    guard.peer_pid = pid;
    guard.pid_changed_ns = -1;
  }
  if (sessions > 0 && pid <= 0) {
    guard.Fail("wire: the %s's pid is %d while it has a session", peer_name, pid);
    return false;
  }
  if (pid == guard.peer_pid) {
    guard.pid_changed_ns = -1;
    return true;
  }
  // A new process stores its pid a few stores before it counts its session: wait for that.
  if (guard.pid_changed_ns < 0) guard.pid_changed_ns = now_ns;
  if (now_ns - guard.pid_changed_ns > kIdentitySettleNs) {
    guard.Fail("wire: the %s's pid changed from %d to %d without a new session (a forged pid)",
               peer_name, guard.peer_pid, pid);
    return false;
  }
  return true;
}

BusStatus WireBus::Status() const noexcept {
  if (!guard_->ok()) return {BusResult::kWireCorrupted, guard_->reason()};
  if (lockstep_ && lockstep_->broken() != nullptr) {
    return {BusResult::kPeerLost, lockstep_->broken()};
  }
  if (const BusStatus mismatch = ClockMismatch(); mismatch.result != BusResult::kOk) {
    return mismatch;
  }
  return PeerStatus();
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
  const std::int64_t beat_ns = peer.last_beat_ns.load(std::memory_order_acquire);
  if (beat_ns == kNoBeatYet) {
    return {BusResult::kPeerAbsent,
            ecs_side ? "wire: a twin process has attached but not started (no heartbeat yet)"
                     : "wire: an ECS process has attached but not started (no heartbeat yet)"};
  }
  std::int64_t step_ns = peer.step_ns.load(std::memory_order_relaxed);
  if (step_ns < 0 || step_ns > kMaxStepNs) step_ns = 0;  // garbage: CheckSegment reports it
  std::int64_t timeout_ns = 20 * step_ns;
  if (timeout_ns < kWireMinHeartbeatTimeoutNs) timeout_ns = kWireMinHeartbeatTimeoutNs;
  if (lockstep_ && timeout_ns < kWireLockstepHeartbeatTimeoutNs) {
    timeout_ns = kWireLockstepHeartbeatTimeoutNs;
  }
  // A negative heartbeat is garbage (CheckSegment reports it) whose age would overflow: lost.
  if (beat_ns < 0 || wall_.NowNs() - beat_ns > timeout_ns) {
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
  const bool twin = side_ == Image::kIcoboardInverse;
  // Nothing read from a segment that failed a check is used: no pins, idle PWM, held lines.
  std::array<bool, kChannels> pins{};
  const bool clean = CheckSegment(wall_.NowNs());
  if (clean && twin) {
    const std::uint64_t words = seg.pwm_words.load(std::memory_order_acquire);
    if (CheckPwmWords(words, guard_.get())) {
      for (std::size_t c = 0; c < kChannels; ++c) pins[c] = UnpackPwm(Unpack16(words, c)).pin;
    }
  } else if (clean) {
    const std::uint32_t bits = seg.twin_pins.load(std::memory_order_acquire);
    if ((bits >> kChannels) != 0) {
      guard_->Fail("wire: the twin's pin bits are 0x%x (only the low %zu are used)", bits,
                   kChannels);
    } else {
      for (std::size_t c = 0; c < kChannels; ++c) pins[c] = ((bits >> c) & 1U) != 0;
    }
  }
  board_.SetDigitalInputs(pins);
  // INIT runs while the command handles its options, before the session's real-time set-up: a
  // beat there would make the waiting peer start against a side that then stays silent for the
  // whole set-up. A transfer to a board that INIT has configured is the loop's: set-up done.
  if (board_.initialised()) present_ = true;
  // The board samples (and publishes its period) while acting on the request; the fetch's NOOP
  // changes nothing on the wire, so one window around both keeps the ECS's replay bound valid.
  if (twin) {
    seg.twin_sampling_ns.store(board_clock_->NowNs(), std::memory_order_seq_cst);
    // The board's clock reads in transfers() come after the store is visible (arm64 may
    // otherwise read the clock while the store still waits in its buffer).
    FenceAgainstClockReads();
  }
  transfers();
  if (twin) seg.twin_sampling_ns.store(kNotSampling, std::memory_order_seq_cst);
  Publish(wall_.NowNs());
  return Status();
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
  return encoder_wire_->Peek(index, board_clock_->NowNs(), out);
}

}  // namespace hiltwin::io
