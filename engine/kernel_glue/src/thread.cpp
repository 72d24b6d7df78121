#include "hiltwin/kernel_glue/thread.h"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <memory>
#include <stdexcept>
#include <system_error>
#include <utility>

namespace hiltwin::kernel_glue {
namespace {

constexpr std::size_t kMaxThreadNameChars = 15;

/// What a new thread runs: it names itself first, so its body (and anyone who looks at it
/// from then on) never sees the creator's name.
struct ThreadStart {
  std::string name;
  std::function<void()> body;
};

void* RunBody(void* argument) {
  const std::unique_ptr<ThreadStart> start(static_cast<ThreadStart*>(argument));
  pthread_setname_np(pthread_self(), start->name.c_str());
  start->body();
  return nullptr;
}

// Owns a pthread_attr_t for the duration of one creation.
class ThreadAttributes {
 public:
  ThreadAttributes() { pthread_attr_init(&attr_); }
  ~ThreadAttributes() { pthread_attr_destroy(&attr_); }
  ThreadAttributes(const ThreadAttributes&) = delete;
  ThreadAttributes& operator=(const ThreadAttributes&) = delete;
  pthread_attr_t* get() noexcept { return &attr_; }

 private:
  pthread_attr_t attr_{};
};

// Every configured CPU: the kernel intersects the mask with the process's cpuset, so this
// means "wherever this process may run", not the creator's (possibly pinned) set.
std::vector<int> EveryCpu() {
  const long configured = sysconf(_SC_NPROCESSORS_CONF);
  std::vector<int> cpus;
  for (int cpu = 0; cpu < std::min<long>(configured > 0 ? configured : 1, CPU_SETSIZE); ++cpu) {
    cpus.push_back(cpu);
  }
  return cpus;
}

void Check(int error, const char* what) {
  if (error != 0) throw std::system_error(error, std::generic_category(), what);
}

}  // namespace

NamedThread::NamedThread(const ThreadSpec& spec, std::function<void()> body) {
  if (spec.name.empty() || spec.name.size() > kMaxThreadNameChars) {
    throw std::invalid_argument("thread name '" + spec.name + "' must have 1 to 15 characters");
  }
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  for (const int cpu : spec.cpus.empty() ? EveryCpu() : spec.cpus) {
    if (cpu < 0 || cpu >= CPU_SETSIZE) {
      throw std::invalid_argument("thread '" + spec.name + "': CPU " + std::to_string(cpu) +
                                  " is not a CPU number");
    }
    CPU_SET(static_cast<std::size_t>(cpu), &cpus);
  }
  ThreadAttributes attr;
  sched_param param{};
  param.sched_priority = 0;
  Check(pthread_attr_setinheritsched(attr.get(), PTHREAD_EXPLICIT_SCHED),
        "pthread_attr_setinheritsched");
  Check(pthread_attr_setschedpolicy(attr.get(), SCHED_OTHER), "pthread_attr_setschedpolicy");
  Check(pthread_attr_setschedparam(attr.get(), &param), "pthread_attr_setschedparam");
  Check(pthread_attr_setaffinity_np(attr.get(), sizeof cpus, &cpus), "pthread_attr_setaffinity_np");
  auto owned = std::make_unique<ThreadStart>(ThreadStart{spec.name, std::move(body)});
  const int error = pthread_create(&handle_, attr.get(), &RunBody, owned.get());
  if (error != 0) {
    throw std::system_error(error, std::generic_category(),
                            "cannot start thread '" + spec.name + "' (pthread_create)");
  }
  static_cast<void>(owned.release());  // RunBody owns it now
  started_ = true;
}

NamedThread::NamedThread(NamedThread&& other) noexcept
    : handle_(other.handle_), started_(std::exchange(other.started_, false)) {}

NamedThread& NamedThread::operator=(NamedThread&& other) noexcept {
  if (this != &other) {
    Join();
    handle_ = other.handle_;
    started_ = std::exchange(other.started_, false);
  }
  return *this;
}

NamedThread::~NamedThread() { Join(); }

void NamedThread::Join() noexcept {
  if (!started_) return;
  pthread_join(handle_, nullptr);
  started_ = false;
}

std::vector<int> AllowedCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::vector<int> cpus;
  if (sched_getaffinity(0, sizeof set, &set) != 0) return cpus;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(static_cast<std::size_t>(cpu), &set)) cpus.push_back(cpu);
  }
  return cpus;
}

int SetCallingThreadCpus(std::span<const int> cpus) noexcept {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int cpu : cpus) {
    if (cpu < 0 || cpu >= CPU_SETSIZE) return EINVAL;
    CPU_SET(static_cast<std::size_t>(cpu), &set);
  }
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set);
}

std::vector<int> HelperCpus(std::span<const int> allowed, std::span<const int> loop_cpus) {
  std::vector<int> helpers;
  for (const int cpu : allowed) {
    if (std::find(loop_cpus.begin(), loop_cpus.end(), cpu) == loop_cpus.end())
      helpers.push_back(cpu);
  }
  if (helpers.empty()) helpers.assign(allowed.begin(), allowed.end());
  return helpers;
}

ScopedThreadCpus::ScopedThreadCpus(std::span<const int> cpus) {
  if (cpus.empty()) return;
  previous_ = AllowedCpus();
  static_cast<void>(SetCallingThreadCpus(cpus));
}

ScopedThreadCpus::~ScopedThreadCpus() {
  if (!previous_.empty()) static_cast<void>(SetCallingThreadCpus(previous_));
}

}  // namespace hiltwin::kernel_glue
