#pragma once
// A scriptable OsCalls: every call is recorded, and any call can be made to fail with a
// chosen errno, so RT set-up and the probe can be tested without (and despite) privileges.

#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "hiltwin/kernel_glue/os_calls.h"

namespace hiltwin::kernel_glue::test {

enum class Call {
  kSetScheduler,
  kGetScheduler,
  kSetAffinity,
  kLockAll,
  kUnlockAll,
  kMallopt,
  kOpenDmaLatency,
  kSetMemlockLimit,
};

struct RecordedCall {
  Call call;
  int a = 0;  // policy / flags / mallopt param / latency
  int b = 0;  // priority / mallopt value
  std::vector<int> cpus;
  std::thread::id thread;
};

class FakeOsCalls final : public OsCalls {
 public:
  /// Makes every later `call` return `error` (0 grants it again).
  void Refuse(Call call, int error) { errors_[call] = error; }
  void SetStackBytes(std::size_t bytes) { stack_bytes_ = bytes; }
  /// RLIMIT_MEMLOCK and CAP_IPC_LOCK as the process would see them.
  void SetMemlock(std::uint64_t soft_bytes, std::uint64_t hard_bytes, bool ipc_lock) {
    memlock_soft_ = soft_bytes;
    memlock_hard_ = hard_bytes;
    ipc_lock_ = ipc_lock;
  }

  int SetThreadScheduler(int policy, int priority) const override {
    return Record({Call::kSetScheduler, policy, priority, {}, std::this_thread::get_id()});
  }
  int GetThreadScheduler(int& policy, int& priority) const override {
    policy = 0;
    priority = 0;
    return Record({Call::kGetScheduler, 0, 0, {}, std::this_thread::get_id()});
  }
  int SetThreadAffinity(std::span<const int> cpus) const override {
    return Record(
        {Call::kSetAffinity, 0, 0, {cpus.begin(), cpus.end()}, std::this_thread::get_id()});
  }
  int LockAllMemory(int flags) const override {
    return Record({Call::kLockAll, flags, 0, {}, std::this_thread::get_id()});
  }
  int UnlockAllMemory() const override {
    return Record({Call::kUnlockAll, 0, 0, {}, std::this_thread::get_id()});
  }
  int SetMallocOption(int param, int value) const override {
    return Record({Call::kMallopt, param, value, {}, std::this_thread::get_id()});
  }
  int OpenCpuDmaLatency(std::int32_t latency_us, int& fd) const override {
    const int error =
        Record({Call::kOpenDmaLatency, latency_us, 0, {}, std::this_thread::get_id()});
    if (error == 0) fd = kFakeFd;
    return error;
  }
  void CloseFd(int fd) const override {
    std::lock_guard lock(mutex_);
    closed_fds_.push_back(fd);
  }
  int GetMemlockLimit(std::uint64_t& soft_bytes, std::uint64_t& hard_bytes) const override {
    std::lock_guard lock(mutex_);
    soft_bytes = memlock_soft_;
    hard_bytes = memlock_hard_;
    return 0;
  }
  int SetMemlockSoftLimit(std::uint64_t soft_bytes) const override {
    const int error = Record({Call::kSetMemlockLimit, 0, 0, {}, std::this_thread::get_id()});
    std::lock_guard lock(mutex_);
    if (error == 0) memlock_soft_ = soft_bytes;
    return error;
  }
  bool HasIpcLockCapability() const override { return ipc_lock_; }
  std::size_t ThreadStackBytes() const override { return stack_bytes_; }

  std::vector<RecordedCall> calls() const {
    std::lock_guard lock(mutex_);
    return calls_;
  }
  std::vector<RecordedCall> calls(Call kind) const {
    std::vector<RecordedCall> selected;
    for (const auto& call : calls()) {
      if (call.call == kind) selected.push_back(call);
    }
    return selected;
  }
  std::vector<int> closed_fds() const {
    std::lock_guard lock(mutex_);
    return closed_fds_;
  }

  static constexpr int kFakeFd = 4242;

 private:
  int Record(RecordedCall call) const {
    std::lock_guard lock(mutex_);
    const auto found = errors_.find(call.call);
    calls_.push_back(std::move(call));
    return found == errors_.end() ? 0 : found->second;
  }

  std::map<Call, int> errors_;
  std::size_t stack_bytes_ = 8u << 20;
  mutable std::uint64_t memlock_soft_ = kUnlimited;
  std::uint64_t memlock_hard_ = kUnlimited;
  bool ipc_lock_ = true;
  mutable std::mutex mutex_;
  mutable std::vector<RecordedCall> calls_;
  mutable std::vector<int> closed_fds_;
};

}  // namespace hiltwin::kernel_glue::test
