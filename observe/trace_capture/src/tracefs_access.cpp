// Access to tracefs: found in /proc/mounts (mounted when allowed), then judged writable.
#include "hiltwin/trace_capture/tracefs_access.h"

#include <spdlog/spdlog.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <sstream>

#include "hiltwin/kernel_glue/os_calls.h"

namespace hiltwin::trace_capture {
namespace {

constexpr const char* kDefaultMountPoint = "/sys/kernel/tracing";
constexpr const char* kMountCommand = "`mount -t tracefs nodev /sys/kernel/tracing`";

// The first tracefs mount, preferring the standard place (the old /sys/kernel/debug/tracing
// automount shows up as tracefs too). Empty when there is none.
std::string FindTracefs() {
  std::ifstream mounts("/proc/mounts");
  std::string found;
  for (std::string line; std::getline(mounts, line);) {
    std::istringstream fields(line);
    std::string device;
    std::string mount_point;
    std::string type;
    fields >> device >> mount_point >> type;
    if (type != "tracefs") continue;
    if (mount_point == kDefaultMountPoint) return mount_point;
    if (found.empty()) found = mount_point;
  }
  return found;
}

}  // namespace

TracefsAccessFacts ProbeTracefs(bool may_mount) {
  TracefsAccessFacts facts;
  facts.may_mount = may_mount;
  const std::string mount_point = FindTracefs();
  if (!mount_point.empty()) {
    facts.mount_point = mount_point;
    facts.mounted = true;
  } else if (may_mount) {
    facts.mount_attempted = true;
    if (::mount("nodev", kDefaultMountPoint, "tracefs", 0, nullptr) == 0) {
      facts.mounted = true;
      spdlog::info("mounted tracefs at {} (it was not mounted)", kDefaultMountPoint);
    } else {
      facts.mount_errno = errno;
    }
  }
  if (facts.mounted) {
    const std::string instances = facts.mount_point + "/instances";
    facts.writable = ::access(instances.c_str(), W_OK) == 0;
    facts.access_errno = facts.writable ? 0 : errno;
  }
  return facts;
}

std::string ExplainTracefsAccess(const TracefsAccessFacts& facts) {
  if (!facts.mounted && !facts.may_mount) {
    return std::string(
               "tracefs is not mounted and mounting it was not allowed: mount it as "
               "root with ") +
           kMountCommand + ", then record again";
  }
  if (!facts.mounted) {
    return "tracefs is not mounted, and mounting it at " + facts.mount_point + " failed (" +
           kernel_glue::ErrnoText(facts.mount_errno) + "): run hiltwin as root, or have root run " +
           kMountCommand;
  }
  if (!facts.writable) {
    return "tracefs at " + facts.mount_point + " is not writable by this user (" +
           facts.mount_point + "/instances: " + kernel_glue::ErrnoText(facts.access_errno) +
           "): recording the kernel's events needs root: run `hiltwin trace --kernel` as root, "
           "or trace without --kernel";
  }
  return {};
}

}  // namespace hiltwin::trace_capture
