#include "hiltwin/kernel_glue/rt_probe.h"

#include <sched.h>
#include <sys/mman.h>
#include <sys/utsname.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>
#include <thread>

#include "hiltwin/kernel_glue/process.h"

namespace hiltwin::kernel_glue {
namespace {

constexpr std::string_view kGovernorCommand =
    "echo performance | sudo tee /sys/devices/system/cpu/cpu*/cpufreq/scaling_governor";

// A tool that hangs (a stuck systemd) must not hang the doctor.
constexpr std::chrono::milliseconds kToolTimeout{10'000};

// Bits of the capability sets in /proc/<pid>/status (linux/capability.h).
constexpr unsigned kCapIpcLock = 14;
constexpr unsigned kCapSysNice = 23;

std::string Trim(std::string_view text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string_view::npos) return {};
  const auto end = text.find_last_not_of(" \t\r\n");
  return std::string(text.substr(begin, end - begin + 1));
}

std::vector<std::string> Words(std::string_view text) {
  std::vector<std::string> words;
  std::istringstream stream{std::string(text)};
  for (std::string word; stream >> word;) words.push_back(word);
  return words;
}

bool HasWord(std::string_view text, std::string_view word) {
  const auto words = Words(text);
  return std::find(words.begin(), words.end(), word) != words.end();
}

template <typename Integer>
std::optional<Integer> ParseInteger(std::string_view text, int base = 10) {
  const std::string trimmed = Trim(text);
  Integer value{};
  const char* end = trimmed.data() + trimmed.size();
  const auto result = std::from_chars(trimmed.data(), end, value, base);
  if (trimmed.empty() || result.ec != std::errc{} || result.ptr != end) return std::nullopt;
  return value;
}

// The probe's view of the machine: files below the root prefix, plus the real system's
// uname() and helper tools only when the root is the real one.
class Machine {
 public:
  explicit Machine(const ProbeOptions& options)
      : options_(options), real_root_(options.root.lexically_normal() == "/") {}

  [[nodiscard]] std::optional<std::string> Read(std::string_view relative) const {
    std::ifstream file(options_.root / std::filesystem::path(relative), std::ios::binary);
    if (!file) return std::nullopt;
    std::ostringstream text;
    text << file.rdbuf();
    if (file.bad()) return std::nullopt;
    return text.str();
  }

  [[nodiscard]] std::optional<std::string> ReadTrimmed(std::string_view relative) const {
    auto text = Read(relative);
    if (text) *text = Trim(*text);
    return text;
  }

  [[nodiscard]] std::filesystem::path Path(std::string_view relative) const {
    return options_.root / std::filesystem::path(relative);
  }

  // uname -v: /proc/sys/kernel/version holds the same text and honours the prefix.
  [[nodiscard]] std::optional<std::string> KernelVersion() const {
    if (auto version = ReadTrimmed("proc/sys/kernel/version")) return version;
    utsname names{};
    if (real_root_ && uname(&names) == 0) return std::string(names.version);
    return std::nullopt;
  }

  // uname -m ("x86_64", "aarch64"): /proc/sys/kernel/arch holds it and honours the prefix.
  [[nodiscard]] std::string Architecture() const {
    if (auto arch = ReadTrimmed("proc/sys/kernel/arch"); arch && !arch->empty()) return *arch;
    utsname names{};
    if (real_root_ && uname(&names) == 0) return std::string(names.machine);
    return {};
  }

  [[nodiscard]] std::optional<std::string> KernelRelease() const {
    if (auto release = ReadTrimmed("proc/sys/kernel/osrelease")) return release;
    utsname names{};
    if (real_root_ && uname(&names) == 0) return std::string(names.release);
    return std::nullopt;
  }

  // Kernel build configuration: /boot/config-<release> (Debian) or /proc/config.gz.
  [[nodiscard]] std::optional<std::string> KernelConfig() const {
    if (const auto release = KernelRelease()) {
      if (auto config = Read("boot/config-" + *release)) return config;
    }
    const auto gz = Path("proc/config.gz");
    std::error_code error;
    if (options_.run_tools && std::filesystem::exists(gz, error)) {
      return RunTool({"gzip", "-dc", gz.string()});
    }
    return std::nullopt;
  }

  // Runs a tool and returns its standard output whatever its exit code (systemd-detect-virt
  // prints "none" and exits 1); nullopt when it cannot start or hangs.
  [[nodiscard]] std::optional<std::string> RunTool(const std::vector<std::string>& argv) const {
    if (!options_.run_tools || argv.empty()) return std::nullopt;
    ProcessOptions streams;
    streams.out = OutputTarget::Capture();
    streams.err = OutputTarget::Discard();
    try {
      ProcessResult result = RunProcess(argv, streams, kToolTimeout);
      if (result.status.timed_out) return std::nullopt;
      return std::move(result.out);
    } catch (const SpawnError&) {
      return std::nullopt;  // not installed: the check falls back to files
    }
  }

  [[nodiscard]] bool real_root() const noexcept { return real_root_; }
  [[nodiscard]] const ProbeOptions& options() const noexcept { return options_; }

