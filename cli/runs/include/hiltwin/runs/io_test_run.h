#pragma once
/// `hiltwin io-test`'s run: open the board(s), INIT and the identity check, the exchange loops
/// (two boards in this process over mock; this side's driver over a wire or a real link), the
/// counting, the text or JSON summary and the exit code. The command
/// (cli/commands/cmd_io_test.cpp) parses its flags, once, into IoTestOptions.

#include <cstdint>
#include <optional>
#include <string>

#include "hiltwin/io/backend.h"
#include "hiltwin/io/board_pair_check.h"

namespace hiltwin::app {

/// io-test's typed configuration: the flags read once (the command's IoTestOptionsFrom).
struct IoTestOptions {
  io::BackendSpec io;
  std::string io_text = "mock";  ///< --io as given: for messages and the summary
  io::Image image = io::Image::kIcoboardInverse;  ///< the image this side's driver needs
  std::optional<io::Image> board_image;  ///< mock: the image its board carries (default: image)
  std::int64_t frames = 1000;
  double rate_hz = 1000.0;
  double wait_peer_s = 0.0;
  std::optional<io::LinkFault> fault;  ///< --inject-fault (mock only)
  std::string fault_text;              ///< --inject-fault as given, for the failure's message
  bool json = false;
};

/// Runs the bring-up test and prints its summary (text, or JSON with `json`); returns 0 when the
/// test passed. Throws CommandError: exit 5 on an I/O error, the wrong image, a lost message or
/// (wire) no peer; 2 when the backend refuses its configuration.
int RunIoTest(const IoTestOptions& options);

}  // namespace hiltwin::app
