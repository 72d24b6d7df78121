#include "hiltwin/tracing/line_reader.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <system_error>

namespace hiltwin::tracing {
namespace {

/// Bytes read at once: large reads make a long file one linear pass.
constexpr std::size_t kChunkBytes = std::size_t{1} << 20;

}  // namespace

LineReader::LineReader(const std::string& path, std::size_t max_line_bytes)
    : max_line_bytes_(max_line_bytes),
      // A longest line with its "\r\n" fits, so the buffer never grows.
      buffer_(std::max(kChunkBytes, max_line_bytes + 2)) {
  file_.reset(std::fopen(path.c_str(), "rbe"));
  if (!file_) throw std::system_error(errno, std::generic_category(), "fopen");
}

LineReader::Status LineReader::Next(std::string_view& line, bool& terminated) {
  for (;;) {
    const char* first = buffer_.data() + begin_;
    const std::size_t pending = end_ - begin_;
    const void* newline = std::memchr(first, '\n', pending);
    if (newline != nullptr) {
      line = std::string_view(first, static_cast<std::size_t>(static_cast<const char*>(newline) -
                                                              first));
      begin_ += line.size() + 1;
      terminated = true;
      break;
    }
    // Past the cap plus a '\r' no line break can save the line: stop reading it.
    if (pending > max_line_bytes_ + 1) {
      ++line_number_;
      return Status::kTooLong;
    }
    if (!Fill()) {
      if (pending == 0) return Status::kEnd;
      line = std::string_view(first, pending);
      begin_ = end_;
      terminated = false;
      break;
    }
  }
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  ++line_number_;
  return line.size() > max_line_bytes_ ? Status::kTooLong : Status::kLine;
}

bool LineReader::AtEnd() { return begin_ == end_ && !Fill(); }

bool LineReader::Fill() {
  if (eof_) return false;
  if (begin_ > 0) {
    std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  const std::size_t got = std::fread(buffer_.data() + end_, 1, buffer_.size() - end_, file_.get());
  if (got == 0) {
    if (std::ferror(file_.get()) != 0) {
      throw std::system_error(errno, std::generic_category(), "fread");
    }
    eof_ = true;
    return false;
  }
  end_ += got;
  return true;
}

}  // namespace hiltwin::tracing
