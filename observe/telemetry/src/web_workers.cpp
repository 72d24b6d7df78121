#include "web_workers.h"

#include <utility>

namespace hiltwin::telemetry::web {

Workers::Workers(std::size_t count, std::size_t capacity, const std::string& name)
    : capacity_(capacity) {
  threads_.reserve(count);
  try {
    for (std::size_t i = 0; i < count; ++i) {
      threads_.emplace_back(kernel_glue::ThreadSpec{name, kernel_glue::AllowedCpus()},
                            [this] { Work(); });
    }
  } catch (...) {
    shutdown();  // the started ones wait on queued_: release them before unwinding
    throw;
  }
}

Workers::~Workers() { shutdown(); }

void Workers::enqueue(std::function<void()> fn) {
  {
    std::unique_lock lock(mutex_);
    room_.wait(lock, [this] { return shutting_down_ || held_ < capacity_; });
    jobs_.push_back(std::move(fn));
    ++held_;
  }
  queued_.notify_one();
}

void Workers::shutdown() {
  {
    const std::lock_guard lock(mutex_);
    shutting_down_ = true;
  }
  queued_.notify_all();
  room_.notify_all();
  for (kernel_glue::NamedThread& thread : threads_) thread.Join();
}

void Workers::Work() {
  for (;;) {
    std::function<void()> job;
    {
      std::unique_lock lock(mutex_);
      queued_.wait(lock, [this] { return shutting_down_ || !jobs_.empty(); });
      if (jobs_.empty()) return;  // shutting down with nothing left to serve
      job = std::move(jobs_.front());
      jobs_.pop_front();
    }
    job();
    {
      const std::lock_guard lock(mutex_);
      --held_;
    }
    room_.notify_one();
  }
}

}  // namespace hiltwin::telemetry::web
