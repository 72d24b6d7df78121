#include "fakes/test_paths.h"

#include <filesystem>
#include <map>
#include <mutex>
#include <string>

namespace hiltwin::test {

const char* BesideTest(const char* relative) {
  static std::mutex mutex;
  static std::map<std::string, std::string> resolved;  // nodes never move: c_str() stays valid
  const std::scoped_lock lock(mutex);
  auto [it, inserted] = resolved.try_emplace(relative);
  if (inserted) {
    // qemu-user answers /proc/self/exe with the emulated program's path, so this holds under
    // the arm64 stage's emulator too.
    const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe");
    it->second = (program.parent_path() / relative).lexically_normal().string();
  }
  return it->second.c_str();
}

}  // namespace hiltwin::test