 private:
  const ProbeOptions& options_;
  bool real_root_;
};

ProbeCheck Make(std::string id, std::string name, std::string value, CheckStatus status,
                std::string advice = {}) {
  ProbeCheck check;
  check.id = std::move(id);
  check.name = std::move(name);
  check.value = std::move(value);
  check.status = status;
  check.advice = std::move(advice);
  return check;
}

ProbeCheck Unknown(std::string id, std::string name, std::string_view why,
                   std::string advice = {}) {
  // Every line that is not ok says what to do, unknown ones included.
  if (advice.empty()) {
    advice =
        "could not be read: check that /proc and /sys are mounted (or that the probed root "
        "holds a full copy of them), or check it by hand as docs/realtime-setup.md describes";
  }
  return Make(std::move(id), std::move(name), "unknown (" + std::string(why) + ")",
              CheckStatus::kWarn, std::move(advice));
}

// A privilege try the options ruled out: a fact, no advice (only the caller knows how its
// user asks for the try).
ProbeCheck NotTried(std::string id, std::string name) {
  ProbeCheck check =
      Make(std::move(id), std::move(name), "unknown (not tried)", CheckStatus::kWarn);
  check.not_tried = true;
  return check;
}

// What differs between a PC and a Raspberry Pi when the advice says "install" or "boot with":
// which real-time kernel to get and where the kernel's command line is kept.
struct PlatformAdvice {
  std::string rt_kernel;     ///< how to get a PREEMPT_RT kernel here
  std::string boot_options;  ///< where boot options such as isolcpus= go
};

PlatformAdvice AdviceFor(const Machine& machine) {
  const std::string arch = machine.Architecture();
  // Raspberry Pi OS boots from the firmware's partition, not through GRUB.
  const bool pi_boot = machine.Read("boot/firmware/cmdline.txt").has_value();
  PlatformAdvice advice;
  if (arch == "aarch64" && pi_boot) {
    advice.rt_kernel =
        "on a Raspberry Pi 4 boot the Raspberry Pi kernel built with its bcm2711_rt_defconfig "
        "(\"-v8-rt\"; kernel= in /boot/firmware/config.txt, docs/raspberry-pi.md)";
    advice.boot_options = "append them to the one line of /boot/firmware/cmdline.txt, reboot";
  } else {
    const std::string debian_arch = arch == "aarch64" ? "arm64" : "amd64";
    advice.rt_kernel =
        "Debian 12: `sudo apt install linux-image-rt-" + debian_arch + "`, then boot it";
    advice.boot_options = "GRUB_CMDLINE_LINUX in /etc/default/grub, sudo update-grub";
  }
  return advice;
}

// "key: value" lines of /proc/self/status.
std::optional<std::string> StatusField(const std::optional<std::string>& status,
                                       std::string_view key) {
  if (!status) return std::nullopt;
  std::istringstream lines(*status);
  for (std::string line; std::getline(lines, line);) {
    if (line.size() > key.size() && line.compare(0, key.size(), key) == 0 &&
        line[key.size()] == ':') {
      return Trim(std::string_view(line).substr(key.size() + 1));
    }
  }
  return std::nullopt;
}

struct Limit {
  std::optional<std::uint64_t> soft;  // nullopt: unlimited
  std::optional<std::uint64_t> hard;
};

// A "Max ..." line of /proc/self/limits: soft and hard columns, "unlimited" allowed.
std::optional<Limit> ParseLimit(const std::optional<std::string>& limits, std::string_view label) {
  if (!limits) return std::nullopt;
  std::istringstream lines(*limits);
  for (std::string line; std::getline(lines, line);) {
    if (line.compare(0, label.size(), label) != 0) continue;
    const auto words = Words(std::string_view(line).substr(label.size()));
    if (words.size() < 2) return std::nullopt;
    Limit limit;
    for (int column = 0; column < 2; ++column) {
      const auto& word = words[static_cast<std::size_t>(column)];
      std::optional<std::uint64_t> value;
      if (word != "unlimited") {
        value = ParseInteger<std::uint64_t>(word);
        if (!value) return std::nullopt;
      }
      (column == 0 ? limit.soft : limit.hard) = value;
    }
    return limit;
  }
  return std::nullopt;
}

std::string LimitText(const std::optional<std::uint64_t>& value) {
  return value ? std::to_string(*value) : "unlimited";
}

struct Capabilities {
  bool sys_nice = false;
  bool ipc_lock = false;
};

std::optional<Capabilities> ParseCapabilities(const std::optional<std::string>& status) {
  const auto field = StatusField(status, "CapEff");
  if (!field) return std::nullopt;
  const auto mask = ParseInteger<std::uint64_t>(*field, 16);
  if (!mask) return std::nullopt;
  return Capabilities{((*mask >> kCapSysNice) & 1U) != 0, ((*mask >> kCapIpcLock) & 1U) != 0};
}

bool ConfigHas(const std::optional<std::string>& config, std::string_view line) {
  return config && config->find(std::string(line) + "\n") != std::string::npos;
}

// A preemption mode ("full") and where it was read; an empty mode means not found.
struct PreemptMode {
  std::string mode;
  std::string source;
};

// A PREEMPT_DYNAMIC kernel picks its mode at boot, so the build configuration may not be the
// mode that runs: ask the live kernel first.
PreemptMode LiveDynamicMode(const Machine& machine) {
  // debugfs shows the live mode as "none voluntary (full) lazy".
  if (const auto live = machine.ReadTrimmed("sys/kernel/debug/sched/preempt")) {
    const auto open = live->find('(');
    const auto close = live->find(')', open);
    if (open != std::string::npos && close != std::string::npos) {
      PreemptMode debugfs{live->substr(open + 1, close - open - 1), "debugfs sched/preempt"};
      if (!debugfs.mode.empty()) return debugfs;
    }
  }
  PreemptMode found;
  if (const auto cmdline = machine.ReadTrimmed("proc/cmdline")) {
    for (const auto& word : Words(*cmdline)) {
      if (word.rfind("preempt=", 0) == 0) found = {word.substr(8), "boot option " + word};
    }
  }
  return found;
}

PreemptMode ConfigMode(const std::optional<std::string>& config, bool dynamic) {
  std::string mode;
  if (ConfigHas(config, "CONFIG_PREEMPT_LAZY=y")) {
    mode = "lazy";
  } else if (ConfigHas(config, "CONFIG_PREEMPT=y")) {
    mode = "full";
  } else if (ConfigHas(config, "CONFIG_PREEMPT_VOLUNTARY=y")) {
    mode = "voluntary";
  } else if (ConfigHas(config, "CONFIG_PREEMPT_NONE=y")) {
    mode = "none";
  }
  if (mode.empty()) return {};
  return {mode, dynamic ? "kernel config default; debugfs not mounted" : "kernel config"};
}

// uname -v names PREEMPT and PREEMPT_LAZY only, so it cannot tell none from voluntary.
PreemptMode UnameMode(const std::string& version) {
  if (HasWord(version, "PREEMPT_LAZY")) return {"lazy", "uname -v"};
  if (HasWord(version, "PREEMPT")) return {"full", "uname -v"};
  return {"none or voluntary", "uname -v"};
}

// The most direct source wins: the live mode, then the build configuration, then uname -v
// (whose PREEMPT says nothing about a dynamic kernel's live mode).
PreemptMode FindPreemptMode(const Machine& machine, const std::optional<std::string>& version,
                            const std::optional<std::string>& config, bool dynamic) {
  PreemptMode found;
  if (dynamic) found = LiveDynamicMode(machine);
  if (found.mode.empty()) found = ConfigMode(config, dynamic);
  if (found.mode.empty() && !dynamic && version) found = UnameMode(*version);
  return found;
}

// What the kernel tells of its preemption: PREEMPT_RT (and from where), PREEMPT_DYNAMIC, and
// otherwise the mode and where it was read.
struct PreemptionFacts {
  std::string rt_source;  // empty: not PREEMPT_RT
  bool dynamic = false;
  PreemptMode found;
  bool nothing_to_read = false;  // no uname -v and no kernel config
};

PreemptionFacts ReadPreemption(const Machine& machine) {
  const auto realtime = machine.ReadTrimmed("sys/kernel/realtime");
  const auto version = machine.KernelVersion();
  const auto config = machine.KernelConfig();
  PreemptionFacts facts;
  if (realtime && *realtime == "1") {
    facts.rt_source = "/sys/kernel/realtime";
  } else if (version && HasWord(*version, "PREEMPT_RT")) {
    facts.rt_source = "uname -v";
  } else if (ConfigHas(config, "CONFIG_PREEMPT_RT=y")) {
    facts.rt_source = "kernel config";
  }
  if (!facts.rt_source.empty()) return facts;
  facts.dynamic = (version && HasWord(*version, "PREEMPT_DYNAMIC")) ||
                  ConfigHas(config, "CONFIG_PREEMPT_DYNAMIC=y");
  facts.found = FindPreemptMode(machine, version, config, facts.dynamic);
  facts.nothing_to_read = !version && !config;
  return facts;
}

// The kernel config's name of a mode: "none" is PREEMPT_NONE, "full" is PREEMPT.
std::string ConfigName(const std::string& mode) {
  if (mode == "none") return "PREEMPT_NONE";
  if (mode == "voluntary") return "PREEMPT_VOLUNTARY";
  if (mode == "full") return "PREEMPT";
  if (mode == "lazy") return "PREEMPT_LAZY";
  if (mode == "none or voluntary") return "PREEMPT_NONE or PREEMPT_VOLUNTARY";
  return "preempt=" + mode;  // a boot option this code does not know yet: as given
}

ProbeCheck CheckPreemption(const Machine& machine) {
  const std::string id = "preemption";
  const std::string name = "preemption model";
  const PlatformAdvice platform = AdviceFor(machine);
  const std::string rt_advice =
      "for wake-up latency in tens of microseconds use a PREEMPT_RT kernel (" + platform.rt_kernel +
      ")";
  const PreemptionFacts facts = ReadPreemption(machine);
  if (!facts.rt_source.empty()) {
    return Make(id, name, "PREEMPT_RT (fully preemptible kernel)", CheckStatus::kOk);
  }
  const bool dynamic = facts.dynamic;
  const PreemptMode& found = facts.found;
  const std::string prefix = dynamic ? "PREEMPT_DYNAMIC, mode " : "";
  if (found.mode.empty()) {
    if (facts.nothing_to_read) {
      return Unknown(id, name, "no uname -v, no kernel config", rt_advice);
    }
    return Make(id, name, prefix + "unknown (debugfs not mounted, no kernel config)",
                CheckStatus::kWarn,
                "see the live mode with `sudo mount -t debugfs none /sys/kernel/debug` and `cat "
                "/sys/kernel/debug/sched/preempt`. " +
                    rt_advice);
  }
  const std::string value = prefix + found.mode + " (" + found.source + ")";
  if (found.mode == "full" || found.mode == "lazy") {
    return Make(id, name, value, CheckStatus::kWarn,
                "fine for millisecond deadlines; " + rt_advice);
  }
  std::string advice =
      "a kernel without full preemption can delay a wake-up by milliseconds; " + rt_advice;
  if (dynamic) {
    advice += "; as a stop-gap boot this kernel with preempt=full (" + platform.boot_options + ")";
  }
  return Make(id, name, value, CheckStatus::kBad, advice);
}

ProbeCheck CheckSchedFifo(const Machine& machine, const OsCalls& os) {
  const std::string id = "sched_fifo";
  const std::string name = "SCHED_FIFO (tried)";
  if (!machine.options().try_privileges) return NotTried(id, name);
  int error = 0;
  // A throwaway thread, so the caller's own policy is never touched.
  std::thread trial([&] {
    error = os.SetThreadScheduler(SCHED_FIFO, 1);
    if (error == 0) (void)os.SetThreadScheduler(SCHED_OTHER, 0);
  });
  trial.join();
  if (error == 0) {
    return Make(id, name, "granted (priority 1 on a throwaway thread)", CheckStatus::kOk);
  }
  return Make(id, name, "refused: " + ErrnoText(error), CheckStatus::kBad,
              "run as root, or `sudo setcap cap_sys_nice,cap_ipc_lock+ep <path of hiltwin>`, or "
              "add '@realtime - rtprio 98' to /etc/security/limits.conf and join group "
              "realtime (log in again); in a container add --cap-add=SYS_NICE; with RT group "
              "scheduling give the cgroup cpu.rt_runtime_us. Without it runs use SCHED_OTHER");
}

ProbeCheck CheckMlockall(const Machine& machine, const OsCalls& os) {
  const std::string id = "mlockall";
  const std::string name = "mlockall (tried)";
  const auto status = machine.Read("proc/self/status");
  if (const auto locked = StatusField(status, "VmLck")) {
    const auto words = Words(*locked);
    const auto kib = words.empty() ? std::nullopt : ParseInteger<std::uint64_t>(words[0]);
    if (kib && *kib > 0) {
      return Make(id, name, "already locked (VmLck " + *locked + ")", CheckStatus::kOk);
    }
  }
  if (!machine.options().try_privileges) return NotTried(id, name);
  // MCL_ONFAULT: the same permission check as a full lock, without faulting everything in.
  const int error = os.LockAllMemory(MCL_CURRENT | MCL_ONFAULT);
  if (error == 0) {
    (void)os.UnlockAllMemory();
    return Make(id, name, "granted (locked, then unlocked again)", CheckStatus::kOk);
  }
  return Make(id, name, "refused: " + ErrnoText(error), CheckStatus::kBad,
              "run as root, or `sudo setcap cap_ipc_lock,cap_sys_nice+ep <path of hiltwin>`, or "
              "add '@realtime - memlock unlimited' to /etc/security/limits.conf; in a "
              "container add --cap-add=IPC_LOCK --ulimit memlock=-1. Without it page faults "
              "can stall the loop");
}

ProbeCheck CheckRtprio(const Machine& machine, const std::optional<Capabilities>& caps) {
  const std::string id = "rlimit_rtprio";
  const std::string name = "RLIMIT_RTPRIO";
  const auto limit = ParseLimit(machine.Read("proc/self/limits"), "Max realtime priority");
  if (!limit) return Unknown(id, name, "/proc/self/limits unreadable");
  const std::string value = "soft " + LimitText(limit->soft) + ", hard " + LimitText(limit->hard);
  if (caps && caps->sys_nice) {
    return Make(id, name, value + " (not needed: CAP_SYS_NICE)", CheckStatus::kOk);
  }
  const std::uint64_t soft = limit->soft.value_or(99);
  if (soft >= 1) return Make(id, name, value, CheckStatus::kOk);
  const std::string advice =
      "allow SCHED_FIFO without root: add '@realtime - rtprio 98' to "
      "/etc/security/limits.conf, `sudo usermod -aG realtime $USER`, log in again";
  if (limit->hard.value_or(99) >= 1) {
    return Make(id, name, value, CheckStatus::kWarn,
                "raise the soft limit in this shell: `ulimit -r " + LimitText(limit->hard) + "`");
  }
  return Make(id, name, value, CheckStatus::kBad, advice);
}

ProbeCheck CheckMemlock(const Machine& machine, const std::optional<Capabilities>& caps) {
  const std::string id = "rlimit_memlock";
  const std::string name = "RLIMIT_MEMLOCK";
  const auto limit = ParseLimit(machine.Read("proc/self/limits"), "Max locked memory");
  if (!limit) return Unknown(id, name, "/proc/self/limits unreadable");
  auto text = [](const std::optional<std::uint64_t>& bytes) {
    return bytes ? std::to_string(*bytes >> 10) + " KiB" : std::string("unlimited");
  };
  const std::string value = "soft " + text(limit->soft) + ", hard " + text(limit->hard);
  if (caps && caps->ipc_lock) {
    return Make(id, name, value + " (not needed: CAP_IPC_LOCK)", CheckStatus::kOk);
  }
  // The same rule as RtSession: below 1 GiB (or unlimited) hiltwin does not lock, because
  // mlockall(MCL_FUTURE) would make every allocation past the limit fail mid-run.
  if (!limit->hard || *limit->hard >= (std::uint64_t{1} << 30)) {
    return Make(id, name, value, CheckStatus::kOk,
                limit->soft && *limit->soft < (std::uint64_t{1} << 30)
                    ? "hiltwin raises the soft limit to the hard one before locking"
                    : "");
  }
  return Make(id, name, value, CheckStatus::kWarn,
              "too small to lock the whole process, so runs stay unlocked (with MCL_FUTURE, "
              "allocations past the limit would fail): add '@realtime - memlock unlimited' to "
              "/etc/security/limits.conf, or grant CAP_IPC_LOCK");
}

ProbeCheck CheckCapabilities(const std::optional<Capabilities>& caps) {
  const std::string id = "capabilities";
  const std::string name = "capabilities (effective)";
  if (!caps) return Unknown(id, name, "no CapEff in /proc/self/status");
  const std::string value = std::string("CAP_SYS_NICE ") + (caps->sys_nice ? "yes" : "no") +
                            ", CAP_IPC_LOCK " + (caps->ipc_lock ? "yes" : "no");
  if (caps->sys_nice && caps->ipc_lock) return Make(id, name, value, CheckStatus::kOk);
  return Make(id, name, value, CheckStatus::kWarn,
              "without root, grant them to the binary: `sudo setcap cap_sys_nice,cap_ipc_lock+ep "
              "<path of hiltwin>` (or rely on the rtprio/memlock limits above)");
}

ProbeCheck CheckCpuDmaLatency(const Machine& machine, const OsCalls& os) {
  const std::string id = "cpu_dma_latency";
  const std::string name = "/dev/cpu_dma_latency";
  if (!machine.options().try_privileges) return NotTried(id, name);
  int fd = -1;
  const int error = os.OpenCpuDmaLatency(0, fd);
  if (error == 0) {
    os.CloseFd(fd);
    return Make(id, name, "writable (runs can hold 0 us)", CheckStatus::kOk);
  }
  return Make(id, name, "refused: " + ErrnoText(error), CheckStatus::kWarn,
              error == ENOENT ? "kernel without PM QoS device; deep idle states stay allowed"
                              : "run as root or add a udev rule: KERNEL==\"cpu_dma_latency\", "
                                "GROUP=\"realtime\", MODE=\"0660\"");
}

std::vector<std::pair<int, std::filesystem::path>> CpuDirectories(const Machine& machine) {
  std::vector<std::pair<int, std::filesystem::path>> cpus;
  std::error_code error;
  std::filesystem::directory_iterator it(machine.Path("sys/devices/system/cpu"), error);
  if (error) return cpus;
  for (const auto& entry : it) {
    const std::string base = entry.path().filename().string();
    if (base.size() < 4 || base.compare(0, 3, "cpu") != 0) continue;
    if (const auto index = ParseInteger<int>(std::string_view(base).substr(3))) {
      cpus.emplace_back(*index, entry.path());
    }
  }
  std::sort(cpus.begin(), cpus.end());
  return cpus;
}

ProbeCheck CheckGovernor(const Machine& machine) {
  const std::string id = "governor";
  const std::string name = "CPU governor";
  std::map<std::string, int> counts;
  int cpus_with_governor = 0;
  for (const auto& [index, path] : CpuDirectories(machine)) {
    std::ifstream file(path / "cpufreq" / "scaling_governor");
    std::string governor;
    if (file && std::getline(file, governor)) {
      ++counts[Trim(governor)];
      ++cpus_with_governor;
    }
  }
  const std::string thesis_command =
      "`" + std::string(kGovernorCommand) +
      "` (and back to the default afterwards: the same with `echo schedutil`)";
  if (cpus_with_governor == 0) {
    return Make(id, name, "not exposed (no cpufreq driver)", CheckStatus::kWarn,
                "thesis §3.8.2 asks for the performance governor while measuring. In a VM the "
                "host sets the CPU frequency: set performance there. On bare metal load a "
                "cpufreq driver (intel_pstate, amd-pstate, acpi-cpufreq), then: " +
                    thesis_command);
  }
  std::string value;
  for (const auto& [governor, count] : counts) {
    if (!value.empty()) value += ", ";
    value += governor + " on " + std::to_string(count) + " CPU" + (count == 1 ? "" : "s");
  }
  if (counts.size() == 1 && counts.begin()->first == "performance") {
    return Make(id, name, value, CheckStatus::kOk);
  }
  return Make(id, name, value, CheckStatus::kWarn,
              "thesis §3.8.2 asks for the performance governor while measuring: " + thesis_command);
}

ProbeCheck CheckIsolation(const Machine& machine) {
  const std::string id = "isolated_cpus";
  const std::string name = "isolated CPUs";
  const auto isolated = machine.ReadTrimmed("sys/devices/system/cpu/isolated");
  const auto nohz = machine.ReadTrimmed("sys/devices/system/cpu/nohz_full");
  const std::string nohz_text =
      "nohz_full: " + (nohz ? (nohz->empty() || *nohz == "(null)" ? std::string("none") : *nohz)
                            : std::string("not built in"));
  const std::string advice =
      "reserve a CPU for the loop: boot with isolcpus=N nohz_full=N rcu_nocbs=N (e.g. the last "
      "CPU; " +
      AdviceFor(machine).boot_options + ") and run hiltwin pinned to N";
  if (!isolated)
    return Unknown(id, name, "no /sys/devices/system/cpu/isolated; " + nohz_text, advice);
  if (isolated->empty()) {
    return Make(id, name, "none; " + nohz_text, CheckStatus::kWarn, advice);
  }
  return Make(id, name, *isolated + "; " + nohz_text, CheckStatus::kOk,
              "pin the RT thread to one of them");
}

ProbeCheck CheckThrottling(const Machine& machine) {
  const std::string id = "rt_throttling";
  const std::string name = "RT throttling";
  const auto runtime = ParseInteger<long long>(
      machine.ReadTrimmed("proc/sys/kernel/sched_rt_runtime_us").value_or(""));
  const auto period = ParseInteger<long long>(
      machine.ReadTrimmed("proc/sys/kernel/sched_rt_period_us").value_or(""));
  if (!runtime) return Unknown(id, name, "/proc/sys/kernel/sched_rt_runtime_us unreadable");
  if (*runtime < 0) {
    return Make(id, name, "off (sched_rt_runtime_us = -1)", CheckStatus::kOk,
                "best for measurement, but a spinning SCHED_FIFO thread can now lock up its "
                "CPU; restore with `echo 950000 | sudo tee /proc/sys/kernel/sched_rt_runtime_us`");
  }
  std::string value = "sched_rt_runtime_us = " + std::to_string(*runtime);
  if (period && *period > 0) {
    value +=
        " of " + std::to_string(*period) + " (" + std::to_string(*runtime * 100 / *period) + " %)";
  }
  return Make(id, name, value, CheckStatus::kWarn,
              "RT threads are paused for the rest of each period once they use this share; for "
              "measurement: `echo -1 | sudo tee /proc/sys/kernel/sched_rt_runtime_us` (risk: a "
              "runaway SCHED_FIFO loop then locks up its CPU; restore 950000 afterwards)");
}

// "0-3,6" -> 5.
std::optional<int> CountCpuList(std::string_view list) {
  int count = 0;
  std::stringstream parts{std::string(list)};
  for (std::string part; std::getline(parts, part, ',');) {
    part = Trim(part);
    if (part.empty()) continue;
    const auto dash = part.find('-');
    const auto first = ParseInteger<int>(part.substr(0, dash));
    const auto last = dash == std::string::npos ? first : ParseInteger<int>(part.substr(dash + 1));
    if (!first || !last || *last < *first) return std::nullopt;
    count += *last - *first + 1;
  }
  return count;
}

ProbeCheck CheckSmtByTopology(const Machine& machine, const std::string& id,
                              const std::string& name) {
  const auto cpus = CpuDirectories(machine);
  if (cpus.empty()) return Unknown(id, name, "no /sys/devices/system/cpu/smt, no cpuN folders");
  for (const auto& [cpu, dir] : cpus) {
    const auto siblings = machine.ReadTrimmed("sys/devices/system/cpu/cpu" + std::to_string(cpu) +
                                              "/topology/thread_siblings_list");
    const auto count = siblings ? CountCpuList(*siblings) : std::nullopt;
    if (!count) return Unknown(id, name, "no SMT control and no readable CPU topology");
    if (*count > 1) {
      return Make(id, name,
                  "on (cpu" + std::to_string(cpu) + " shares its core: " + *siblings +
                      "; no SMT control in this kernel)",
                  CheckStatus::kWarn,
                  "a sibling hardware thread shares the loop's core: boot with nosmt, or keep "
                  "the sibling idle (isolate both)");
    }
  }
  return Make(id, name, "none (one thread per core)", CheckStatus::kOk);
}

ProbeCheck CheckSmt(const Machine& machine) {
  const std::string id = "smt";
  const std::string name = "SMT (hyper-threading)";
  const auto active = machine.ReadTrimmed("sys/devices/system/cpu/smt/active");
  const auto control = machine.ReadTrimmed("sys/devices/system/cpu/smt/control");
  const std::string control_text = control ? " (control: " + *control + ")" : "";
  // A kernel without SMT control (arm64: the Pi's cores run one thread each) has no smt/ folder;
  // the CPU topology still tells whether any core is shared.
  if (!active) return CheckSmtByTopology(machine, id, name);
  if (*active == "0") return Make(id, name, "off" + control_text, CheckStatus::kOk);
  return Make(id, name, "on" + control_text, CheckStatus::kWarn,
              "a sibling hyper-thread shares the loop's core: `echo off | sudo tee "
              "/sys/devices/system/cpu/smt/control` (or boot with nosmt), or keep the sibling "
              "idle (isolate both)");
}

ProbeCheck CheckClocksource(const Machine& machine) {
  const std::string id = "clocksource";
  const std::string name = "clocksource";
  const std::string base = "sys/devices/system/clocksource/clocksource0/";
  const auto current = machine.ReadTrimmed(base + "current_clocksource");
  const auto available = machine.ReadTrimmed(base + "available_clocksource");
  if (!current || current->empty()) return Unknown(id, name, "no current_clocksource");
  const bool tsc_available = available && HasWord(*available, "tsc");
  const std::string switch_advice =
      tsc_available ? "switch: `echo tsc | sudo tee /sys/devices/system/clocksource/clocksource0/"
                      "current_clocksource`"
                    : "tsc is not offered here (unstable or absent)";
  if (*current == "tsc" || *current == "arch_sys_counter") {
    return Make(id, name, *current, CheckStatus::kOk);
  }
  if (*current == "kvm-clock" || *current == "hyperv_clocksource_tsc_page" || *current == "xen") {
    return Make(id, name, *current + " (paravirtual)", CheckStatus::kWarn,
                "usable in a guest, reads cost a little more than tsc; " + switch_advice);
  }
  if (*current == "hpet" || *current == "acpi_pm" || *current == "jiffies" ||
      *current == "refined-jiffies") {
    return Make(id, name, *current + " (slow to read)", CheckStatus::kBad,
                "every clock read costs about a microsecond; " + switch_advice);
  }
  return Make(id, name, *current, CheckStatus::kWarn, switch_advice);
}

ProbeCheck CheckCpus(const Machine& machine) {
  const std::string id = "cpus_online";
  const std::string name = "CPUs online";
  const auto online = machine.ReadTrimmed("sys/devices/system/cpu/online");
  if (!online) return Unknown(id, name, "no /sys/devices/system/cpu/online");
  const auto count = CountCpuList(*online);
  if (!count) return Unknown(id, name, "unparsable list '" + *online + "'");
  const std::string value = *online + " (" + std::to_string(*count) + ")";
  if (*count >= 2) return Make(id, name, value, CheckStatus::kOk);
  return Make(id, name, value, CheckStatus::kWarn,
              "the loop shares its only CPU with everything else; use a machine with 2 or more");
}

ProbeCheck CheckVirtualisation(const Machine& machine) {
  const std::string id = "virtualisation";
  const std::string name = "virtualisation";
  std::vector<std::string> findings;
  bool vm = false;
  bool container = false;
  bool any_source = false;
  if (machine.real_root()) {
    if (const auto out = machine.RunTool({"systemd-detect-virt", "--vm"})) {
      any_source = true;
      const std::string kind = Trim(*out);
      if (!kind.empty() && kind != "none") {
        vm = true;
        findings.push_back("VM: " + kind);
      }
    }
    if (const auto out = machine.RunTool({"systemd-detect-virt", "--container"})) {
      const std::string kind = Trim(*out);
      if (!kind.empty() && kind != "none") {
        container = true;
        findings.push_back("container: " + kind);
      }
    }
  }
  if (const auto type = machine.ReadTrimmed("sys/hypervisor/type"); type && !type->empty()) {
    any_source = true;
    if (!vm) findings.push_back("VM: " + *type + " (/sys/hypervisor)");
    vm = true;
  }
  if (const auto cpuinfo = machine.Read("proc/cpuinfo")) {
    any_source = true;
    std::istringstream lines(*cpuinfo);
    for (std::string line; std::getline(lines, line);) {
      if (line.rfind("flags", 0) == 0 && HasWord(line, "hypervisor")) {
        if (!vm) findings.push_back("VM (hypervisor CPU flag)");
        vm = true;
        break;
      }
    }
  }
  if (!any_source) return Unknown(id, name, "no /proc/cpuinfo, no systemd-detect-virt");
  if (!vm && !container) return Make(id, name, "bare metal", CheckStatus::kOk);
  std::string value;
  for (const auto& finding : findings) value += (value.empty() ? "" : "; ") + finding;
  std::string advice;
  if (vm) {
    advice =
        "the hypervisor can stall this guest for milliseconds (see steal time), so timing "
        "here is not bare-metal timing: for trustworthy runs use bare metal, or dedicated, "
        "pinned vCPUs on an idle host";
  }
  if (container) {
    advice += std::string(advice.empty() ? "" : "; ") +
              "containers usually lack RT rights: --cap-add=SYS_NICE --cap-add=IPC_LOCK "
              "--ulimit rtprio=99 --ulimit memlock=-1";
  }
  return Make(id, name, value, CheckStatus::kWarn, advice);
}

std::string Percent(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f %%", value);
  return text;
}

}  // namespace

std::string_view ToString(CheckStatus status) noexcept {
  switch (status) {
    case CheckStatus::kOk:
      return "ok";
    case CheckStatus::kWarn:
      return "warn";
    case CheckStatus::kBad:
      return "bad";
  }
  return "unknown";
}

std::size_t ProbeReport::Count(CheckStatus status) const noexcept {
  return static_cast<std::size_t>(
      std::count_if(checks.begin(), checks.end(),
                    [&](const ProbeCheck& check) { return check.status == status; }));
}

const ProbeCheck* ProbeReport::Find(std::string_view id) const noexcept {
  for (const auto& check : checks) {
    if (check.id == id) return &check;
  }
  return nullptr;
}

std::optional<CpuTicks> ParseProcStat(std::string_view proc_stat) {
  std::istringstream lines{std::string(proc_stat)};
  for (std::string line; std::getline(lines, line);) {
    const auto words = Words(line);
    if (words.empty() || words[0] != "cpu") continue;
    // user nice system idle iowait irq softirq steal [guest guest_nice]; guest time is
    // already counted in user, so the total is the first eight.
    if (words.size() < 9) return std::nullopt;
    CpuTicks ticks;
    for (std::size_t column = 1; column <= 8; ++column) {
      const auto value = ParseInteger<std::uint64_t>(words[column]);
      if (!value) return std::nullopt;
      ticks.total += *value;
      if (column == 8) ticks.steal = *value;
    }
    return ticks;
  }
  return std::nullopt;
}

ProbeCheck AssessSteal(std::optional<CpuTicks> since_boot, std::optional<CpuTicks> window_start,
                       std::optional<CpuTicks> window_end, int window_ms) {
  const std::string id = "steal_time";
  const std::string name = "steal time";
  if (!since_boot) return Unknown(id, name, "/proc/stat unreadable");
  auto share = [](std::uint64_t steal, std::uint64_t total) {
    return total > 0 ? 100.0 * static_cast<double>(steal) / static_cast<double>(total) : 0.0;
  };
  const double boot_pct = share(since_boot->steal, since_boot->total);
  std::string value = Percent(boot_pct) + " since boot";
  double window_pct = 0.0;
  std::uint64_t window_steal = 0;
  if (window_start && window_end && window_end->total >= window_start->total &&
      window_end->steal >= window_start->steal) {
    window_steal = window_end->steal - window_start->steal;
    window_pct = share(window_steal, window_end->total - window_start->total);
    value += ", " + Percent(window_pct) + " over " + std::to_string(window_ms) + " ms";
  }
  const std::string advice =
      "the hypervisor gave this guest's CPU time to others: wake-ups can be late by a host "
      "time slice, causing deadline misses that are not hiltwin's; ask for dedicated vCPUs";
  if (boot_pct >= 5.0 || window_pct >= 5.0) {
    return Make(id, name, value, CheckStatus::kBad, advice);
  }
  if (since_boot->steal > 0 || window_steal > 0) {
    return Make(id, name, value, CheckStatus::kWarn, advice);
  }
  return Make(id, name, value, CheckStatus::kOk);
}

ProbeReport RunRtProbe(const ProbeOptions& options, const OsCalls& os) {
  const Machine machine(options);
  const auto window_start_time = std::chrono::steady_clock::now();
  const auto steal_start = ParseProcStat(machine.Read("proc/stat").value_or(""));
  const auto caps = ParseCapabilities(machine.Read("proc/self/status"));

  ProbeReport report;
  report.checks.push_back(CheckPreemption(machine));
  report.checks.push_back(CheckSchedFifo(machine, os));
  report.checks.push_back(CheckMlockall(machine, os));
  report.checks.push_back(CheckRtprio(machine, caps));
  report.checks.push_back(CheckMemlock(machine, caps));
  report.checks.push_back(CheckCapabilities(caps));
  report.checks.push_back(CheckCpuDmaLatency(machine, os));
  report.checks.push_back(CheckGovernor(machine));
  report.checks.push_back(CheckIsolation(machine));
  report.checks.push_back(CheckThrottling(machine));
  report.checks.push_back(CheckSmt(machine));
  report.checks.push_back(CheckClocksource(machine));
  report.checks.push_back(CheckCpus(machine));
  report.checks.push_back(CheckVirtualisation(machine));

  // The other checks took part of the window already; sleep only for what is left.
  std::optional<CpuTicks> steal_end;
  if (options.steal_sample_ms > 0 && steal_start) {
    std::this_thread::sleep_until(window_start_time +
                                  std::chrono::milliseconds(options.steal_sample_ms));
    steal_end = ParseProcStat(machine.Read("proc/stat").value_or(""));
  }
  const auto window_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                             std::chrono::steady_clock::now() - window_start_time)
                             .count();
  report.checks.push_back(
      AssessSteal(steal_start, steal_start, steal_end, static_cast<int>(window_ms)));
  return report;
}

KernelPreemption FindKernelPreemption(const ProbeOptions& options) {
  const Machine machine(options);
  const PreemptionFacts facts = ReadPreemption(machine);
  if (!facts.rt_source.empty()) return {"PREEMPT_RT", facts.rt_source};
  const std::string dynamic = facts.dynamic ? "PREEMPT_DYNAMIC, " : "";
  if (facts.found.mode.empty()) {
    return {"unknown", facts.nothing_to_read
                           ? "no uname -v, no kernel config"
                           : dynamic + "debugfs not mounted, no preempt= boot option, no kernel "
                                       "config"};
  }
  return {ConfigName(facts.found.mode), dynamic + facts.found.source};
}

}  // namespace hiltwin::kernel_glue
