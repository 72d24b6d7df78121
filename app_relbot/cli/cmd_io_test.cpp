// `hiltwin io-test`: bring-up test of the FPGA link. INIT, identity check, N frames with a known
// pattern, then a summary; exit 0 only without errors, 5 on an I/O error, the wrong image or (wire)
// no peer. Over a wire or a real link the inputs come from the other side, which is expected to run
// io-test too: its pattern is checked by relations that hold whatever its frame index is.
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "hiltwin/app_relbot/commands.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/io/conversions.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/io/wire_bus.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::app {
namespace {

struct IoTestOptions {
  std::string io = "mock";
  std::string image = "icoboard_inverse";
  std::string board_image;
  std::int64_t frames = 1000;
  double rate_hz = 1000.0;
  double wait_peer_s = 0.0;
  bool json = false;
};

/// The known pattern: PWM values and encoder positions as functions of the data-frame index.
std::int32_t PatternPwm(std::int64_t k, std::size_t c) {
  return static_cast<std::int32_t>((k * 37 + static_cast<std::int64_t>(c) * 511) % 4095) - 2047;
}
std::int32_t PatternCounts(std::int64_t k, std::size_t c) {
  return io::WrapToRelative(k * 13 * static_cast<std::int64_t>(c + 1) - 5000);
}
std::int32_t PatternPosition(std::int64_t k, std::size_t c) {
  return static_cast<std::int32_t>(k * 13 * static_cast<std::int64_t>(c + 1));  // within any pulse limit
}
std::array<std::uint8_t, 8> PatternBytes(std::int64_t i) {
  std::array<std::uint8_t, 8> bytes{};
  for (std::size_t b = 0; b < bytes.size(); ++b) {
    bytes[b] = static_cast<std::uint8_t>((i * 131 + static_cast<std::int64_t>(b) * 29) & 0xFF);
  }
  return bytes;
}

/// Mock only: drives the emulated board's inputs with the pattern, indexed by board time. The
/// encoder lines are an emulator whose period p (index p + 1) starts at p·step and moves from
/// PatternCounts(p) to PatternCounts(p + 1); the ECS board's readers decode its edges.
class PatternSource final : public io::PwmSignalSource, public io::EncoderLineSource {
 public:
  explicit PatternSource(std::int64_t step_ns)
      : step_ns_(step_ns),
        divider_(io::ClockDividerForStep(step_ns)),
        subticks_(io::SubticksPerStep(step_ns, divider_)) {}
  void DutyAt(std::int64_t t_ns, std::array<double, io::kChannels>& duty_out) noexcept override {
    for (std::size_t c = 0; c < io::kChannels; ++c) duty_out[c] = io::PwmToDuty(PatternPwm(t_ns / step_ns_, c));
  }
  io::LineView Lines(std::int64_t t_ns) noexcept override {
    io::LineView view;
    view.newest = static_cast<std::uint64_t>(t_ns / step_ns_) + 1;
    return view;
  }
  bool Period(std::uint64_t index, io::EncoderPeriod& out) noexcept override {
    if (index == 0) return false;
    const auto p = static_cast<std::int64_t>(index - 1);
    out.index = index;
    for (std::size_t c = 0; c < io::kChannels; ++c) {
      const io::PulsePlan plan = io::PlanPulses(PatternCounts(p, c), PatternCounts(p + 1, c));
      out.channels[c] = io::PulseSegment{PatternCounts(p, c), plan.pulses, plan.direction, p * step_ns_,
                                         subticks_, divider_};
    }
    return true;
  }

