#pragma once
// httplib's task queue on hiltwin's threads. httplib's own ThreadPool starts std::threads
// that inherit their creator's policy and CPU set; these workers are kernel_glue::NamedThreads
// (SCHED_OTHER, named, docs/architecture.md "Real-time rules"), and their number is
// fixed, so a crowd of browsers queues instead of spawning threads. The queue is bounded too:
// httplib calls enqueue from its accept loop right after each accept, so an enqueue that waits
// for room stops the accepting, and a flood of connections waits in the kernel's listen
// queue, holding no descriptor of ours (a process out of descriptors could not write its
// report).

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
  /// Starts `count` threads named `name` (≤ 15 characters); at most `capacity` (≥ count)
  /// connections are held at once, queued or being served.
  Workers(std::size_t count, std::size_t capacity, const std::string& name);
  ~Workers() override;
  Workers(const Workers&) = delete;
  Workers& operator=(const Workers&) = delete;

  /// One accepted connection to serve; waits while `capacity` are held already.
  void enqueue(std::function<void()> fn) override;
  /// Serves what is queued, then joins every worker (httplib calls it once the listening
  /// socket is closed, so queued connections end at once).
  void shutdown() override;

 private:
  void Work();

  std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable queued_;
  std::condition_variable room_;
  std::deque<std::function<void()>> jobs_;
  std::size_t held_ = 0;  // queued or being served
  bool shutting_down_ = false;
  std::vector<kernel_glue::NamedThread> threads_;
};

}  // namespace hiltwin::telemetry::web
