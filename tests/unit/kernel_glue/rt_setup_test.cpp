#include "hiltwin/kernel_glue/rt_setup.h"

#include <gtest/gtest.h>
#include <malloc.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <stdexcept>
#include <string>

#include "fake_os_calls.h"

namespace hiltwin::kernel_glue {
namespace {

using test::Call;
using test::FakeOsCalls;

RtSetupRequest FullRequest() {
  RtSetupRequest request;
  request.fifo_priority = 80;
  request.cpus = {1, 3};
  request.lock_memory = true;
  request.prefault_stack_bytes = 64 * 1024;
  request.prefault_heap_bytes = 1u << 20;
  request.hold_cpu_dma_latency = true;
  return request;
}

bool AnyWarningContains(const RtSetupRecord& record, const std::string& a, const std::string& b) {
  for (const auto& warning : record.warnings) {
    if (warning.find(a) != std::string::npos && warning.find(b) != std::string::npos) return true;
  }
  return false;
}

TEST(RtSession, AllGrantedRecordsEveryStepAndPassesTheRightArguments) {
  FakeOsCalls os;
  const RtSession session = RtSession::Apply(FullRequest(), os);
  const RtSetupRecord& record = session.record();
  EXPECT_TRUE(record.sched_fifo);
  EXPECT_EQ(record.fifo_priority, 80);
  EXPECT_TRUE(record.affinity);
  EXPECT_EQ(record.cpus, (std::vector<int>{1, 3}));
  EXPECT_TRUE(record.memory_locked);
  EXPECT_TRUE(record.heap_prefaulted);
  EXPECT_EQ(record.heap_prefault_bytes, 1u << 20);
  EXPECT_TRUE(record.stack_prefaulted);
  EXPECT_EQ(record.stack_prefault_bytes, 64u * 1024);
  EXPECT_TRUE(record.cpu_dma_latency_held);
  EXPECT_TRUE(record.warnings.empty());

  const auto sched = os.calls(Call::kSetScheduler);
  ASSERT_EQ(sched.size(), 1u);
  EXPECT_EQ(sched[0].a, SCHED_FIFO);
  EXPECT_EQ(sched[0].b, 80);
  const auto lock = os.calls(Call::kLockAll);
  ASSERT_EQ(lock.size(), 1u);
  EXPECT_EQ(lock[0].a, MCL_CURRENT | MCL_FUTURE);
  const auto mallopts = os.calls(Call::kMallopt);
  ASSERT_EQ(mallopts.size(), 2u);
  EXPECT_EQ(mallopts[0].a, M_TRIM_THRESHOLD);
  EXPECT_EQ(mallopts[0].b, -1);
  EXPECT_EQ(mallopts[1].a, M_MMAP_MAX);
  EXPECT_EQ(mallopts[1].b, 0);
  const auto affinity = os.calls(Call::kSetAffinity);
  ASSERT_EQ(affinity.size(), 1u);
  EXPECT_EQ(affinity[0].cpus, (std::vector<int>{1, 3}));
  const auto dma = os.calls(Call::kOpenDmaLatency);
  ASSERT_EQ(dma.size(), 1u);
  EXPECT_EQ(dma[0].a, 0);  // 0 us: no deep idle states while the session lives
}

TEST(RtSession, MemoryIsPreparedBeforeSchedFifoIsTaken) {
  FakeOsCalls os;
  const RtSession session = RtSession::Apply(FullRequest(), os);
  const auto calls = os.calls();
  ASSERT_FALSE(calls.empty());
  // Heap work at RT priority would hog a CPU: mallopt first, SCHED_FIFO last.
  EXPECT_EQ(calls.front().call, Call::kMallopt);
  EXPECT_EQ(calls.back().call, Call::kSetScheduler);
}

struct RefusalCase {
  Call call;
  int error;
  const char* errno_name;
  const char* step_word;  // appears in the warning
  const char* label;      // test name suffix
};

class RtSessionRefusal : public ::testing::TestWithParam<RefusalCase> {};

TEST_P(RtSessionRefusal, RefusedStepIsRecordedAndWarnedAndTheRestStillHappens) {
  const RefusalCase refusal = GetParam();
  FakeOsCalls os;
  os.Refuse(refusal.call, refusal.error);
  RtSetupRecord record;
  ASSERT_NO_THROW(record = RtSession::Apply(FullRequest(), os).record());

  const bool fifo_refused = refusal.call == Call::kSetScheduler;
  const bool affinity_refused = refusal.call == Call::kSetAffinity;
  const bool lock_refused = refusal.call == Call::kLockAll;
  const bool mallopt_refused = refusal.call == Call::kMallopt;
  const bool dma_refused = refusal.call == Call::kOpenDmaLatency;

  EXPECT_EQ(record.sched_fifo, !fifo_refused);
  EXPECT_EQ(record.fifo_priority, fifo_refused ? 0 : 80);
  EXPECT_EQ(record.affinity, !affinity_refused);
  EXPECT_EQ(record.cpus.empty(), affinity_refused);
  EXPECT_EQ(record.memory_locked, !lock_refused);
  // Without mallopt the pre-faulted heap would go back to the kernel on free(): skipped.
  EXPECT_EQ(record.heap_prefaulted, !mallopt_refused);
  EXPECT_TRUE(record.stack_prefaulted);
  EXPECT_EQ(record.cpu_dma_latency_held, !dma_refused);

  ASSERT_EQ(record.warnings.size(), 1u);
  EXPECT_TRUE(AnyWarningContains(record, refusal.errno_name, refusal.step_word))
      << record.warnings[0];
  EXPECT_NE(record.warnings[0].find("continuing"), std::string::npos) << record.warnings[0];
}

INSTANTIATE_TEST_SUITE_P(
    EachCall, RtSessionRefusal,
    ::testing::Values(
        RefusalCase{Call::kSetScheduler, EPERM, "EPERM", "SCHED_FIFO", "SchedFifoEperm"},
        RefusalCase{Call::kSetAffinity, EINVAL, "EINVAL", "affinity", "AffinityEinval"},
        RefusalCase{Call::kLockAll, EPERM, "EPERM", "mlockall", "MlockallEperm"},
        RefusalCase{Call::kLockAll, ENOMEM, "ENOMEM", "CAP_IPC_LOCK", "MlockallEnomem"},
        RefusalCase{Call::kMallopt, EINVAL, "EINVAL", "mallopt", "MalloptEinval"},
        RefusalCase{Call::kOpenDmaLatency, EACCES, "EACCES", "cpu_dma_latency", "DmaLatencyEacces"},
        RefusalCase{Call::kOpenDmaLatency, ENOENT, "ENOENT", "PM QoS", "DmaLatencyEnoent"}),
    [](const ::testing::TestParamInfo<RefusalCase>& param_info) {
      return std::string(param_info.param.label);
    });

TEST(RtSession, SchedFifoRefusalAdvisesHowToGrantIt) {
  FakeOsCalls os;
  os.Refuse(Call::kSetScheduler, EPERM);
  const RtSession session = RtSession::Apply(FullRequest(), os);
  ASSERT_EQ(session.record().warnings.size(), 1u);
  const std::string& warning = session.record().warnings[0];
  EXPECT_NE(warning.find("CAP_SYS_NICE"), std::string::npos) << warning;
  EXPECT_NE(warning.find("limits.conf"), std::string::npos) << warning;
  EXPECT_NE(warning.find("SCHED_OTHER"), std::string::npos) << warning;
}

TEST(RtSession, EverythingRefusedStillReturnsARecord) {
  FakeOsCalls os;
  for (const Call call : {Call::kSetScheduler, Call::kSetAffinity, Call::kLockAll, Call::kMallopt,
                          Call::kOpenDmaLatency}) {
    os.Refuse(call, EPERM);
  }
  const RtSession session = RtSession::Apply(FullRequest(), os);
  const RtSetupRecord& record = session.record();
  EXPECT_FALSE(record.sched_fifo);
  EXPECT_FALSE(record.affinity);
  EXPECT_FALSE(record.memory_locked);
  EXPECT_FALSE(record.heap_prefaulted);
  EXPECT_FALSE(record.cpu_dma_latency_held);
  EXPECT_TRUE(record.stack_prefaulted);   // needs no permission
  EXPECT_EQ(record.warnings.size(), 5u);  // sched, affinity, mallopt, mlockall, dma
}

TEST(RtSession, NothingRequestedMakesNoCalls) {
  FakeOsCalls os;
  RtSetupRequest request;
  request.fifo_priority = 0;
  request.cpus.clear();
  request.lock_memory = false;
  request.prefault_stack_bytes = 0;
  request.hold_cpu_dma_latency = false;
  const RtSession session = RtSession::Apply(request, os);
  EXPECT_TRUE(os.calls().empty());
  EXPECT_FALSE(session.record().sched_fifo);
  EXPECT_FALSE(session.record().stack_prefaulted);
  EXPECT_TRUE(session.record().warnings.empty());
}

TEST(RtSession, SmallMemlockLimitWithoutCapabilityIsNotLocked) {
  FakeOsCalls os;
  os.SetMemlock(8u << 20, 8u << 20, /*ipc_lock=*/false);
  const RtSession session = RtSession::Apply(FullRequest(), os);
  // mlockall(MCL_FUTURE) under an 8 MiB limit would make later allocations fail: not called.
  EXPECT_TRUE(os.calls(Call::kLockAll).empty());
  EXPECT_FALSE(session.record().memory_locked);
  EXPECT_TRUE(session.record().heap_prefaulted);
  ASSERT_EQ(session.record().warnings.size(), 1u);
  EXPECT_NE(session.record().warnings[0].find("RLIMIT_MEMLOCK is 8192 KiB"), std::string::npos)
      << session.record().warnings[0];
}

TEST(RtSession, SoftMemlockLimitIsRaisedToAnUnlimitedHardLimit) {
  FakeOsCalls os;
  os.SetMemlock(8u << 20, OsCalls::kUnlimited, /*ipc_lock=*/false);
  const RtSession session = RtSession::Apply(FullRequest(), os);
  EXPECT_EQ(os.calls(Call::kSetMemlockLimit).size(), 1u);
  EXPECT_EQ(os.calls(Call::kLockAll).size(), 1u);
  EXPECT_TRUE(session.record().memory_locked);
  EXPECT_TRUE(session.record().warnings.empty());
}

TEST(RtSession, CapabilityOrALargeLimitAllowsLocking) {
  FakeOsCalls with_capability;
  with_capability.SetMemlock(64u << 10, 64u << 10, /*ipc_lock=*/true);
  EXPECT_TRUE(RtSession::Apply(FullRequest(), with_capability).record().memory_locked);
  FakeOsCalls large_limit;
  large_limit.SetMemlock(std::uint64_t{2} << 30, std::uint64_t{2} << 30, /*ipc_lock=*/false);
  EXPECT_TRUE(RtSession::Apply(FullRequest(), large_limit).record().memory_locked);
}

TEST(RtSession, StackPrefaultIsCappedAtHalfTheThreadStack) {
  FakeOsCalls os;
  os.SetStackBytes(128 * 1024);
  RtSetupRequest request = FullRequest();
  request.prefault_stack_bytes = 256 * 1024;
  const RtSession session = RtSession::Apply(request, os);
  EXPECT_TRUE(session.record().stack_prefaulted);
  EXPECT_EQ(session.record().stack_prefault_bytes, 64u * 1024);
  ASSERT_EQ(session.record().warnings.size(), 1u);
  EXPECT_NE(session.record().warnings[0].find("stack pre-fault reduced"), std::string::npos);
}

TEST(RtSession, LatencyDescriptorIsClosedExactlyOnceAcrossMoves) {
  FakeOsCalls os;
  {
    RtSession first = RtSession::Apply(FullRequest(), os);
    RtSession second(std::move(first));
    RtSession third;
    third = std::move(second);
    EXPECT_TRUE(third.record().cpu_dma_latency_held);
    EXPECT_TRUE(os.closed_fds().empty());
  }
  EXPECT_EQ(os.closed_fds(), (std::vector<int>{FakeOsCalls::kFakeFd}));
}

TEST(RtSession, MoveAssignmentReleasesTheOldDescriptor) {
  FakeOsCalls os;
  RtSession held = RtSession::Apply(FullRequest(), os);
  held = RtSession{};
  EXPECT_EQ(os.closed_fds(), (std::vector<int>{FakeOsCalls::kFakeFd}));
  EXPECT_FALSE(held.record().cpu_dma_latency_held);
}

TEST(RtSession, BadRequestsThrowBeforeAnyCall) {
  FakeOsCalls os;
  RtSetupRequest request = FullRequest();
  request.fifo_priority = 100;
  EXPECT_THROW((void)RtSession::Apply(request, os), std::invalid_argument);
  request.fifo_priority = -1;
  EXPECT_THROW((void)RtSession::Apply(request, os), std::invalid_argument);
  request.fifo_priority = 10;
  request.cpus = {0, -2};
  EXPECT_THROW((void)RtSession::Apply(request, os), std::invalid_argument);
  EXPECT_TRUE(os.calls().empty());
}

TEST(RtSession, EachKindOfRefusalIsLoggedOnlyOnceButRecordedEveryTime) {
  FakeOsCalls os;
  os.Refuse(Call::kSetScheduler, EPERM);
  ResetRtSetupWarningsForTest();  // earlier tests in this process may have logged this kind
  const auto before = RtSetupWarningsLogged();
  const RtSession first = RtSession::Apply(FullRequest(), os);
  const auto after_first = RtSetupWarningsLogged();
  const RtSession second = RtSession::Apply(FullRequest(), os);
  const auto after_second = RtSetupWarningsLogged();
  EXPECT_EQ(after_first - before, 1u);
  EXPECT_EQ(after_second, after_first);
  EXPECT_EQ(first.record().warnings.size(), 1u);
  EXPECT_EQ(second.record().warnings.size(), 1u);
}

TEST(RtSession, JsonCarriesEveryField) {
  FakeOsCalls os;
  os.Refuse(Call::kLockAll, EPERM);
  const RtSession session = RtSession::Apply(FullRequest(), os);
  const nlohmann::json json = ToJson(session.record());
  EXPECT_EQ(json.at("sched_fifo"), true);
  EXPECT_EQ(json.at("fifo_priority"), 80);
  EXPECT_EQ(json.at("affinity"), true);
  EXPECT_EQ(json.at("cpus").get<std::vector<int>>(), (std::vector<int>{1, 3}));
  EXPECT_EQ(json.at("memory_locked"), false);
  EXPECT_EQ(json.at("heap_prefaulted"), true);
  EXPECT_EQ(json.at("heap_prefault_bytes"), 1u << 20);
  EXPECT_EQ(json.at("stack_prefaulted"), true);
  EXPECT_EQ(json.at("stack_prefault_bytes"), 64u * 1024);
  EXPECT_EQ(json.at("cpu_dma_latency_held"), true);
  ASSERT_EQ(json.at("warnings").size(), 1u);
  EXPECT_NE(json.at("warnings")[0].get<std::string>().find("mlockall"), std::string::npos);
}

TEST(RtSession, SummaryNamesWhatIsInEffect) {
  FakeOsCalls granted;
  EXPECT_EQ(Summary(RtSession::Apply(FullRequest(), granted).record()),
            "SCHED_FIFO 80, CPUs 1,3, memory locked, heap 1 MiB pre-faulted, stack 64 KiB "
            "pre-faulted, cpu_dma_latency 0 us held; 0 warnings");
  FakeOsCalls refused;
  refused.Refuse(Call::kSetScheduler, EPERM);
  const std::string summary = Summary(RtSession::Apply(FullRequest(), refused).record());
  EXPECT_EQ(summary.rfind("SCHED_OTHER", 0), 0u) << summary;
  EXPECT_NE(summary.find("1 warning"), std::string::npos) << summary;
}

// The real OS: whatever this machine allows, each requested step is either in effect or
// explained by a warning. Only harmless steps are requested (no SCHED_FIFO, no mlockall).
TEST(RtSession, RealCallsEitherSucceedOrWarn) {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  ASSERT_EQ(sched_getaffinity(0, sizeof(allowed), &allowed), 0);
  RtSetupRequest request;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(static_cast<std::size_t>(cpu), &allowed)) request.cpus.push_back(cpu);
  }
  request.lock_memory = false;
  request.prefault_stack_bytes = 64 * 1024;
  request.hold_cpu_dma_latency = true;
  const RtSession session = RtSession::Apply(request);
  const RtSetupRecord& record = session.record();
  EXPECT_TRUE(record.stack_prefaulted);
  EXPECT_TRUE(record.affinity || AnyWarningContains(record, "affinity", "continuing"));
  EXPECT_TRUE(record.cpu_dma_latency_held ||
              AnyWarningContains(record, "cpu_dma_latency", "continuing"));
}

}  // namespace
}  // namespace hiltwin::kernel_glue
