// `hiltwin io-test`: bring-up test of the FPGA link. INIT, identity check, N data frames with a
// known pattern, then a summary; exit 0 only without errors, 5 on an I/O error or the wrong image.
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "hiltwin/app_relbot/commands.h"
#include "hiltwin/io/backend.h"
#include "hiltwin/io/conversions.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/kernel_glue/clock.h"

namespace hiltwin::app {
namespace {

struct IoTestOptions {
  std::string io = "mock";
  std::string image = "icoboard_inverse";
  std::string board_image;
  std::int64_t frames = 1000;
  double rate_hz = 1000.0;
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

/// Mock only: drives the emulated board's inputs with the pattern, indexed by board time.
class PatternSource final : public io::PwmSignalSource, public io::EncoderLineSource {
 public:
  explicit PatternSource(std::int64_t step_ns) : step_ns_(step_ns) {}
  void DutyAt(std::int64_t t_ns, std::array<double, io::kChannels>& duty_out) noexcept override {
    for (std::size_t c = 0; c < io::kChannels; ++c) duty_out[c] = io::PwmToDuty(PatternPwm(t_ns / step_ns_, c));
  }
  void CountsAt(std::int64_t t_ns, std::array<std::int32_t, io::kChannels>& counts_out) noexcept override {
    for (std::size_t c = 0; c < io::kChannels; ++c) counts_out[c] = PatternCounts(t_ns / step_ns_, c);
  }