 private:
  std::int64_t step_ns_;
  std::uint32_t divider_;
  std::uint32_t subticks_;
};

/// Residue of `value` modulo `modulus` in [0, modulus).
std::int64_t Mod(std::int64_t value, std::int64_t modulus) {
  return ((value % modulus) + modulus) % modulus;
}

/// Twin side over a wire or real link: PWM from the other side's io-test. Every channel must
/// come from the same pattern frame (channel c is 511·c ahead of channel 0, modulo 4095), or an
/// adjacent one: a real PWM reader measures each channel in its own PWM period, so one channel
/// may still show the previous frame. All zero is the idle line before the first ALL frame.
bool IsPeerPwmPattern(const std::array<std::int32_t, io::kChannels>& pwm) {
  if (pwm == std::array<std::int32_t, io::kChannels>{}) return true;
  for (std::size_t c = 1; c < io::kChannels; ++c) {
    const std::int64_t r = Mod(pwm[c] - pwm[0] - 511 * static_cast<std::int64_t>(c), 4095);
    if (r != 0 && r != 37 && r != 4095 - 37) return false;
  }
  return true;
}

/// ECS side over a wire or real link: counts from the other side's io-test, which sends channel
/// c at (c+1)·13·k. The readers see the pulses spread over the twin's periods (channel c moves
/// c+1 times as fast), so channel c stays within 3 twin periods' worth of (c+1) × channel 0,
/// and channel 0 never moves backwards.
class PeerCountsCheck {
 public:
  bool operator()(const io::EcsInputs& in) {
    for (std::size_t c = 1; c < io::kChannels; ++c) {
      const auto factor = static_cast<std::int64_t>(c + 1);
      const std::int32_t deviation = io::WrapToRelative(in.counts[c] - factor * in.counts[0]);
      if (deviation > 3 * 13 * factor || deviation < -3 * 13 * factor) return false;
    }
    const bool forward = !primed_ || in.absolute_counts[0] >= last_;
    primed_ = true;
    last_ = in.absolute_counts[0];
    return forward;
  }

