#pragma once
// httplib's task queue on hiltwin's threads. httplib's own ThreadPool starts std::threads
// that inherit their creator's policy and CPU set; these workers are kernel_glue::NamedThreads
// (SCHED_OTHER, named, docs/architecture.md "Real-time rules"), and their number is
// fixed, so a crowd of browsers queues instead of spawning threads.

#include <httplib.h>

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "hiltwin/kernel_glue/thread.h"

namespace hiltwin::telemetry::web {

class Workers : public httplib::TaskQueue {
 public:
  /// Starts `count` threads named `name` (≤ 15 characters).
  Workers(std::size_t count, const std::string& name);
  ~Workers() override;
  Workers(const Workers&) = delete;
  Workers& operator=(const Workers&) = delete;

  /// One accepted connection to serve.
  void enqueue(std::function<void()> fn) override;
  /// Serves what is queued, then joins every worker (httplib calls it once the listening
  /// socket is closed, so queued connections end at once).
  void shutdown() override;

 private:
  void Work();

  std::mutex mutex_;
  std::condition_variable queued_;
  std::deque<std::function<void()>> jobs_;
  bool shutting_down_ = false;
  std::vector<kernel_glue::NamedThread> threads_;
};

}  // namespace hiltwin::telemetry::web
