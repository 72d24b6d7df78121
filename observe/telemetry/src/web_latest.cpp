#include "web_latest.h"

#include <utility>

namespace hiltwin::telemetry::web {

void LatestRecord::Store(std::shared_ptr<const std::string> json) {
  {
    const std::lock_guard lock(mutex_);
    json_ = std::move(json);
    ++seq_;
  }
  changed_.notify_all();
}

LatestRecord::Next LatestRecord::WaitNewer(std::uint64_t seen, std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  const auto newer = [&] { return seq_ > seen && json_ != nullptr; };
  changed_.wait_for(lock, timeout, [&] { return stopped_ || newer(); });
  // A record not yet sent goes out even after Stop: it is often the run's final one.
  if (newer()) return {json_, seq_, false};
  return {nullptr, seen, stopped_};
}

LatestRecord::Next LatestRecord::Latest() const {
  const std::lock_guard lock(mutex_);
  return {json_, seq_, stopped_};
}

void LatestRecord::Stop() {
  {
    const std::lock_guard lock(mutex_);
    stopped_ = true;
  }
  changed_.notify_all();
}

}  // namespace hiltwin::telemetry::web
