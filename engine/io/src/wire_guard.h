#pragma once
// The wire's latched verdict on the segment (wire_bus.cpp, wire_lockstep.cpp): private to io.
#include <array>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>

namespace hiltwin::io {

/// The first impossible value this side read from the segment, latched: once set, the side
/// reads nothing more from the wire and every transfer reports it. The message lives in this
/// object (the bus outlives the run that reports it), formatted without allocating.
class WireGuard {
 public:
  explicit WireGuard(std::string path) : path_(std::move(path)) {}
  [[nodiscard]] bool ok() const noexcept { return reason_ == nullptr; }
  [[nodiscard]] const char* reason() const noexcept { return reason_; }
  [[nodiscard]] const std::string& path() const noexcept { return path_; }

  /// Latches "wire: <what>: the segment is corrupted (...)" unless a reason is latched already.
  __attribute__((format(printf, 2, 3))) void Fail(const char* format, ...) noexcept {
    if (reason_ != nullptr) return;
    va_list args;
    va_start(args, format);
    const int used = std::vsnprintf(text_.data(), text_.size(), format, args);
    va_end(args);
    if (used >= 0 && static_cast<std::size_t>(used) < text_.size()) {
      std::snprintf(text_.data() + used, text_.size() - static_cast<std::size_t>(used),
                    ": the segment is corrupted (another process writes into %s); outputs go "
                    "safe: stop that process, then restart both sides",
                    path_.c_str());
    }
    reason_ = text_.data();
  }

  // The ECS's view of the ring's newest index: the last value read and when.
  std::uint64_t newest_seen = 0;
  std::int64_t newest_seen_ns = 0;
  // The twin's own count of the periods it published.
  std::uint64_t published = 0;
  // The peer's identity as last seen, and since when a changed pid awaits its new session.
  std::uint32_t peer_sessions = 0;
  std::int32_t peer_pid = 0;
  std::int64_t pid_changed_ns = -1;
  // What this side last stored in its own stop_cause and, in lockstep, its lockstep_ns.
  std::uint32_t own_stop_cause = 0;
  std::int64_t own_lockstep_ns = 0;

 private:
  std::string path_;
  const char* reason_ = nullptr;
  std::array<char, 512> text_{};
};

}  // namespace hiltwin::io
