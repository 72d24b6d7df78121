#pragma once
// A test's own wire and scratch folder for the two-process tests (twin and controller on a
// wire): both are named after this process and the running test, so tests that ctest runs in
// parallel never share a shared-memory segment or a file.

#include <filesystem>
#include <string>

namespace hiltwin::test {

class WireScratch {
 public:
  /// Names the wire `prefix`-PID-TEST (the test's name cut to 24 characters, which keeps the
  /// wire name within the 64 the wire allows) and creates the folder. Construct it while a
  /// test runs: a fixture member does.
  explicit WireScratch(const std::string& prefix);
  /// Removes the folder and a segment a faulted side may have left behind.
  ~WireScratch();
  WireScratch(const WireScratch&) = delete;
  WireScratch& operator=(const WireScratch&) = delete;

  /// A file in this test's folder.
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  /// The wire's bare name (`hiltwin hil --wire NAME`, the vandal's argument).
  const std::string& WireName() const { return wire_; }
  /// The I/O spec both sides take (`--io wire:NAME`).
  std::string Wire() const { return "wire:" + wire_; }
  /// Where the kernel keeps the wire's segment while it exists.
  std::string SegmentPath() const { return "/dev/shm/hiltwin-wire-" + wire_; }

 private:
  std::string wire_;
  std::filesystem::path dir_;
};

}  // namespace hiltwin::test
