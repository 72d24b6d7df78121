// `hiltwin io-test`: bring-up test of the FPGA link. INIT, identity check, N data frames with a
// known pattern (and a TEST loop-back after every third), then a summary; exit 0 only without
// errors, 5 on an I/O error, the wrong image, an end-to-end message lost or (wire) no peer.
//
// Over mock, both boards run in this process (io::BoardPairCheck): the twin's driver and board,
// the ECS's driver and board, joined by the encoder lines and the PWM wire. The ECS decodes the
// twin's encoder pattern edge by edge and the twin reads the ECS's PWM pattern; messages are
// counted sent/received/missed end to end as thesis Table 5.2 counts them, so
// `--io mock --frames 720000` repeats that test. Mock boards have no clock (board time is data
// frames × step), so a mock run is not paced by the wall clock.
//
// Over a wire or a real link the other side is expected to run io-test too: its pattern is
// checked by relations that hold whatever its frame index is.
// Flags -> IoTestOptions (typed, read once) -> RunIoTest (hiltwin/runs/io_test_run.h).
#include <algorithm>
#include <array>
#include <cstdint>
#include <exception>
#include <memory>
#include <string>
#include <utility>

#include "commands.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/runs/io_test_run.h"

namespace hiltwin::app {
namespace {

/// io-test's flags as the command line gave them.
struct IoTestFlags {
  std::string io = "mock";
  std::string image = "icoboard_inverse";
  std::string board_image;
  std::int64_t frames = 1000;
  double rate_hz = 1000.0;
  double wait_peer_s = 0.0;
  std::string inject_fault;
  bool json = false;
};

/// --io, and the flags checked against its kind (exit 2 for usage).
io::BackendSpec IoTestBackendOf(const IoTestFlags& f) {
  io::BackendSpec spec;
  try {
    spec = io::ParseBackendSpec(f.io);
  } catch (const io::ConfigError& e) {
    throw CommandError(ExitCode::kUsage, std::string("--io: ") + e.what());
  }
  const bool mock = spec.kind == io::BackendSpec::Kind::kMock;
  if (!f.board_image.empty() && !mock) {
    const bool rtl = spec.kind == io::BackendSpec::Kind::kVerilated;
    throw CommandError(ExitCode::kUsage,
                       "--board-image " + f.board_image + " only applies to --io mock; " +
                           (rtl ? "the RTL board's image is chosen with --io verilated:IMAGE "
                                  "(icoboard or icoboard_inverse)"
                                : "a wired or real board carries its own image (drop "
                                  "--board-image)"));
  }
  if (f.wait_peer_s > 0.0 && spec.kind != io::BackendSpec::Kind::kWire) {
    throw CommandError(ExitCode::kUsage,
                       "--wait-peer only applies to --io wire:NAME; a mock board has no peer and a "
                       "real board's peer cannot be seen from here (drop --wait-peer)");
  }
  if (!f.inject_fault.empty() && !mock) {
    throw CommandError(
        ExitCode::kUsage,
        "--inject-fault only applies to --io mock, whose boards run in this process; "
        "a wired or real board cannot be made to fail from here (drop --inject-fault)");
  }
  return spec;
}

constexpr const char* kFaultForms =
    "KIND[,at=FRAME][,count=N] with KIND stuck-emulator, stuck-reader or corrupt-counts, e.g. "
    "stuck-emulator,at=1000,count=5";

[[noreturn]] void BadFault(const std::string& spec, const std::string& problem) {
  throw CommandError(ExitCode::kUsage,
                     "--inject-fault " + spec + ": " + problem + "; accepted form: " + kFaultForms);
}

std::int64_t ParseFaultNumber(const std::string& spec, const std::string& key,
                              const std::string& value, std::int64_t min) {
  std::size_t used = 0;
  std::int64_t number = -1;
  try {
    number = std::stoll(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != value.size() || value.empty() || number < min) {
    BadFault(spec, key + "=" + value + " is not a whole number >= " + std::to_string(min));
  }
  return number;
}

io::LinkFault::Kind ParseFaultKind(const std::string& spec, const std::string& kind) {
  using Kind = io::LinkFault::Kind;
  static constexpr std::array<std::pair<const char*, Kind>, 3> kKinds = {{
      {"stuck-emulator", Kind::kStuckEmulator},
      {"stuck-reader", Kind::kStuckReader},
      {"corrupt-counts", Kind::kCorruptCounts},
  }};
  for (const auto& [name, value] : kKinds) {
    if (kind == name) return value;
  }
  BadFault(spec, "unknown fault '" + kind + "'");
}

/// Whether `kind` acts on the ECS's data frames. Those are one more than --frames: frame 0 reads
/// the lines at rest after INIT and frame k + 1 reads encoder message k (sent in the twin's frame
/// k), so only ECS frames 1..frames carry a message, and every twin frame 0..frames - 1 does.
bool HitsEcsFrames(io::LinkFault::Kind kind) {
  return kind == io::LinkFault::Kind::kStuckReader || kind == io::LinkFault::Kind::kCorruptCounts;
}

/// at=FRAME must hit a frame that carries an encoder message, or the fault would test nothing
/// (and the run would pass, or fail without a lost message to name).
void CheckFaultFrame(const std::string& spec, const io::LinkFault& fault, std::int64_t frames) {
  const std::string at = "at=" + std::to_string(fault.at_frame);
  const std::string runs = std::to_string(frames) + " (--frames " + std::to_string(frames) + ")";
  if (!HitsEcsFrames(fault.kind)) {
    if (fault.at_frame >= frames) {
      BadFault(spec, at + " comes after the last of the run's " + std::to_string(frames) +
                         " data frames (--frames); choose a smaller at");
    }
    return;
  }
  if (fault.at_frame == 0) {
    BadFault(spec, "at=0 hits no encoder message: the ECS's data frame 0 reads the lines at rest "
                   "after INIT, and its frame k + 1 reads encoder message k; choose at between 1 "
                   "and " + runs);
  }
  if (fault.at_frame > frames) {
    BadFault(spec, at + " comes after the ECS's last data frame, " + runs +
                       ", which reads the last encoder message; choose at between 1 and " +
                       std::to_string(frames));
  }
}

/// `--inject-fault KIND[,at=FRAME][,count=N]` (mock only): what the boards do wrong, when. FRAME
/// defaults to the first data frame that carries an encoder message on the side the fault acts
/// on (0 for the twin's emulator, 1 for the ECS's readers and answers); a fault that would hit
/// no message is refused.
io::LinkFault ParseLinkFault(const std::string& spec, std::int64_t frames) {
  io::LinkFault fault;
  bool at_given = false;
  std::size_t start = 0;
  for (int item = 0; start <= spec.size(); ++item) {
    const std::size_t comma = std::min(spec.find(',', start), spec.size());
    const std::string part = spec.substr(start, comma - start);
    start = comma + 1;
    if (item == 0) {
      fault.kind = ParseFaultKind(spec, part);
      continue;
    }
    const std::size_t eq = part.find('=');
    const std::string key = part.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : part.substr(eq + 1);
    if (key == "at") {
      fault.at_frame = ParseFaultNumber(spec, key, value, 0);
      at_given = true;
    } else if (key == "count") {
      fault.frames = ParseFaultNumber(spec, key, value, 1);
    } else {
      BadFault(spec, "'" + part + "' is not at=FRAME or count=N");
    }
  }
  if (!at_given) fault.at_frame = HitsEcsFrames(fault.kind) ? 1 : 0;
  CheckFaultFrame(spec, fault, frames);
  return fault;
}

/// The flags, read once, in the order they are checked (exit 2 naming the flag).
IoTestOptions IoTestOptionsFrom(const IoTestFlags& f) {
  IoTestOptions o;
  o.image = io::ParseImage(f.image).value_or(io::Image::kIcoboardInverse);  // CLI11-checked
  o.io = IoTestBackendOf(f);
  o.io_text = f.io;
  if (!f.board_image.empty()) o.board_image = io::ParseImage(f.board_image);  // CLI11-checked
  o.frames = f.frames;
  o.rate_hz = f.rate_hz;
  o.wait_peer_s = f.wait_peer_s;
  if (!f.inject_fault.empty()) o.fault = ParseLinkFault(f.inject_fault, f.frames);
  o.fault_text = f.inject_fault;
  o.json = f.json;
  return o;
}

void AddIoTestFlags(CLI::App* app, IoTestFlags& options) {
  app->add_option("--io", options.io, std::string("backend: ") + io::kBackendForms)
      ->capture_default_str();
  app->add_option("--image", options.image,
                  "image this side's driver needs: icoboard (ECS) or icoboard_inverse (twin); over "
                  "mock, whose counters lead the summary")
      ->check(CLI::IsMember({"icoboard", "icoboard_inverse"}))
      ->capture_default_str();
  app->add_option("--board-image", options.board_image,
                  "mock only: image the emulated board of --image's side carries (default: the one "
                  "--image needs); a mismatch tests the wrong-image error")
      ->check(CLI::IsMember({"icoboard", "icoboard_inverse"}));
  app->add_option("--frames", options.frames,
                  "data (ALL) frames to send after INIT, each one encoder and one PWM message; a "
                  "TEST loop-back follows every 3rd, so every 4th transfer is a TEST")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{100'000'000}))
      ->capture_default_str();
  app->add_option(
         "--rate", options.rate_hz,
         "frame rate in Hz and the step size sent in INIT (over mock only the step: the boards' "
         "time is frames x step, and the run is as fast as the machine)")
      ->check(CLI::Range(1.0, 100'000.0))
      ->capture_default_str();
  app->add_option("--wait-peer", options.wait_peer_s,
                  "wire only: wait up to SECONDS for the other process to attach before INIT "
                  "(a run with no peer fails with exit 5)")
      ->check(CLI::Range(0.0, 3600.0));
  app->add_option("--inject-fault", options.inject_fault,
                  std::string("mock only: make the boards fail to see io-test catch it: ") +
                      kFaultForms +
                      " (data frame FRAME on, N frames; stuck-emulator acts on the twin's frames, "
                      "whose frame k sends encoder message k, FRAME 0 by default; stuck-reader "
                      "and corrupt-counts on the ECS's, whose frame k + 1 reads it, FRAME 1 by "
                      "default)");
  app->add_flag("--json", options.json,
                "print the summary as JSON (frames_sent, frames_received, frames_corrupted, "
                "frames_missed, init_frames_*, test_frames_*, count_errors, counts_over_limit, "
                "frames_peer_absent; over mock also encoder_messages_*, pwm_messages_*, ...)");
}

Command AddIoTestCommand(CLI::App& parent) {
  auto flags = std::make_shared<IoTestFlags>();
  CLI::App* app = parent.add_subcommand(
      "io-test", "Bring-up test of the FPGA link: INIT, identity check, N frames, errors counted");
  app->description(
      "Bring-up test of the FPGA link: INIT, identity check, N frames, errors counted.\n"
      "Sends INIT (with the step size from --rate), checks the board's identity (icoboard = ECS\n"
      "image, icoboard_inverse = twin image), then N data frames with a known pattern (a TEST\n"
      "loop-back after every 3rd) and prints frames sent/received/corrupted/missed (data, INIT\n"
      "and TEST apart) and count errors. Over mock both boards run here, joined by their wires,\n"
      "unpaced: the ECS must decode the twin's encoder pattern edge by edge and the twin read the\n"
      "ECS's PWM, counted as messages sent/received/missed (thesis Table 5.2: --frames 720000).\n"
      "Over wire:NAME or spidev the other side must run io-test too: its pattern is checked on\n"
      "arrival. Exit 0 only without errors; 5 on an I/O error, the wrong image, a lost message or\n"
      "a wire with no peer; 2 on bad usage. Frames: docs/spi-protocol.md.");
  AddIoTestFlags(app, *flags);
  return Command{app, [flags] { return RunIoTest(IoTestOptionsFrom(*flags)); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(70, AddIoTestCommand);

}  // namespace hiltwin::app
