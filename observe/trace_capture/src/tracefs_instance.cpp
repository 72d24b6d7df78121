// The kernel recorder's tracefs instance: created, configured, emptied of its losses, removed.
#include "tracefs_instance.h"

#include <spdlog/spdlog.h>

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>

#include "hiltwin/kernel_glue/os_calls.h"
#include "hiltwin/trace_capture/capture_error.h"
#include "kernel_event_decoder.h"

namespace hiltwin::trace_capture {
namespace {

std::string JoinCpus(const std::vector<int>& cpus) {
  std::string list;
  for (int cpu : cpus) list += (list.empty() ? "" : ",") + std::to_string(cpu);
  return list;
}

// The stats lines that count events this CPU's buffer lost: "overrun" (overwritten before
// they were read: the collector fell behind), "commit overrun" (nested writers filled a
// page) and "dropped events" (lost when the buffer does not overwrite).
std::uint64_t LostInStats(const std::string& stats) {
  std::uint64_t lost = 0;
  std::istringstream lines(stats);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon);
    if (key != "overrun" && key != "commit overrun" && key != "dropped events") continue;
    std::uint64_t count = 0;
    std::size_t start = line.find_first_not_of(' ', colon + 1);
    if (start == std::string::npos) continue;
    std::from_chars(line.data() + start, line.data() + line.size(), count);
    lost += count;
  }
  return lost;
}

}  // namespace

std::vector<int> ParseCpuList(const std::string& text) {
  std::vector<int> cpus;
  std::istringstream items(text);
  for (std::string item; std::getline(items, item, ',');) {
    while (!item.empty() && (item.back() == '\n' || item.back() == ' ')) item.pop_back();
    if (item.empty()) continue;
    int first = 0;
    int last = 0;
    const char* end = item.data() + item.size();
    auto result = std::from_chars(item.data(), end, first);
    last = first;
    if (result.ec == std::errc() && result.ptr != end && *result.ptr == '-') {
      result = std::from_chars(result.ptr + 1, end, last);
    }
    if (result.ec != std::errc() || result.ptr != end || last < first) {
      throw CaptureError("bad CPU list '" + text + "'");
    }
    for (int cpu = first; cpu <= last; ++cpu) cpus.push_back(cpu);
  }
  return cpus;
}

std::vector<int> OnlineCpus() {
  std::ifstream in("/sys/devices/system/cpu/online");
  std::string text;
  std::getline(in, text);
  return ParseCpuList(text);
}

TracefsInstance::TracefsInstance(const std::string& name) : name_(name) {
  if (tracefs_instance_exists(name.c_str())) {
    throw CaptureError("the tracefs instance " + name + " exists already (another kernel " +
                       "recording of this process, or one left by a crashed process with this " +
                       "pid: remove it with `rmdir " + std::string(tracefs_tracing_dir()) +
                       "/instances/" + name + "`)");
  }
  instance_ = tracefs_instance_create(name.c_str());
  if (instance_ == nullptr) {
    throw CaptureError("cannot create the tracefs instance " + name + " (" +
                       kernel_glue::ErrnoText(errno) + "): run as root");
  }
}

TracefsInstance::~TracefsInstance() { Destroy(); }

void TracefsInstance::Write(const std::string& file, const std::string& value) const {
  if (tracefs_instance_file_write(instance_, file.c_str(), value.c_str()) < 0) {
    throw CaptureError("tracefs: writing '" + value + "' to instances/" + name_ + "/" + file +
                       " failed (" + kernel_glue::ErrnoText(errno) + ")");
  }
}

void TracefsInstance::SetRecording(bool on) {
  if ((on ? tracefs_trace_on(instance_) : tracefs_trace_off(instance_)) != 0) {
    throw CaptureError("tracefs: cannot turn recording " + std::string(on ? "on" : "off") +
                       " in instance " + name_ + " (" + kernel_glue::ErrnoText(errno) + ")");
  }
}

void TracefsInstance::Configure(const std::vector<int>& cpus, int buffer_kb) {
  SetRecording(false);  // a new instance records at once; nothing until it is set up
  // CLOCK_MONOTONIC, the loop's own clock, so kernel and loop times compare directly.
  Write("trace_clock", "mono");
  // It returns the bytes written to tracing_cpumask (its manual says 0), so only < 0 fails.
  if (tracefs_instance_set_affinity(instance_, JoinCpus(cpus).c_str()) < 0) {
    throw CaptureError("tracefs: cannot record CPUs " + JoinCpus(cpus) + " (" +
                       kernel_glue::ErrnoText(errno) + ")");
  }
  for (int cpu : cpus) {
    if (tracefs_instance_set_buffer_size(instance_, static_cast<std::size_t>(buffer_kb), cpu) !=
        0) {
      throw CaptureError("tracefs: cannot size CPU " + std::to_string(cpu) + "'s buffer to " +
                         std::to_string(buffer_kb) + " KiB (" + kernel_glue::ErrnoText(errno) +
                         ")");
    }
  }
}

void TracefsInstance::EnableEvents() {
  int enabled = 0;
  for (const KernelEventSource& source : KernelEventSources()) {
    if (!tracefs_event_file_exists(instance_, source.system, source.name, "enable")) {
      spdlog::warn("this kernel has no {}:{} event: recording without it", source.system,
                   source.name);
    } else if (tracefs_event_enable(instance_, source.system, source.name) != 0) {
      spdlog::warn("cannot enable {}:{} ({}): recording without it", source.system, source.name,
                   kernel_glue::ErrnoText(errno));
    } else {
      ++enabled;
    }
  }
  if (enabled == 0) throw CaptureError("tracefs: none of the scheduler events could be enabled");
}

std::uint64_t TracefsInstance::LostEvents(const std::vector<int>& cpus) const {
  std::uint64_t lost = 0;
  for (int cpu : cpus) {
    const std::string file = "per_cpu/cpu" + std::to_string(cpu) + "/stats";
    const std::unique_ptr<char, decltype(&std::free)> text(
        tracefs_instance_file_read(instance_, file.c_str(), nullptr), &std::free);
    if (text) lost += LostInStats(text.get());
  }
  return lost;
}

void TracefsInstance::Destroy() noexcept {
  if (instance_ == nullptr) return;
  tracefs_trace_off(instance_);
  if (tracefs_instance_destroy(instance_) != 0) {
    const int error = errno;
    try {
      spdlog::warn("cannot remove the tracefs instance {} ({}): remove it with `rmdir {}`", name_,
                   kernel_glue::ErrnoText(error),
                   std::string(tracefs_tracing_dir()) + "/instances/" + name_);
    } catch (...) {  // a warning that cannot be built is not worth a terminate()
    }
  }
  tracefs_instance_free(instance_);
  instance_ = nullptr;
}

}  // namespace hiltwin::trace_capture
