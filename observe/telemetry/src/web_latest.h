#pragma once
// The web sink's one shared value: the newest record's JSON and its sequence number. The
// telemetry thread stores; every event stream waits for a number newer than the one it sent.
// A stream that falls behind sees only the newest record (it skips, it never queues), so a
// slow browser costs the publisher one notify and nothing else.

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

namespace hiltwin::telemetry::web {

class LatestRecord {
 public:
  /// What a waiting stream gets: the newest JSON (null on a keep-alive timeout or before the
  /// first record) and its sequence number; `stopped` once Stop() was called.
  struct Next {
    std::shared_ptr<const std::string> json;
    std::uint64_t seq = 0;
    bool stopped = false;
  };

  /// Replaces the newest record and wakes every waiting stream (the lock is held for a pointer
  /// swap only).
  void Store(std::shared_ptr<const std::string> json);
  /// The newest record with a number above `seen`, waiting at most `timeout` for one; once
  /// stopped, that record if there is one, else `stopped` at once.
  [[nodiscard]] Next WaitNewer(std::uint64_t seen, std::chrono::milliseconds timeout);
  /// The newest record now (json null before the first).
  [[nodiscard]] Next Latest() const;
  /// Wakes every stream for good: each sends what it has not sent yet, then ends.
  void Stop();

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::shared_ptr<const std::string> json_;
  std::uint64_t seq_ = 0;
  bool stopped_ = false;
};

}  // namespace hiltwin::telemetry::web