 private:
  bool primed_ = false;
  std::int64_t last_ = 0;
};

struct Summary {
  std::uint64_t count_errors = 0;
  const char* fault = nullptr;
  std::int64_t frames = 0;               ///< frames sent after INIT
  std::int64_t frames_peer_absent = 0;   ///< wire: frames during which no peer was attached
};

template <typename Driver, typename Inputs, typename Send, typename Check>
Summary RunFrames(Driver& driver, const IoTestOptions& options, std::int64_t period_ns, Send send,
                  Check check) {
  Summary summary;
  kernel_glue::MonotonicClock clock;
  const std::int64_t t0_ns = clock.NowNs() + period_ns;
  Inputs in{};
  std::int64_t data_frames = 0;
  for (std::int64_t i = 0; i < options.frames; ++i) {
    clock.SleepUntilNs(t0_ns + i * period_ns);
    io::ExchangeStatus status;
    ++summary.frames;
    if (i % 4 == 3) {
      // Every fourth frame is a TEST loop-back: a known pattern on every backend.
      const auto pattern = PatternBytes(i);
      std::array<std::uint8_t, 8> echo{};
      status = driver.Test(pattern, echo);
      if (status.ok() && echo != pattern) ++summary.count_errors;
    } else {
      status = driver.Exchange(send(data_frames), in);
      ++data_frames;
      // With no peer the inputs are idle: nothing to check, and the run fails for that below.
      if (status.ok() && !status.peer_absent && !check(in)) ++summary.count_errors;
    }
    if (status.peer_absent) ++summary.frames_peer_absent;
    if (status.code == io::ExchangeStatus::Code::kFault) {
      summary.fault = status.reason;
      break;
    }
  }
  return summary;
}

const char* SideName(io::Image image) { return image == io::Image::kIcoboard ? "ECS" : "twin"; }

/// The way out when the other side of a wire is missing: the command that starts it.
std::string NoPeerAdvice(const IoTestOptions& options, io::Image image, bool waited) {
  return std::string("start the other side first, e.g. `hiltwin io-test --io ") + options.io +
         " --image " + io::ToString(io::Counterpart(image)) + " --frames 100000` in another " +
         "terminal, " + (waited ? "or wait longer with a larger --wait-peer" :
                                  "or add --wait-peer SECONDS to wait for it");
}

/// Wire only: waits (start-up, not real-time) until the other process has attached.
void WaitForPeer(io::IoBackend& backend, const IoTestOptions& options, io::Image image) {
  const auto* wire = dynamic_cast<const io::WireBus*>(&backend.bus());
  if (wire == nullptr) return;
  kernel_glue::MonotonicClock clock;
  const std::int64_t deadline = clock.NowNs() + static_cast<std::int64_t>(options.wait_peer_s * 1e9);
  while (wire->PeerStatus().result == io::BusResult::kPeerAbsent) {
    if (clock.NowNs() >= deadline) {
      char seconds[32];
      std::snprintf(seconds, sizeof seconds, "%g", options.wait_peer_s);
      throw CommandError(ExitCode::kIo, std::string("no ") + SideName(io::Counterpart(image)) +
                                            " process attached to " + options.io + " within " +
                                            seconds + " s (--wait-peer); " + NoPeerAdvice(options, image, true));
    }
    clock.SleepUntilNs(clock.NowNs() + 10'000'000);
  }
}

/// Checks the flags against the backend kind and opens it (exit 2 for usage, 5 for I/O).
std::unique_ptr<io::IoBackend> OpenIoTestBackend(const IoTestOptions& options, io::Image image) {
  io::BackendOptions backend_options;
  backend_options.side = image;
  if (!options.board_image.empty()) backend_options.mock_board_image = io::ParseImage(options.board_image);
  io::BackendSpec spec;
  try {
    spec = io::ParseBackendSpec(options.io);
  } catch (const io::ConfigError& e) {
    throw CommandError(ExitCode::kUsage, std::string("--io: ") + e.what());
  }
  if (!options.board_image.empty() && spec.kind != io::BackendSpec::Kind::kMock) {
    throw CommandError(ExitCode::kUsage,
                       "--board-image " + options.board_image + " only applies to --io mock; a wired "
                       "or real board carries its own image (drop --board-image)");
  }
  if (options.wait_peer_s > 0.0 && spec.kind != io::BackendSpec::Kind::kWire) {
    throw CommandError(ExitCode::kUsage,
                       "--wait-peer only applies to --io wire:NAME; a mock board has no peer and a "
                       "real board's peer cannot be seen from here (drop --wait-peer)");
  }
  try {
    return io::OpenBackend(options.io, backend_options);
  } catch (const io::ConfigError& e) {
    throw CommandError(ExitCode::kUsage, std::string("--io ") + options.io + ": " + e.what());
  } catch (const std::exception& e) {
    throw CommandError(ExitCode::kIo, std::string(e.what()) + " (--io " + options.io + ")");
  }
}

/// Everything one io-test found; the JSON, the text and the exit code derive from it.
struct IoTestOutcome {
  Summary summary;
  io::InitResult init;
  io::LinkCounters counters;
  io::TransferTiming timing;
  io::EncoderLineCounters reader;  ///< ECS board model's line readers (mock only)
  std::uint64_t count_errors = 0;  ///< pattern mismatches plus reader errors
  bool ok = false;
  [[nodiscard]] double mean_transfer_ns() const {
    return timing.transfers > 0 ? static_cast<double>(timing.total_ns) / static_cast<double>(timing.transfers)
                                : 0.0;
  }
};

template <typename Driver, typename Inputs, typename Send, typename Check>
void ExchangeWith(Driver& driver, const IoTestOptions& options, std::int64_t period_ns, Send send,
                  Check check, IoTestOutcome& outcome) {
  outcome.init = driver.Init(period_ns);
  if (!outcome.init.ok) throw CommandError(ExitCode::kIo, outcome.init.message);
  outcome.summary = RunFrames<Driver, Inputs>(driver, options, period_ns, send, check);
  outcome.counters = driver.counters();
  outcome.timing = driver.timing();
}

/// INIT, then the pattern frames from this side's driver; a mock board plays the other side.
IoTestOutcome ExchangeFrames(io::IoBackend& backend, const IoTestOptions& options, io::Image image,
                             std::int64_t period_ns) {
  const bool mock = backend.kind() == io::BackendSpec::Kind::kMock;
  io::EmulatedFpga* board = backend.emulated_board();
  IoTestOutcome outcome;
  if (image == io::Image::kIcoboardInverse) {
    io::IcoBoardInverse driver(backend.bus());
    ExchangeWith<io::IcoBoardInverse, io::TwinInputs>(
        driver, options, period_ns,
        [](std::int64_t k) {
          std::array<std::int32_t, io::kChannels> out{};
          for (std::size_t c = 0; c < io::kChannels; ++c) out[c] = PatternPosition(k, c);
          return out;
        },
        [&](const io::TwinInputs& in) {
          if (!mock) return IsPeerPwmPattern(in.pwm);
          const std::int64_t k = board->time_ns() / period_ns;
          for (std::size_t c = 0; c < io::kChannels; ++c) {
            if (in.pwm[c] != PatternPwm(k, c)) return false;
          }
          return true;
        },
        outcome);
  } else {
    io::IcoBoard driver(backend.bus());
    PeerCountsCheck peer_counts;
    ExchangeWith<io::IcoBoard, io::EcsInputs>(
        driver, options, period_ns,
        [](std::int64_t k) {
          std::array<std::int32_t, io::kChannels> out{};
          for (std::size_t c = 0; c < io::kChannels; ++c) out[c] = PatternPwm(k, c);
          return out;
        },
        [&](const io::EcsInputs& in) {
          if (!mock) return peer_counts(in);
          const std::int64_t k = board->time_ns() / period_ns;
          for (std::size_t c = 0; c < io::kChannels; ++c) {
            if (in.counts[c] != PatternCounts(k, c)) return false;
          }
          return true;
        },
        outcome);
  }
  // The ECS board model's readers: edges a real reader would miscount, and lines that jumped.
  if (board != nullptr && image == io::Image::kIcoboard) outcome.reader = board->encoder_lines().counters();
  const io::EncoderLineCounters& r = outcome.reader;
  outcome.count_errors = outcome.summary.count_errors + r.illegal_transitions + r.too_fast_edges + r.resyncs;
  const io::LinkCounters& c = outcome.counters;
  outcome.ok = outcome.summary.fault == nullptr && outcome.count_errors == 0 &&
               outcome.summary.frames_peer_absent == 0 && c.frames_corrupted == 0 &&
               c.frames_missed == 0 && c.frames_received == c.frames_sent;
  return outcome;
}

void PrintJson(const IoTestOptions& options, const IoTestOutcome& o) {
  nlohmann::json j;
  j["backend"] = options.io;
  j["image"] = options.image;
  j["board_identity"] = o.init.identity;
  j["rate_hz"] = options.rate_hz;
  j["frames_sent"] = o.counters.frames_sent;
  j["frames_received"] = o.counters.frames_received;
  j["frames_corrupted"] = o.counters.frames_corrupted;
  j["frames_missed"] = o.counters.frames_missed;
  j["count_errors"] = o.count_errors;
  j["faults"] = o.counters.faults;
  j["pulse_limit_events"] = o.counters.pulse_limit_events;
  j["counts_over_limit"] = o.counters.counts_over_limit;
  j["reader_illegal_transitions"] = o.reader.illegal_transitions;
  j["reader_too_fast_edges"] = o.reader.too_fast_edges;
  j["reader_resyncs"] = o.reader.resyncs;
  j["transfer_ns_mean"] = o.mean_transfer_ns();
  j["transfer_ns_max"] = o.timing.max_ns;
  j["peer_absent"] = o.summary.frames_peer_absent > 0;
  j["frames_peer_absent"] = o.summary.frames_peer_absent;
  j["ok"] = o.ok;
  std::printf("%s\n", j.dump(2).c_str());
}

void PrintText(const IoTestOptions& options, const IoTestOutcome& o) {
  using ull = unsigned long long;
  std::printf("io-test over %s, image %s (board identity %u), %.0f Hz\n", options.io.c_str(),
              options.image.c_str(), static_cast<unsigned>(o.init.identity), options.rate_hz);
  std::printf("  frames sent       %llu\n", static_cast<ull>(o.counters.frames_sent));
  std::printf("  frames received   %llu\n", static_cast<ull>(o.counters.frames_received));
  std::printf("  frames corrupted  %llu\n", static_cast<ull>(o.counters.frames_corrupted));
  std::printf("  frames missed     %llu\n", static_cast<ull>(o.counters.frames_missed));
  std::printf("  count errors      %llu (reader: %llu illegal, %llu too fast, %llu resyncs)\n",
              static_cast<ull>(o.count_errors), static_cast<ull>(o.reader.illegal_transitions),
              static_cast<ull>(o.reader.too_fast_edges), static_cast<ull>(o.reader.resyncs));
  std::printf("  counts over limit %llu\n", static_cast<ull>(o.counters.counts_over_limit));
  std::printf("  transfer time     mean %.0f ns, max %lld ns\n", o.mean_transfer_ns(),
              static_cast<long long>(o.timing.max_ns));
  if (o.summary.frames_peer_absent > 0) {
    std::printf("  no peer           %lld of %lld frames\n",
                static_cast<long long>(o.summary.frames_peer_absent),
                static_cast<long long>(o.summary.frames));
  }
  std::printf("%s\n", o.ok ? "PASS" : "FAIL");
}

/// Exit 5 with what went wrong and the way out; returns when the test passed.
void ThrowUnlessPassed(const IoTestOptions& options, io::Image image, const IoTestOutcome& o, bool mock) {
  const Summary& summary = o.summary;
  if (summary.fault != nullptr) {
    throw CommandError(ExitCode::kIo, std::string("link fault on ") + options.io + ": " + summary.fault);
  }
  if (summary.frames_peer_absent > 0) {
    const std::string other = SideName(io::Counterpart(image));
    const std::string what =
        summary.frames_peer_absent == summary.frames
            ? "no " + other + " process was attached to " + options.io + " during the whole run, so " +
                  "nothing crossed the wire"
            : "no " + other + " process was attached to " + options.io + " for " +
                  std::to_string(summary.frames_peer_absent) + " of " + std::to_string(summary.frames) +
                  " frames, which tested nothing";
    throw CommandError(ExitCode::kIo, what + "; " + NoPeerAdvice(options, image, options.wait_peer_s > 0.0));
  }
  if (!o.ok) {
    throw CommandError(ExitCode::kIo, "the link had errors (see the summary above); check wiring, "
                                      "cable length and SPI speed, then rerun" +
                                      std::string(mock ? "" : "; over a wire or real link the other "
                                                              "side must run io-test too (its pattern "
                                                              "is checked)"));
  }
}

int RunIoTest(const IoTestOptions& options) {
  const io::Image image = *io::ParseImage(options.image);
  const std::unique_ptr<io::IoBackend> backend = OpenIoTestBackend(options, image);
  if (options.wait_peer_s > 0.0) WaitForPeer(*backend, options, image);
  const std::int64_t period_ns = kernel_glue::PeriodNsFromRateHz(options.rate_hz);
  const bool mock = backend->kind() == io::BackendSpec::Kind::kMock;
  PatternSource pattern(period_ns);
  if (mock) {
    backend->emulated_board()->SetPwmSource(&pattern);
    backend->emulated_board()->SetEncoderSource(&pattern);
  }
  const IoTestOutcome outcome = ExchangeFrames(*backend, options, image, period_ns);
  if (options.json) {
    PrintJson(options, outcome);
  } else {
    PrintText(options, outcome);
  }
  ThrowUnlessPassed(options, image, outcome, mock);
  return static_cast<int>(ExitCode::kPass);
}

Command AddIoTestCommand(CLI::App& parent) {
  auto options = std::make_shared<IoTestOptions>();
  CLI::App* app = parent.add_subcommand(
      "io-test", "Bring-up test of the FPGA link: INIT, identity check, N frames, errors counted");
  app->description(
      "Bring-up test of the FPGA link: sends INIT (with the step size from --rate), checks the\n"
      "board's identity (icoboard = ECS image, icoboard_inverse = twin image), then N frames with\n"
      "a known pattern (every 4th a TEST loop-back) and prints frames sent/received/corrupted/\n"
      "missed and count errors. Over wire:NAME or spidev the other side must run io-test too:\n"
      "its pattern is checked on arrival. Exit 0 only without errors; 5 on an I/O error, the\n"
      "wrong image or a wire with no peer; 2 on bad usage. Frame layout: docs/spi-protocol.md.");
  app->add_option("--io", options->io, std::string("backend: ") + io::kBackendForms)
      ->capture_default_str();
  app->add_option("--image", options->image,
                  "image this side's driver needs: icoboard (ECS) or icoboard_inverse (twin)")
      ->check(CLI::IsMember({"icoboard", "icoboard_inverse"}))
      ->capture_default_str();
  app->add_option("--board-image", options->board_image,
                  "mock only: image the emulated board carries (default: the one --image needs); "
                  "a mismatch tests the wrong-image error")
      ->check(CLI::IsMember({"icoboard", "icoboard_inverse"}));
  app->add_option("--frames", options->frames,
                  "frames to send after INIT: every 4th is a TEST loop-back, the others data (ALL) "
                  "frames")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{100'000'000}))
      ->capture_default_str();
  app->add_option("--rate", options->rate_hz, "frame rate in Hz; also the step size sent in INIT")
      ->check(CLI::Range(1.0, 100'000.0))
      ->capture_default_str();
  app->add_option("--wait-peer", options->wait_peer_s,
                  "wire only: wait up to SECONDS for the other process to attach before INIT "
                  "(a run with no peer fails with exit 5)")
      ->check(CLI::Range(0.0, 3600.0));
  app->add_flag("--json", options->json,
                "print the summary as JSON (frames_sent, frames_received, frames_corrupted, "
                "frames_missed, count_errors, counts_over_limit, frames_peer_absent, ...)");
  return Command{app, [options] { return RunIoTest(*options); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(70, AddIoTestCommand);

}  // namespace hiltwin::app
