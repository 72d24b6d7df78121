#include "hiltwin/kernel_glue/rt_probe.h"

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "fake_os_calls.h"

namespace hiltwin::kernel_glue {
namespace {

using test::Call;
using test::FakeOsCalls;
namespace fs = std::filesystem;

const char* const kAllIds[] = {
    "preemption",   "sched_fifo",      "mlockall",    "rlimit_rtprio",  "rlimit_memlock",
    "capabilities", "cpu_dma_latency", "governor",    "isolated_cpus",  "rt_throttling",
    "smt",          "clocksource",     "cpus_online", "virtualisation", "steal_time"};

// A throwaway /sys + /proc + /boot tree.
class FakeRoot : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("hiltwin_probe_" + std::to_string(getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  void Write(const std::string& relative, const std::string& text) {
    const fs::path path = root_ / relative;
    fs::create_directories(path.parent_path());
    std::ofstream(path) << text;
  }

  // Files as on this project's KVM guest (PREEMPT_DYNAMIC, mode none; no cpufreq; no
  // isolcpus; steal time; root with all capabilities).
  void WriteKvmGuest() {
    Write("proc/sys/kernel/version", "#1 SMP PREEMPT_DYNAMIC @0\n");
    Write("proc/sys/kernel/osrelease", "6.18.44-test\n");
    Write("proc/sys/kernel/arch", "x86_64\n");
    Write("boot/config-6.18.44-test",
          "CONFIG_PREEMPT_BUILD=y\nCONFIG_PREEMPT_NONE=y\n# CONFIG_PREEMPT_VOLUNTARY is not set\n"
          "# CONFIG_PREEMPT is not set\nCONFIG_PREEMPT_DYNAMIC=y\n");
    Write("proc/cmdline", "console=ttyS0 quiet panic=1\n");
    Write("proc/self/status", "Name:\thiltwin\nVmLck:\t       0 kB\nCapEff:\t000001fffeffffff\n");
    Write("proc/self/limits",
          "Limit                     Soft Limit           Hard Limit           Units     \n"
          "Max locked memory         8388608              8388608              bytes     \n"
          "Max realtime priority     0                    0                    \n");
    Write("sys/devices/system/cpu/cpu0/uevent", "");
    Write("sys/devices/system/cpu/cpu1/uevent", "");
    Write("sys/devices/system/cpu/online", "0-1\n");
    Write("sys/devices/system/cpu/isolated", "\n");
    Write("sys/devices/system/cpu/smt/active", "0\n");
    Write("sys/devices/system/cpu/smt/control", "notsupported\n");
    Write("sys/devices/system/clocksource/clocksource0/current_clocksource", "tsc\n");
    Write("sys/devices/system/clocksource/clocksource0/available_clocksource", "tsc kvm-clock \n");
    Write("proc/sys/kernel/sched_rt_runtime_us", "950000\n");
    Write("proc/sys/kernel/sched_rt_period_us", "1000000\n");
    Write("proc/cpuinfo", "processor\t: 0\nflags\t\t: fpu vme tsc hypervisor avx2\n");
    Write("proc/stat", "cpu  8571 0 3987 372278 963 0 109 284 0 0\ncpu0 1 2 3 4 5 6 7 8 0 0\n");
  }

  ProbeOptions Options(bool try_privileges = true) const {
    ProbeOptions options;
    options.root = root_;
    options.try_privileges = try_privileges;
    options.steal_sample_ms = 0;
    options.run_tools = false;
    return options;
  }

  const ProbeCheck& Check(const ProbeReport& report, const std::string& id) {
    const ProbeCheck* check = report.Find(id);
    if (check == nullptr) {
      ADD_FAILURE() << "no check " << id;
      static const ProbeCheck kMissing;
      return kMissing;
    }
    return *check;
  }

  static bool Contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  }

  fs::path root_;
  FakeOsCalls os_;
};

TEST_F(FakeRoot, EmptyTreeGivesEveryCheckAsUnknownWarning) {
  const ProbeReport report = RunRtProbe(Options(/*try_privileges=*/false), os_);
  ASSERT_EQ(report.checks.size(), std::size(kAllIds));
  for (std::size_t i = 0; i < std::size(kAllIds); ++i) {
    const ProbeCheck& check = report.checks[i];
    EXPECT_EQ(check.id, kAllIds[i]);
    EXPECT_EQ(check.status, CheckStatus::kWarn) << check.id << ": " << check.value;
    EXPECT_FALSE(check.value.empty()) << check.id;
    EXPECT_FALSE(check.name.empty()) << check.id;
  }
  EXPECT_TRUE(Contains(Check(report, "preemption").value, "unknown"));
  EXPECT_TRUE(Contains(Check(report, "steal_time").value, "unknown"));
  EXPECT_TRUE(Contains(Check(report, "clocksource").value, "unknown"));
  EXPECT_TRUE(Contains(Check(report, "governor").value, "not exposed"));
  EXPECT_TRUE(os_.calls().empty());  // try_privileges = false: nothing tried
}

TEST_F(FakeRoot, KvmGuestLikeThisMachine) {
  WriteKvmGuest();
  const ProbeReport report = RunRtProbe(Options(), os_);

  const ProbeCheck& preemption = Check(report, "preemption");
  EXPECT_EQ(preemption.value,
            "PREEMPT_DYNAMIC, mode none (kernel config default; debugfs not mounted)");
  EXPECT_EQ(preemption.status, CheckStatus::kBad);
  EXPECT_TRUE(Contains(preemption.advice, "linux-image-rt-amd64"));
  EXPECT_TRUE(Contains(preemption.advice, "preempt=full"));

  EXPECT_EQ(Check(report, "sched_fifo").status, CheckStatus::kOk);
  EXPECT_EQ(Check(report, "mlockall").status, CheckStatus::kOk);
  EXPECT_EQ(Check(report, "capabilities").value, "CAP_SYS_NICE yes, CAP_IPC_LOCK yes");
  EXPECT_EQ(Check(report, "rlimit_rtprio").value, "soft 0, hard 0 (not needed: CAP_SYS_NICE)");
  EXPECT_EQ(Check(report, "rlimit_rtprio").status, CheckStatus::kOk);
  EXPECT_EQ(Check(report, "rlimit_memlock").value,
            "soft 8192 KiB, hard 8192 KiB (not needed: CAP_IPC_LOCK)");

  const ProbeCheck& governor = Check(report, "governor");
  EXPECT_EQ(governor.value, "not exposed (no cpufreq driver)");
  EXPECT_EQ(governor.status, CheckStatus::kWarn);
  EXPECT_TRUE(Contains(governor.advice,
                       "echo performance | sudo tee "
                       "/sys/devices/system/cpu/cpu*/cpufreq/scaling_governor"));

  EXPECT_EQ(Check(report, "isolated_cpus").value, "none; nohz_full: not built in");
  EXPECT_EQ(Check(report, "isolated_cpus").status, CheckStatus::kWarn);
  EXPECT_EQ(Check(report, "rt_throttling").value, "sched_rt_runtime_us = 950000 of 1000000 (95 %)");
  EXPECT_EQ(Check(report, "rt_throttling").status, CheckStatus::kWarn);
  EXPECT_EQ(Check(report, "smt").value, "off (control: notsupported)");
  EXPECT_EQ(Check(report, "smt").status, CheckStatus::kOk);
  EXPECT_EQ(Check(report, "clocksource").value, "tsc");
  EXPECT_EQ(Check(report, "clocksource").status, CheckStatus::kOk);
  EXPECT_EQ(Check(report, "cpus_online").value, "0-1 (2)");
  EXPECT_EQ(Check(report, "virtualisation").value, "VM (hypervisor CPU flag)");
  EXPECT_EQ(Check(report, "virtualisation").status, CheckStatus::kWarn);
  // 284 steal ticks of 385'192: 0.07 %, small but present.
  EXPECT_EQ(Check(report, "steal_time").value, "0.07 % since boot");
  EXPECT_EQ(Check(report, "steal_time").status, CheckStatus::kWarn);
}

TEST_F(FakeRoot, PreemptRtFromSysKernelRealtime) {
  WriteKvmGuest();
  Write("sys/kernel/realtime", "1\n");
  const ProbeReport report = RunRtProbe(Options(false), os_);
  EXPECT_EQ(Check(report, "preemption").status, CheckStatus::kOk);
  EXPECT_TRUE(Contains(Check(report, "preemption").value, "PREEMPT_RT"));
}

TEST_F(FakeRoot, PreemptRtFromUnameAlone) {
  Write("proc/sys/kernel/version", "#1 SMP PREEMPT_RT Debian 6.1.90-1\n");
  EXPECT_EQ(Check(RunRtProbe(Options(false), os_), "preemption").status, CheckStatus::kOk);
}

TEST_F(FakeRoot, LiveDynamicModeFromDebugfsWinsOverConfig) {
  WriteKvmGuest();
  Write("sys/kernel/debug/sched/preempt", "none voluntary (full) lazy\n");
  const ProbeCheck check = Check(RunRtProbe(Options(false), os_), "preemption");
  EXPECT_EQ(check.value, "PREEMPT_DYNAMIC, mode full (debugfs sched/preempt)");
  EXPECT_EQ(check.status, CheckStatus::kWarn);
}

TEST_F(FakeRoot, DynamicModeFromBootOption) {
  WriteKvmGuest();
  Write("proc/cmdline", "quiet preempt=voluntary\n");
  const ProbeCheck check = Check(RunRtProbe(Options(false), os_), "preemption");
  EXPECT_EQ(check.value, "PREEMPT_DYNAMIC, mode voluntary (boot option preempt=voluntary)");
  EXPECT_EQ(check.status, CheckStatus::kBad);
}

TEST_F(FakeRoot, DynamicWithoutConfigOrDebugfsSaysHowToFindOut) {
  Write("proc/sys/kernel/version", "#1 SMP PREEMPT_DYNAMIC Debian\n");
  const ProbeCheck check = Check(RunRtProbe(Options(false), os_), "preemption");
  EXPECT_EQ(check.status, CheckStatus::kWarn);
  EXPECT_TRUE(Contains(check.value, "unknown"));
  EXPECT_TRUE(Contains(check.advice, "/sys/kernel/debug/sched/preempt"));
}

// What `hiltwin trace --kernel` records beside the kernel's events (issue 35): the model by
// the kernel config's name, and how it was told.
TEST_F(FakeRoot, KernelPreemptionNamesTheModelAndHowItWasTold) {
  const KernelPreemption none = FindKernelPreemption(Options());
  EXPECT_EQ(none.model, "unknown");
  EXPECT_EQ(none.source, "no uname -v, no kernel config");
  WriteKvmGuest();
  const KernelPreemption guest = FindKernelPreemption(Options());
  EXPECT_EQ(guest.model, "PREEMPT_NONE");
  EXPECT_EQ(guest.source, "PREEMPT_DYNAMIC, kernel config default; debugfs not mounted");
  Write("sys/kernel/debug/sched/preempt", "none voluntary (full) lazy\n");
  const KernelPreemption live = FindKernelPreemption(Options());
  EXPECT_EQ(live.model, "PREEMPT");
  EXPECT_EQ(live.source, "PREEMPT_DYNAMIC, debugfs sched/preempt");
  Write("proc/sys/kernel/version", "#1 SMP PREEMPT_RT Debian 6.1.90-1\n");
  const KernelPreemption rt = FindKernelPreemption(Options());
  EXPECT_EQ(rt.model, "PREEMPT_RT");
  EXPECT_EQ(rt.source, "uname -v");
}

TEST_F(FakeRoot, StaticKernelsFromUname) {
  Write("proc/sys/kernel/version", "#1 SMP PREEMPT Fri Jan 1\n");
  EXPECT_EQ(Check(RunRtProbe(Options(false), os_), "preemption").value, "full (uname -v)");
  Write("proc/sys/kernel/version", "#1 SMP Fri Jan 1\n");
  const ProbeCheck check = Check(RunRtProbe(Options(false), os_), "preemption");
  EXPECT_EQ(check.value, "none or voluntary (uname -v)");
  EXPECT_EQ(check.status, CheckStatus::kBad);
}

TEST_F(FakeRoot, GovernorMixedWarnsWithTheThesisCommandAndAllPerformanceIsOk) {
  Write("sys/devices/system/cpu/cpu0/cpufreq/scaling_governor", "performance\n");
  Write("sys/devices/system/cpu/cpu1/cpufreq/scaling_governor", "powersave\n");
  Write("sys/devices/system/cpu/cpu2/cpufreq/scaling_governor", "powersave\n");
  Write("sys/devices/system/cpu/cpufreq/policy0/scaling_governor", "ignored\n");
  const ProbeCheck mixed = Check(RunRtProbe(Options(false), os_), "governor");
  EXPECT_EQ(mixed.value, "performance on 1 CPU, powersave on 2 CPUs");
  EXPECT_EQ(mixed.status, CheckStatus::kWarn);
  EXPECT_TRUE(Contains(mixed.advice, "§3.8.2"));
  EXPECT_TRUE(Contains(mixed.advice, "echo performance | sudo tee"));

  Write("sys/devices/system/cpu/cpu1/cpufreq/scaling_governor", "performance\n");
  Write("sys/devices/system/cpu/cpu2/cpufreq/scaling_governor", "performance\n");
  const ProbeCheck all = Check(RunRtProbe(Options(false), os_), "governor");
  EXPECT_EQ(all.value, "performance on 3 CPUs");
  EXPECT_EQ(all.status, CheckStatus::kOk);
}

TEST_F(FakeRoot, IsolatedCpusWithNohzFullAreOk) {
  Write("sys/devices/system/cpu/isolated", "3\n");
  Write("sys/devices/system/cpu/nohz_full", "3\n");
  const ProbeCheck check = Check(RunRtProbe(Options(false), os_), "isolated_cpus");
  EXPECT_EQ(check.value, "3; nohz_full: 3");
  EXPECT_EQ(check.status, CheckStatus::kOk);
}

TEST_F(FakeRoot, ThrottlingOffIsOkButWarnsOfLockUp) {
  Write("proc/sys/kernel/sched_rt_runtime_us", "-1\n");
  const ProbeCheck check = Check(RunRtProbe(Options(false), os_), "rt_throttling");
  EXPECT_EQ(check.status, CheckStatus::kOk);
  EXPECT_TRUE(Contains(check.advice, "lock up"));
}

TEST_F(FakeRoot, SmtOnWarns) {
  Write("sys/devices/system/cpu/smt/active", "1\n");
  const ProbeCheck check = Check(RunRtProbe(Options(false), os_), "smt");
  EXPECT_EQ(check.value, "on");
  EXPECT_EQ(check.status, CheckStatus::kWarn);
}

// A Raspberry Pi 4 on Raspberry Pi OS: arm64, booted by the firmware (no GRUB), its cores one
// thread each with no SMT control in the kernel, the arm generic timer as clocksource.
TEST_F(FakeRoot, RaspberryPiAdviceNamesThePisKernelAndBootFiles) {
  WriteKvmGuest();
  Write("proc/sys/kernel/arch", "aarch64\n");
  Write("boot/firmware/cmdline.txt", "console=serial0,115200 root=PARTUUID=0 rootwait\n");
  Write("sys/devices/system/clocksource/clocksource0/current_clocksource", "arch_sys_counter\n");
  const ProbeReport report = RunRtProbe(Options(), os_);

  const ProbeCheck& preemption = Check(report, "preemption");
  EXPECT_EQ(preemption.status, CheckStatus::kBad);
  EXPECT_TRUE(Contains(preemption.advice, "bcm2711_rt_defconfig")) << preemption.advice;
  EXPECT_TRUE(Contains(preemption.advice, "/boot/firmware/cmdline.txt")) << preemption.advice;
  EXPECT_FALSE(Contains(preemption.advice, "amd64")) << preemption.advice;
  EXPECT_FALSE(Contains(preemption.advice, "grub")) << preemption.advice;
  const ProbeCheck& isolation = Check(report, "isolated_cpus");
  EXPECT_TRUE(Contains(isolation.advice, "/boot/firmware/cmdline.txt")) << isolation.advice;
  EXPECT_EQ(Check(report, "clocksource").value, "arch_sys_counter");
  EXPECT_EQ(Check(report, "clocksource").status, CheckStatus::kOk);

  // Plain Debian on an arm64 board boots through GRUB and has Debian's arm64 RT kernel.
  fs::remove(root_ / "boot/firmware/cmdline.txt");
  const ProbeReport debian = RunRtProbe(Options(), os_);
  EXPECT_TRUE(Contains(Check(debian, "preemption").advice, "linux-image-rt-arm64"));
  EXPECT_TRUE(Contains(Check(debian, "isolated_cpus").advice, "GRUB_CMDLINE_LINUX"));
}

TEST_F(FakeRoot, WithoutSmtControlTheTopologyTellsWhetherCoresAreShared) {
  WriteKvmGuest();
  fs::remove_all(root_ / "sys/devices/system/cpu/smt");
  Write("sys/devices/system/cpu/cpu0/topology/thread_siblings_list", "0\n");
  Write("sys/devices/system/cpu/cpu1/topology/thread_siblings_list", "1\n");
  const ProbeReport one_each = RunRtProbe(Options(), os_);
  const ProbeCheck& alone = Check(one_each, "smt");
  EXPECT_EQ(alone.value, "none (one thread per core)");
  EXPECT_EQ(alone.status, CheckStatus::kOk);

  Write("sys/devices/system/cpu/cpu0/topology/thread_siblings_list", "0-1\n");
  Write("sys/devices/system/cpu/cpu1/topology/thread_siblings_list", "0-1\n");
  const ProbeReport shared = RunRtProbe(Options(), os_);
  EXPECT_EQ(Check(shared, "smt").status, CheckStatus::kWarn);
  EXPECT_TRUE(Contains(Check(shared, "smt").value, "cpu0 shares its core: 0-1"));

  Write("sys/devices/system/cpu/cpu0/topology/thread_siblings_list", "0\n");
  fs::remove_all(root_ / "sys/devices/system/cpu/cpu1/topology");
  const ProbeReport unreadable = RunRtProbe(Options(), os_);
  EXPECT_TRUE(Contains(Check(unreadable, "smt").value, "unknown"));
}

TEST_F(FakeRoot, ClocksourceGrades) {
  const std::string base = "sys/devices/system/clocksource/clocksource0/";
  Write(base + "available_clocksource", "tsc hpet acpi_pm\n");
  Write(base + "current_clocksource", "hpet\n");
  ProbeCheck check = Check(RunRtProbe(Options(false), os_), "clocksource");
  EXPECT_EQ(check.status, CheckStatus::kBad);
  EXPECT_TRUE(Contains(check.advice, "echo tsc | sudo tee"));
  Write(base + "current_clocksource", "kvm-clock\n");
  check = Check(RunRtProbe(Options(false), os_), "clocksource");
  EXPECT_EQ(check.status, CheckStatus::kWarn);
  EXPECT_EQ(check.value, "kvm-clock (paravirtual)");
}

TEST_F(FakeRoot, OneCpuWarnsAndBareMetalIsOk) {
  Write("sys/devices/system/cpu/online", "0\n");
  Write("proc/cpuinfo", "processor\t: 0\nflags\t\t: fpu vme tsc avx2\n");
  const ProbeReport report = RunRtProbe(Options(false), os_);
  EXPECT_EQ(Check(report, "cpus_online").value, "0 (1)");
  EXPECT_EQ(Check(report, "cpus_online").status, CheckStatus::kWarn);
  EXPECT_EQ(Check(report, "virtualisation").value, "bare metal");
  EXPECT_EQ(Check(report, "virtualisation").status, CheckStatus::kOk);
}

TEST_F(FakeRoot, RefusedPrivilegesAreBadWithAdvice) {
  WriteKvmGuest();
  Write("proc/self/status", "VmLck:\t0 kB\nCapEff:\t0000000000000000\n");
  os_.Refuse(Call::kSetScheduler, EPERM);
  os_.Refuse(Call::kLockAll, ENOMEM);
  os_.Refuse(Call::kOpenDmaLatency, EACCES);
  const ProbeReport report = RunRtProbe(Options(), os_);

  const ProbeCheck& fifo = Check(report, "sched_fifo");
  EXPECT_EQ(fifo.status, CheckStatus::kBad);
  EXPECT_TRUE(Contains(fifo.value, "EPERM"));
  EXPECT_TRUE(Contains(fifo.advice, "setcap"));
  const ProbeCheck& lock = Check(report, "mlockall");
  EXPECT_EQ(lock.status, CheckStatus::kBad);
  EXPECT_TRUE(Contains(lock.value, "ENOMEM"));
  EXPECT_EQ(Check(report, "cpu_dma_latency").status, CheckStatus::kWarn);
  EXPECT_TRUE(Contains(Check(report, "cpu_dma_latency").value, "EACCES"));
  EXPECT_EQ(Check(report, "capabilities").value, "CAP_SYS_NICE no, CAP_IPC_LOCK no");
  EXPECT_EQ(Check(report, "capabilities").status, CheckStatus::kWarn);
  EXPECT_EQ(Check(report, "rlimit_rtprio").status, CheckStatus::kBad);    // 0/0, no capability
  EXPECT_EQ(Check(report, "rlimit_memlock").status, CheckStatus::kWarn);  // 8 MiB, no capability
  EXPECT_TRUE(Contains(Check(report, "rlimit_memlock").advice, "memlock unlimited"));
  EXPECT_TRUE(os_.calls(Call::kUnlockAll).empty());  // nothing to undo
}

TEST_F(FakeRoot, RtprioSoftZeroHardHighSuggestsUlimit) {
  Write("proc/self/status", "CapEff:\t0000000000000000\n");
  Write("proc/self/limits",
        "Max locked memory         unlimited            unlimited            bytes\n"
        "Max realtime priority     0                    95\n");
  const ProbeReport report = RunRtProbe(Options(false), os_);
  EXPECT_EQ(Check(report, "rlimit_rtprio").status, CheckStatus::kWarn);
  EXPECT_TRUE(Contains(Check(report, "rlimit_rtprio").advice, "ulimit -r 95"));
  EXPECT_EQ(Check(report, "rlimit_memlock").value, "soft unlimited, hard unlimited");
  EXPECT_EQ(Check(report, "rlimit_memlock").status, CheckStatus::kOk);
}

TEST_F(FakeRoot, PrivilegeTriesAreUndoneAndFifoIsTriedOffThisThread) {
  WriteKvmGuest();
  const ProbeReport report = RunRtProbe(Options(), os_);
  const auto sched = os_.calls(Call::kSetScheduler);
  ASSERT_EQ(sched.size(), 2u);
  EXPECT_EQ(sched[0].a, SCHED_FIFO);
  EXPECT_EQ(sched[1].a, SCHED_OTHER);  // restored
  EXPECT_NE(sched[0].thread, std::this_thread::get_id());
  const auto lock = os_.calls(Call::kLockAll);
  ASSERT_EQ(lock.size(), 1u);
  EXPECT_EQ(lock[0].a, MCL_CURRENT | MCL_ONFAULT);
  EXPECT_EQ(os_.calls(Call::kUnlockAll).size(), 1u);
  EXPECT_EQ(os_.closed_fds(), (std::vector<int>{FakeOsCalls::kFakeFd}));
  EXPECT_EQ(Check(report, "cpu_dma_latency").status, CheckStatus::kOk);
}

TEST_F(FakeRoot, AlreadyLockedMemoryIsNotTouched) {
  WriteKvmGuest();
  Write("proc/self/status", "VmLck:\t   40960 kB\nCapEff:\t000001fffeffffff\n");
  const ProbeCheck check = Check(RunRtProbe(Options(), os_), "mlockall");
  EXPECT_EQ(check.status, CheckStatus::kOk);
  EXPECT_TRUE(Contains(check.value, "already locked"));
  EXPECT_TRUE(os_.calls(Call::kLockAll).empty());
  EXPECT_TRUE(os_.calls(Call::kUnlockAll).empty());
}

TEST_F(FakeRoot, SkippedTriesAreMarkedAndNoAdviceNamesACommandFlag) {
  const ProbeReport report = RunRtProbe(Options(/*try_privileges=*/false), os_);
  for (const char* id : {"sched_fifo", "mlockall", "cpu_dma_latency"}) {
    const ProbeCheck& check = Check(report, id);
    EXPECT_TRUE(check.not_tried) << id;
    EXPECT_EQ(check.value, "unknown (not tried)") << id;
    EXPECT_EQ(check.status, CheckStatus::kWarn) << id;
    EXPECT_EQ(check.advice, "") << id;  // the command words how to try it
  }
  std::size_t not_tried = 0;
  for (const auto& check : report.checks) {
    not_tried += check.not_tried ? 1U : 0U;
    // Every other line that is not ok says what to do, in the probe's own terms.
    if (!check.not_tried) {
      EXPECT_FALSE(check.advice.empty()) << check.id;
    }
    for (const char* flag : {"--no-try", "--root", "hiltwin doctor"}) {
      EXPECT_EQ(check.advice.find(flag), std::string::npos) << check.id << ": " << check.advice;
    }
  }
  EXPECT_EQ(not_tried, 3u);
  EXPECT_FALSE(Check(RunRtProbe(Options(), os_), "sched_fifo").not_tried);
}

TEST_F(FakeRoot, CountAndFindAgreeWithTheChecks) {
  WriteKvmGuest();
  const ProbeReport report = RunRtProbe(Options(), os_);
  EXPECT_EQ(report.Count(CheckStatus::kOk) + report.Count(CheckStatus::kWarn) +
                report.Count(CheckStatus::kBad),
            report.checks.size());
  EXPECT_EQ(report.Find("preemption"), &report.checks.front());
  EXPECT_EQ(report.Find("no_such_check"), nullptr);
}

TEST(ProcStat, ParsesTheAggregateLine) {
  const auto ticks = ParseProcStat("cpu  100 0 100 700 0 0 0 100 5 0\ncpu0 1 1 1 1 1 1 1 1 1 1\n");
  ASSERT_TRUE(ticks.has_value());
  EXPECT_EQ(ticks->total, 1000u);  // guest (5) is already inside user
  EXPECT_EQ(ticks->steal, 100u);
  EXPECT_FALSE(ParseProcStat("").has_value());
  EXPECT_FALSE(ParseProcStat("cpu  1 2 3\n").has_value());
  EXPECT_FALSE(ParseProcStat("cpu  1 2 3 4 5 6 7 x 0 0\n").has_value());
  EXPECT_FALSE(ParseProcStat("cpu0 1 2 3 4 5 6 7 8 0 0\n").has_value());
}

TEST(ProcStat, StealGrades) {
  const CpuTicks none{1000, 0};
  EXPECT_EQ(AssessSteal(none, none, CpuTicks{1100, 0}, 200).status, CheckStatus::kOk);
  EXPECT_EQ(AssessSteal(none, none, CpuTicks{1100, 0}, 200).value,
            "0.00 % since boot, 0.00 % over 200 ms");
  // Nothing since boot, 2 of 100 ticks in the window: present, below 5 %.
  const ProbeCheck window = AssessSteal(none, none, CpuTicks{1100, 2}, 200);
  EXPECT_EQ(window.status, CheckStatus::kWarn);
  EXPECT_EQ(window.value, "0.00 % since boot, 2.00 % over 200 ms");
  EXPECT_EQ(AssessSteal(none, none, CpuTicks{1100, 10}, 200).status, CheckStatus::kBad);
  EXPECT_EQ(AssessSteal(CpuTicks{1000, 100}, std::nullopt, std::nullopt, 0).status,
            CheckStatus::kBad);
  EXPECT_EQ(AssessSteal(std::nullopt, std::nullopt, std::nullopt, 0).status, CheckStatus::kWarn);
  // A counter that ran backwards (bad input) is ignored rather than wrapped.
  EXPECT_EQ(AssessSteal(none, CpuTicks{1000, 5}, CpuTicks{1100, 0}, 200).value,
            "0.00 % since boot");
}

// The real machine: whatever it is, the probe completes and says something on every line.
TEST(RtProbeReal, RunsOnThisMachineWithoutTrying) {
  ProbeOptions options;
  options.try_privileges = false;
  options.steal_sample_ms = 0;
  options.run_tools = false;
  const ProbeReport report = RunRtProbe(options);
  ASSERT_EQ(report.checks.size(), std::size(kAllIds));
  for (const auto& check : report.checks) EXPECT_FALSE(check.value.empty()) << check.id;
}

}  // namespace
}  // namespace hiltwin::kernel_glue
