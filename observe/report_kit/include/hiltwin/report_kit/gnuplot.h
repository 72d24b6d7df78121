#pragma once
/// What every gnuplot picture needs (a scratch directory for its data, quoting, running gnuplot
/// as a child with a timeout, checking that the PNG appeared). Shared by `assess --plot`
/// (observe/assess) and the jitter pictures (observe/jitter).

#include <filesystem>
#include <stdexcept>
#include <string>

namespace hiltwin::analysis {

/// gnuplot could not start or did not produce the picture (bad path, no space, ...); carries
/// its output. Messages name the PNG path and gnuplot; the caller adds its flag.
class PlotError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace hiltwin::analysis

namespace hiltwin::analysis::detail {

/// gnuplot single-quoted string: a quote is written twice.
[[nodiscard]] std::string GnuplotQuote(const std::string& s);

/// A fresh directory under $TMPDIR (or /tmp), removed with everything in it on destruction.
class ScratchDir {
 public:
  /// `prefix` names it, e.g. "hiltwin-assess" (mkdtemp adds six characters). Throws PlotError.
  explicit ScratchDir(const std::string& prefix);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const noexcept { return path_; }

 private:
  std::filesystem::path path_;
};

/// Removes an old `png_path`, runs gnuplot on `script` and checks that it wrote `png_path`.
/// Throws InputError when gnuplot is not installed (naming gnuplot-nox), PlotError when it
/// fails (with its output).
void RenderWithGnuplot(const std::filesystem::path& script, const std::string& png_path);

}  // namespace hiltwin::analysis::detail
