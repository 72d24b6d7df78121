#pragma once
// Helpers shared by the fuzz targets: input as text, input as a file for readers that take a
// path, and a stop for exceptions no parser documents.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <string_view>

namespace hiltwin::fuzz {

inline std::string_view AsText(const std::uint8_t* data, std::size_t size) noexcept {
  return {reinterpret_cast<const char*>(data), size};
}

/// A private folder for this process's scratch files (readers that only take a path), removed
/// at exit. Under TMPDIR (or /tmp), named by pid so parallel fuzzers never share one.
inline const std::filesystem::path& ScratchDir() {
  static const std::filesystem::path dir = [] {
    const char* tmp = std::getenv("TMPDIR");  // NOLINT(concurrency-mt-unsafe): one thread
    std::filesystem::path path = (tmp != nullptr && *tmp != '\0') ? tmp : "/tmp";
    path /= "hiltwin-fuzz-" + std::to_string(::getpid());
    std::filesystem::create_directories(path);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(ScratchDir(), ignored);
    });
    return path;
  }();
  return dir;
}

/// Writes the input to ScratchDir()/name and returns the path.
inline std::filesystem::path WriteScratch(const char* name, const std::uint8_t* data,
                                          std::size_t size) {
  std::filesystem::path path = ScratchDir() / name;
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, file) != size) std::abort();
  std::fclose(file);
  return path;
}

/// An exception the API under test does not document: report it as a finding (abort makes
/// libFuzzer save the input as a crash).
[[noreturn]] inline void Undocumented(const char* api, const std::exception* e) noexcept {
  std::fprintf(stderr, "FINDING: %s threw an undocumented exception: %s\n", api,
               e != nullptr ? e->what() : "(not a std::exception)");
  std::abort();
}

}  // namespace hiltwin::fuzz

/// try { ... } HILTWIN_FUZZ_UNDOCUMENTED("Api") after the documented catch clauses.
#define HILTWIN_FUZZ_UNDOCUMENTED(api)                                     \
  catch (const std::exception& undocumented) {                             \
    ::hiltwin::fuzz::Undocumented(api, &undocumented);                     \
  }                                                                        \
  catch (...) {                                                            \
    ::hiltwin::fuzz::Undocumented(api, nullptr);                           \
  }