 private:
  std::int64_t step_ns_;
};

struct Summary {
  std::uint64_t count_errors = 0;
  const char* fault = nullptr;
  bool peer_absent = false;
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
    if (i % 4 == 3) {
      // Every fourth frame is a TEST loop-back: a known pattern on every backend.
      const auto pattern = PatternBytes(i);
      std::array<std::uint8_t, 8> echo{};
      status = driver.Test(pattern, echo);
      if (status.ok() && echo != pattern) ++summary.count_errors;
    } else {
      status = driver.Exchange(send(data_frames), in);
      ++data_frames;
      if (status.ok() && !check(in)) ++summary.count_errors;
    }
    summary.peer_absent = summary.peer_absent || status.peer_absent;
    if (status.code == io::ExchangeStatus::Code::kFault) {
      summary.fault = status.reason;
      break;
    }
  }
  return summary;
}

int RunIoTest(const IoTestOptions& options) {
  const io::Image image = *io::ParseImage(options.image);
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
  std::unique_ptr<io::IoBackend> backend;
  try {
    backend = io::OpenBackend(options.io, backend_options);
  } catch (const io::ConfigError& e) {
    throw CommandError(ExitCode::kUsage, std::string("--io ") + options.io + ": " + e.what());
  } catch (const std::exception& e) {
    throw CommandError(ExitCode::kIo, std::string(e.what()) + " (--io " + options.io + ")");
  }
  const std::int64_t period_ns = kernel_glue::PeriodNsFromRateHz(options.rate_hz);
  const bool mock = backend->kind() == io::BackendSpec::Kind::kMock;
  PatternSource pattern(period_ns);
  if (mock) {
    backend->emulated_board()->SetPwmSource(&pattern);
    backend->emulated_board()->SetEncoderSource(&pattern);
  }
  io::EmulatedFpga* board = backend->emulated_board();

  auto run = [&](auto& driver, auto inputs_tag, auto send, auto check) {
    const io::InitResult init = driver.Init(period_ns);
    if (!init.ok) throw CommandError(ExitCode::kIo, init.message);
    using Inputs = decltype(inputs_tag);
    const Summary summary =
        RunFrames<std::remove_reference_t<decltype(driver)>, Inputs>(driver, options, period_ns, send, check);
    return std::make_pair(summary, init);
  };

  Summary summary;
  io::InitResult init;
  io::LinkCounters counters;
  io::TransferTiming timing;
  if (image == io::Image::kIcoboardInverse) {
    io::IcoBoardInverse driver(backend->bus());
    std::tie(summary, init) = run(
        driver, io::TwinInputs{},
        [](std::int64_t k) {
          std::array<std::int32_t, io::kChannels> out{};
          for (std::size_t c = 0; c < io::kChannels; ++c) out[c] = PatternPosition(k, c);
          return out;
        },
        [&](const io::TwinInputs& in) {
          if (!mock) return true;  // a real or wired board's PWM is not ours to predict
          const std::int64_t k = board->time_ns() / period_ns;
          for (std::size_t c = 0; c < io::kChannels; ++c) {
            if (in.pwm[c] != PatternPwm(k, c)) return false;
          }
          return true;
        });
    counters = driver.counters();
    timing = driver.timing();
  } else {
    io::IcoBoard driver(backend->bus());
    std::tie(summary, init) = run(
        driver, io::EcsInputs{},
        [](std::int64_t k) {
          std::array<std::int32_t, io::kChannels> out{};
          for (std::size_t c = 0; c < io::kChannels; ++c) out[c] = PatternPwm(k, c);
          return out;
        },
        [&](const io::EcsInputs& in) {
          if (!mock) return true;
          const std::int64_t k = board->time_ns() / period_ns;
          for (std::size_t c = 0; c < io::kChannels; ++c) {
            if (in.counts[c] != PatternCounts(k, c)) return false;
          }
          return true;
        });
    counters = driver.counters();
    timing = driver.timing();
  }

  const bool ok = summary.fault == nullptr && summary.count_errors == 0 &&
                  counters.frames_corrupted == 0 && counters.frames_missed == 0 &&
                  counters.frames_received == counters.frames_sent;
  const double mean_ns =
      timing.transfers > 0 ? static_cast<double>(timing.total_ns) / static_cast<double>(timing.transfers) : 0.0;
  if (options.json) {
    nlohmann::json j;
    j["backend"] = options.io;
    j["image"] = options.image;
    j["board_identity"] = init.identity;
    j["rate_hz"] = options.rate_hz;
    j["frames_sent"] = counters.frames_sent;
    j["frames_received"] = counters.frames_received;
    j["frames_corrupted"] = counters.frames_corrupted;
    j["frames_missed"] = counters.frames_missed;
    j["count_errors"] = summary.count_errors;
    j["faults"] = counters.faults;
    j["pulse_limit_events"] = counters.pulse_limit_events;
    j["transfer_ns_mean"] = mean_ns;
    j["transfer_ns_max"] = timing.max_ns;
    j["peer_absent"] = summary.peer_absent;
    j["ok"] = ok;
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("io-test over %s, image %s (board identity %u), %.0f Hz\n", options.io.c_str(),
                options.image.c_str(), static_cast<unsigned>(init.identity), options.rate_hz);
    std::printf("  frames sent       %llu\n", static_cast<unsigned long long>(counters.frames_sent));
    std::printf("  frames received   %llu\n", static_cast<unsigned long long>(counters.frames_received));
    std::printf("  frames corrupted  %llu\n", static_cast<unsigned long long>(counters.frames_corrupted));
    std::printf("  frames missed     %llu\n", static_cast<unsigned long long>(counters.frames_missed));
    std::printf("  count errors      %llu\n", static_cast<unsigned long long>(summary.count_errors));
    std::printf("  transfer time     mean %.0f ns, max %lld ns\n", mean_ns,
                static_cast<long long>(timing.max_ns));
    if (summary.peer_absent) {
      std::printf("  note: no peer was attached to %s; its inputs were idle\n", options.io.c_str());
    }
    std::printf("%s\n", ok ? "PASS" : "FAIL");
  }
  if (summary.fault != nullptr) {
    throw CommandError(ExitCode::kIo, std::string("link fault on ") + options.io + ": " + summary.fault);
  }
  if (!ok) {
    throw CommandError(ExitCode::kIo, "the link had errors (see the summary above); check wiring, "
                                      "cable length and SPI speed, then rerun");
  }
  return static_cast<int>(ExitCode::kPass);
}

Command AddIoTestCommand(CLI::App& parent) {
  auto options = std::make_shared<IoTestOptions>();
  CLI::App* app = parent.add_subcommand(
      "io-test", "Bring-up test of the FPGA link: INIT, identity check, N data frames, errors counted");
  app->description(
      "Bring-up test of the FPGA link: sends INIT (with the step size from --rate), checks the\n"
      "board's identity (icoboard = ECS image, icoboard_inverse = twin image), then N frames with\n"
      "a known pattern (every 4th a TEST loop-back) and prints frames sent/received/corrupted/\n"
      "missed and count errors. Exit 0 only without errors; 5 on an I/O error or the wrong image;\n"
      "2 on bad usage. Frame layout: docs/spi-protocol.md.");
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
  app->add_option("--frames", options->frames, "data frames to send after INIT")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{100'000'000}))
      ->capture_default_str();
  app->add_option("--rate", options->rate_hz, "frame rate in Hz; also the step size sent in INIT")
      ->check(CLI::Range(1.0, 100'000.0))
      ->capture_default_str();
  app->add_flag("--json", options->json,
                "print the summary as JSON (frames_sent, frames_received, frames_corrupted, "
                "frames_missed, count_errors, ...)");
  return Command{app, [options] { return RunIoTest(*options); }};
}

}  // namespace

HILTWIN_REGISTER_COMMAND(70, AddIoTestCommand);

}  // namespace hiltwin::app
