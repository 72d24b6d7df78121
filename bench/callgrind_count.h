#pragma once
// Instructions beside seconds: callgrind counts what a thread executes whatever the machine's
// load (this VM has no hardware counters for perf). A benchmark brackets the work it measures
// with ToggleCounting() (callgrind's client request: it acts on the calling thread only, and
// natively it is a handful of no-op instructions), reruns itself under
// `valgrind --tool=callgrind --collect-atstart=no` with two item counts, and divides the
// difference of the counts by the difference of the items, so whatever the bracket holds
// besides the items (set-up, a first call's lazy initialisation) cancels.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "hiltwin/kernel_glue/process.h"

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define HILTWIN_BENCH_HAS_CALLGRIND 1
#endif

namespace hiltwin::bench {

/// Starts (or stops) callgrind's counting on the calling thread; nothing outside valgrind.
inline void ToggleCounting() noexcept {
#if defined(HILTWIN_BENCH_HAS_CALLGRIND)
  CALLGRIND_TOGGLE_COLLECT;
#endif
}

namespace detail {

/// The words after `key` on the first line that starts with it, e.g. "events: Ir Dr".
inline std::optional<std::vector<std::string>> WordsAfter(std::string_view text,
                                                          std::string_view key) {
  std::istringstream lines{std::string(text)};
  for (std::string line; std::getline(lines, line);) {
    if (line.compare(0, key.size(), key) != 0) continue;
    std::istringstream words(line.substr(key.size()));
    std::vector<std::string> out;
    for (std::string word; words >> word;) out.push_back(word);
    return out;
  }
  return std::nullopt;
}

}  // namespace detail

/// The instructions (`Ir`) a callgrind output file counts: the `Ir` column (its place on the
/// `events:` line) of the `totals:` line, or of `summary:` when there is no `totals:`. Nothing
/// when the file has neither, no `Ir` event, or the column is not a whole number.
inline std::optional<std::uint64_t> CallgrindInstructions(std::string_view text) {
  const auto events = detail::WordsAfter(text, "events:");
  if (!events) return std::nullopt;
  std::size_t column = 0;
  while (column < events->size() && (*events)[column] != "Ir") ++column;
  if (column == events->size()) return std::nullopt;
  auto totals = detail::WordsAfter(text, "totals:");
  if (!totals) totals = detail::WordsAfter(text, "summary:");
  if (!totals || column >= totals->size()) return std::nullopt;
  const std::string& figure = (*totals)[column];
  if (figure.empty() || figure.find_first_not_of("0123456789") != std::string::npos ||
      figure.size() > 19) {
    return std::nullopt;
  }
  return std::stoull(figure);
}

/// Instructions per item from two bracketed runs of items1 and items2 items (items2 > items1):
/// what the bracket holds besides the items cancels.
inline double InstructionsPerItem(std::uint64_t items1, std::uint64_t count1,
                                  std::uint64_t items2, std::uint64_t count2) {
  if (items2 <= items1) throw std::invalid_argument("InstructionsPerItem: items2 <= items1");
  return (static_cast<double>(count2) - static_cast<double>(count1)) /
         static_cast<double>(items2 - items1);
}

/// Runs `argv` under callgrind, counting only between the child's ToggleCounting() calls, and
/// returns what it counted. Throws std::runtime_error saying what to do when valgrind or its
/// headers are missing, the child fails, or it counted nothing (no bracket was reached).
inline std::uint64_t CountInstructions(const std::vector<std::string>& argv) {
#if !defined(HILTWIN_BENCH_HAS_CALLGRIND)
  throw std::runtime_error(
      "instruction counts need valgrind's headers at build time: apt-get install valgrind, "
      "then rebuild the benchmark");
#endif
  const std::filesystem::path out = std::filesystem::temp_directory_path() /
                                    ("hiltwin_bench_callgrind_" + std::to_string(::getpid()));
  std::vector<std::string> command = {"valgrind", "--tool=callgrind", "--collect-atstart=no",
                                      "--callgrind-out-file=" + out.string()};
  command.insert(command.end(), argv.begin(), argv.end());
  kernel_glue::ProcessResult result;
  try {
    result = kernel_glue::RunProcess(command, {.out = kernel_glue::OutputTarget::Discard(),
                                               .err = kernel_glue::OutputTarget::Capture()});
  } catch (const kernel_glue::SpawnError& e) {
    throw std::runtime_error(e.NotFound() ? "valgrind not found: apt-get install valgrind"
                                          : std::string("cannot start valgrind: ") + e.what());
  }
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  std::filesystem::remove(out);
  if (!result.status.Success()) {
    throw std::runtime_error("callgrind run of " + argv.front() + " ended with " +
                             result.status.Describe() + ":\n" + result.err);
  }
  const std::optional<std::uint64_t> counted = CallgrindInstructions(text.str());
  if (!counted || *counted == 0) {
    throw std::runtime_error("callgrind counted nothing for " + argv.front() +
                             " (no ToggleCounting() bracket ran)");
  }
  return *counted;
}

}  // namespace hiltwin::bench
