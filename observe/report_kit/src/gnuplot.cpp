#include "hiltwin/report_kit/gnuplot.h"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>

#include "hiltwin/kernel_glue/process.h"
#include "hiltwin/tracing/csv.h"

namespace hiltwin::analysis::detail {
namespace {

// gnuplot renders in a few seconds even at tens of thousands of rows; a stuck one must not hang.
constexpr std::chrono::seconds kGnuplotTimeout{120};

// Runs gnuplot on `script`, its stdout and stderr together (its messages, for the error).
kernel_glue::ProcessResult RunGnuplot(const std::filesystem::path& script) {
  kernel_glue::ProcessOptions streams;
  streams.out = kernel_glue::OutputTarget::Capture();
  streams.err = kernel_glue::OutputTarget::SameAsStdout();
  try {
    return kernel_glue::RunProcess({"gnuplot", script.string()}, streams, kGnuplotTimeout);
  } catch (const kernel_glue::SpawnError& e) {
    if (e.NotFound()) {
      throw InputError("gnuplot is not installed (not found on PATH): install the Debian "
                       "package gnuplot-nox (apt-get install gnuplot-nox)");
    }
    throw PlotError(e.what());
  }
}

}  // namespace

std::string GnuplotQuote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) {
    out += c;
    if (c == '\'') out += '\'';
  }
  out += "'";
  return out;
}

ScratchDir::ScratchDir(const std::string& prefix) {
  const char* base = std::getenv("TMPDIR");  // NOLINT(concurrency-mt-unsafe): not on a loop thread
  std::string pattern = std::string(base != nullptr && *base != '\0' ? base : "/tmp") + "/" +
                        prefix + "-XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr) {
    throw PlotError("cannot create a temporary directory for gnuplot's data (" +
                    std::string(std::strerror(errno)) +  // NOLINT(concurrency-mt-unsafe)
                    "); set TMPDIR to a writable directory");
  }
  path_ = pattern;
}

ScratchDir::~ScratchDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

void RenderWithGnuplot(const std::filesystem::path& script, const std::string& png_path) {
  std::error_code ec;
  std::filesystem::remove(png_path, ec);  // so an old picture cannot pass for a new one
  const kernel_glue::ProcessResult gnuplot = RunGnuplot(script);
  const bool written =
      std::filesystem::exists(png_path, ec) && std::filesystem::file_size(png_path, ec) > 0;
  if (!gnuplot.status.Success() || !written) {
    throw PlotError("cannot write " + png_path + ": gnuplot " +
                    (gnuplot.status.Success() ? "wrote no picture" : gnuplot.status.Describe()) +
                    ": " + gnuplot.out + "check that the directory exists and is writable");
  }
}

}  // namespace hiltwin::analysis::detail
