#pragma once
/// Reading a text file line by line through one buffer whose size is bounded by the longest
/// line the caller accepts: a file without line breaks (or /dev/zero) costs one line's cap of
/// memory and is refused there, instead of being read whole. The CSV reader (csv.h) and the
/// timing-log reader (traces) read through it; each says what its cap is and words its errors.

#include <cstddef>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace hiltwin::tracing {

class LineReader {
 public:
  /// What Next found.
  enum class Status {
    kLine,     ///< a line of at most the cap
    kEnd,      ///< nothing more in the file
    kTooLong,  ///< the line numbered line_number() goes on past the cap (its text is not given)
  };

  /// Opens `path` for reading; lines may hold up to `max_line_bytes` bytes (without the '\n'
  /// and a '\r' before it). Throws std::system_error (the errno of fopen) when it cannot.
  LineReader(const std::string& path, std::size_t max_line_bytes);

  /// The next line, without its '\n' (nor a '\r' before it). `terminated` is false for a last
  /// line the file ends inside of. After kTooLong the reader is spent. Throws
  /// std::system_error (the errno of fread) when the file cannot be read.
  Status Next(std::string_view& line, bool& terminated);
  Status Next(std::string_view& line) {
    bool terminated = false;
    return Next(line, terminated);
  }

  /// Whether nothing follows the last line returned.
  [[nodiscard]] bool AtEnd();
  /// 1-based number of the line Next returned (or found too long) last; 0 before the first.
  [[nodiscard]] std::size_t line_number() const noexcept { return line_number_; }

 private:
  bool Fill();

  struct FileClose {
    void operator()(std::FILE* file) const noexcept { std::fclose(file); }
  };
  std::unique_ptr<std::FILE, FileClose> file_;
  std::size_t max_line_bytes_;
  std::vector<char> buffer_;
  std::size_t begin_ = 0;
  std::size_t end_ = 0;
  bool eof_ = false;
  std::size_t line_number_ = 0;
};

}  // namespace hiltwin::tracing
