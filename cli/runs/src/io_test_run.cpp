// `hiltwin io-test`'s run (hiltwin/runs/io_test_run.h): INIT, identity check, N data frames
// with a known pattern (and a TEST loop-back after every third), then a summary; exit 0 only
// without errors, 5 on an I/O error, the wrong image, an end-to-end message lost or (wire) no
// peer.
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
#include "hiltwin/runs/io_test_run.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>

#include "hiltwin/io/backend.h"
#include "hiltwin/io/board_pair_check.h"
#include "hiltwin/io/conversions.h"
#include "hiltwin/io/icoboard.h"
#include "hiltwin/io/peer_link.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/runs/command.h"

namespace hiltwin::app {
namespace {

/// A TEST loop-back follows every third data frame but the last: one transfer in four.
constexpr std::int64_t kDataFramesPerTest = 3;

/// Wire and real links: the twin's encoder positions as a function of the data-frame index
/// (channel c moves (c+1)·13 counts per frame, within any pulse limit), which the other side's
/// io-test checks by relation (PeerCountsCheck).
std::int32_t PatternPosition(std::int64_t k, std::size_t c) {
  return static_cast<std::int32_t>(k * 13 * static_cast<std::int64_t>(c + 1));
}
std::array<std::uint8_t, 8> PatternBytes(std::int64_t i) {
  std::array<std::uint8_t, 8> bytes{};
  for (std::size_t b = 0; b < bytes.size(); ++b) {
    bytes[b] = static_cast<std::uint8_t>((i * 131 + static_cast<std::int64_t>(b) * 29) & 0xFF);
  }
  return bytes;
}

/// Residue of `value` modulo `modulus` in [0, modulus).
std::int64_t Mod(std::int64_t value, std::int64_t modulus) {
  return ((value % modulus) + modulus) % modulus;
}

/// Twin side over a wire or real link: PWM from the other side's io-test (io::PwmTestValue).
/// Every channel must come from the same pattern frame (channel c is 511·c ahead of channel 0,
/// modulo 4095), or an adjacent one: a real PWM reader measures each channel in its own PWM
/// period, so one channel may still show the previous frame. All zero is the idle line before
/// the first ALL frame.
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
  std::int64_t frames = 0;              ///< transfers after INIT (data and TEST)
  std::int64_t frames_peer_absent = 0;  ///< wire: frames during which no peer was attached
};

/// Wire and real links: `options.frames` data frames, each in its own period slot on the
/// monotonic clock (the board reads that clock), a TEST loop-back after every third but the last.
template <typename Driver, typename Inputs, typename Send, typename Check>
Summary RunFrames(Driver& driver, const IoTestOptions& options, std::int64_t period_ns, Send send,
                  Check check) {
  Summary summary;
  kernel_glue::MonotonicClock clock;
  const std::int64_t t0_ns = clock.NowNs() + period_ns;
  Inputs in{};
  std::int64_t data_frames = 0;
  for (std::int64_t i = 0; data_frames < options.frames; ++i) {
    clock.SleepUntilNs(t0_ns + i * period_ns);
    io::ExchangeStatus status;
    ++summary.frames;
    const bool test = i % (kDataFramesPerTest + 1) == kDataFramesPerTest;
    if (test) {
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
  return std::string("start the other side first, e.g. `hiltwin io-test --io ") + options.io_text +
         " --image " + io::ToString(io::Counterpart(image)) + " --frames 100000` in another " +
         "terminal, " +
         (waited ? "or wait longer with a larger --wait-peer"
                 : "or add --wait-peer SECONDS to wait for it");
}

/// Wire only: waits (start-up, not real-time) until the other process is up. Poll beats this
/// side's heartbeat too: a side counts as up from its first beat, so two sides that only
/// watched would wait for each other.
void WaitForPeer(io::IoBackend& backend, const IoTestOptions& options, io::Image image) {
  io::PeerLink* const link = backend.peer_link();
  if (link == nullptr) return;
  kernel_glue::MonotonicClock clock;
  const std::int64_t deadline =
      clock.NowNs() + static_cast<std::int64_t>(options.wait_peer_s * 1e9);
  while (link->Poll().result == io::BusResult::kPeerAbsent) {
    if (clock.NowNs() >= deadline) {
      char seconds[32];
      std::snprintf(seconds, sizeof seconds, "%g", options.wait_peer_s);
      throw CommandError(ExitCode::kIo, std::string("no ") + SideName(io::Counterpart(image)) +
                                            " process attached to " + options.io_text + " within " +
                                            seconds + " s (--wait-peer); " +
                                            NoPeerAdvice(options, image, true));
    }
    clock.SleepUntilNs(clock.NowNs() + 10'000'000);
  }
}

/// Opens a wire or spidev backend (exit 2 for usage, 5 for I/O).
std::unique_ptr<io::IoBackend> OpenIoTestBackend(const IoTestOptions& options, io::Image image) {
  io::BackendOptions backend_options;
  backend_options.side = image;
  try {
    return io::OpenBackend(options.io, backend_options);
  } catch (const io::ConfigError& e) {
    throw CommandError(ExitCode::kUsage, std::string("--io ") + options.io_text + ": " + e.what());
  } catch (const std::exception& e) {
    throw CommandError(ExitCode::kIo, std::string(e.what()) + " (--io " + options.io_text + ")");
  }
}

/// Two-board mock only: what crossed between the boards, and the other driver's counters.
struct MockFigures {
  io::PairTally tally;
  io::LinkCounters counterpart;  ///< the driver of the other image
  std::uint8_t counterpart_identity = 0;
};

/// Everything one io-test found; the JSON, the text and the exit code derive from it.
struct IoTestOutcome {
  Summary summary;
  io::InitResult init;
  io::LinkCounters counters;  ///< this side's (--image) driver
  io::TransferTiming timing;
  io::EncoderLineCounters reader;  ///< ECS board model's line readers (mock, and wire as ECS)
  std::optional<MockFigures> mock;
  std::uint64_t count_errors = 0;  ///< values that arrived wrong, plus reader errors
  bool ok = false;
  [[nodiscard]] double mean_transfer_ns() const {
    return timing.transfers > 0
               ? static_cast<double>(timing.total_ns) / static_cast<double>(timing.transfers)
               : 0.0;
  }
};

/// Every frame of every kind a driver sent was answered and used.
bool CleanCounters(const io::LinkCounters& c) {
  return c.frames_corrupted == 0 && c.frames_missed == 0 && c.faults == 0 &&
         c.frames_received == c.frames_sent && c.init_frames_received == c.init_frames_sent &&
         c.test_frames_received == c.test_frames_sent;
}

/// Reader errors: edges a real reader would miscount, and lines that jumped.
std::uint64_t ReaderErrors(const io::EncoderLineCounters& r) {
  return r.illegal_transitions + r.too_fast_edges + r.resyncs;
}

/// The data steps of a two-board mock run, with the transfers in the order RunFrames sends them
/// (a TEST loop-back after every third data frame but the last), then the ECS's last frame.
/// Stops at a link fault, as RunFrames does.
const char* RunPairSteps(io::BoardPairCheck& pair, std::int64_t frames, Summary& summary) {
  for (std::int64_t k = 0; k < frames; ++k) {
    ++summary.frames;
    if (const char* fault = pair.DataStep().fault()) return fault;
    if ((k + 1) % kDataFramesPerTest == 0 && k + 1 < frames) {
      ++summary.frames;
      if (const char* fault = pair.TestStep(PatternBytes(summary.frames)).fault()) return fault;
    }
  }
  return pair.Finish().fault();
}

/// Over mock: both boards and drivers in this process; `image` says whose counters lead.
IoTestOutcome RunMock(const IoTestOptions& options, io::Image image, std::int64_t period_ns,
                      const io::LinkFault& fault) {
  const io::Image board_image = options.board_image.value_or(image);
  const bool twin_side = image == io::Image::kIcoboardInverse;
  auto pair =
      std::make_unique<io::BoardPairCheck>(twin_side ? board_image : io::Image::kIcoboardInverse,
                                           twin_side ? io::Image::kIcoboard : board_image);
  pair->Inject(fault);
  const io::PairInit init = pair->Init(period_ns);
  IoTestOutcome outcome;
  outcome.init = twin_side ? init.twin : init.ecs;
  if (!outcome.init.ok) throw CommandError(ExitCode::kIo, outcome.init.message);
  const io::InitResult& other = twin_side ? init.ecs : init.twin;
  if (!other.ok) throw CommandError(ExitCode::kIo, other.message + " (the mock's other board)");
  outcome.summary.fault = RunPairSteps(*pair, options.frames, outcome.summary);
  const io::IcoBoardLink& mine =
      twin_side ? static_cast<const io::IcoBoardLink&>(pair->twin()) : pair->ecs();
  const io::IcoBoardLink& theirs =
      twin_side ? static_cast<const io::IcoBoardLink&>(pair->ecs()) : pair->twin();
  outcome.counters = mine.counters();
  outcome.timing = mine.timing();
  outcome.reader = pair->ecs_board().encoder_lines().counters();
  outcome.mock = MockFigures{pair->tally(), theirs.counters(), other.identity};
  const io::PairTally& t = pair->tally();
  outcome.count_errors =
      t.encoder.wrong + t.pwm.wrong + t.test_echo_errors + ReaderErrors(outcome.reader);
  outcome.ok = outcome.summary.fault == nullptr && outcome.count_errors == 0 &&
               t.encoder.missed() == 0 && t.pwm.missed() == 0 && CleanCounters(outcome.counters) &&
               CleanCounters(outcome.mock->counterpart);
  return outcome;
}

template <typename Driver, typename Inputs, typename Send, typename Check>
void ExchangeWith(Driver& driver, const IoTestOptions& options, std::int64_t period_ns, Send send,
                  Check check, IoTestOutcome& outcome) {
  outcome.init = driver.Init(period_ns);
  if (!outcome.init.ok) throw CommandError(ExitCode::kIo, outcome.init.message);
  outcome.summary = RunFrames<Driver, Inputs>(driver, options, period_ns, send, check);
  outcome.counters = driver.counters();
  outcome.timing = driver.timing();
}

/// Over a wire or a real link: INIT, then the pattern frames from this side's driver; the other
/// side's io-test sends its pattern, checked here by relation.
IoTestOutcome ExchangeFrames(io::IoBackend& backend, const IoTestOptions& options, io::Image image,
                             std::int64_t period_ns) {
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
        [](const io::TwinInputs& in) { return IsPeerPwmPattern(in.pwm); }, outcome);
  } else {
    io::IcoBoard driver(backend.bus());
    PeerCountsCheck peer_counts;
    ExchangeWith<io::IcoBoard, io::EcsInputs>(
        driver, options, period_ns,
        [](std::int64_t k) {
          std::array<std::int32_t, io::kChannels> out{};
          for (std::size_t c = 0; c < io::kChannels; ++c) out[c] = io::PwmTestValue(k, c);
          return out;
        },
        [&](const io::EcsInputs& in) { return peer_counts(in); }, outcome);
  }
  // The local ECS board model's readers (wire): edges a real reader would miscount.
  const io::EmulatedFpga* board = backend.emulated_board();
  if (board != nullptr && image == io::Image::kIcoboard)
    outcome.reader = board->encoder_lines().counters();
  outcome.count_errors = outcome.summary.count_errors + ReaderErrors(outcome.reader);
  outcome.ok = outcome.summary.fault == nullptr && outcome.count_errors == 0 &&
               outcome.summary.frames_peer_absent == 0 && CleanCounters(outcome.counters);
  return outcome;
}

void AddCounters(nlohmann::json& j, const io::LinkCounters& c) {
  j["frames_sent"] = c.frames_sent;
  j["frames_received"] = c.frames_received;
  j["frames_corrupted"] = c.frames_corrupted;
  j["frames_missed"] = c.frames_missed;
  j["init_frames_sent"] = c.init_frames_sent;
  j["init_frames_received"] = c.init_frames_received;
  j["test_frames_sent"] = c.test_frames_sent;
  j["test_frames_received"] = c.test_frames_received;
  j["faults"] = c.faults;
}

void AddMockJson(nlohmann::json& j, const IoTestOptions& options, const MockFigures& m) {
  const io::PairTally& t = m.tally;
  j["encoder_messages_sent"] = t.encoder.sent;
  j["encoder_messages_received"] = t.encoder.received;
  j["encoder_messages_missed"] = t.encoder.missed();
  j["pwm_messages_sent"] = t.pwm.sent;
  j["pwm_messages_received"] = t.pwm.received;
  j["pwm_messages_missed"] = t.pwm.missed();
  j["test_echo_errors"] = t.test_echo_errors;
  j["encoder_wraps_up"] = t.wraps_up;
  j["encoder_wraps_down"] = t.wraps_down;
  nlohmann::json other;
  other["image"] = io::ToString(io::Counterpart(options.image));
  other["board_identity"] = m.counterpart_identity;
  AddCounters(other, m.counterpart);
  j["counterpart"] = other;
}

void PrintJson(const IoTestOptions& options, const IoTestOutcome& o) {
  nlohmann::json j;
  j["backend"] = options.io_text;
  j["image"] = io::ToString(options.image);
  j["board_identity"] = o.init.identity;
  j["rate_hz"] = options.rate_hz;
  AddCounters(j, o.counters);
  j["count_errors"] = o.count_errors;
  j["pulse_limit_events"] = o.counters.pulse_limit_events;
  j["counts_over_limit"] = o.counters.counts_over_limit;
  j["reader_illegal_transitions"] = o.reader.illegal_transitions;
  j["reader_too_fast_edges"] = o.reader.too_fast_edges;
  j["reader_resyncs"] = o.reader.resyncs;
  j["reader_edges"] = o.reader.edges;
  j["transfer_ns_mean"] = o.mean_transfer_ns();
  j["transfer_ns_max"] = o.timing.max_ns;
  j["peer_absent"] = o.summary.frames_peer_absent > 0;
  j["frames_peer_absent"] = o.summary.frames_peer_absent;
  if (o.mock) AddMockJson(j, options, *o.mock);
  j["ok"] = o.ok;
  std::printf("%s\n", j.dump(2).c_str());
}

using ull = unsigned long long;

void PrintFrameLine(const char* what, std::uint64_t data, std::uint64_t init, std::uint64_t test) {
  std::printf("  %-17s %llu data, %llu INIT, %llu TEST\n", what, static_cast<ull>(data),
              static_cast<ull>(init), static_cast<ull>(test));
}

void PrintMockText(const IoTestOptions& options, const MockFigures& m, std::uint64_t edges) {
  const io::LinkCounters& c = m.counterpart;
  std::printf(
      "  other side        %s (identity %u): %llu of %llu data frames received, %llu "
      "corrupted, %llu missed\n",
      io::ToString(io::Counterpart(options.image)),
      static_cast<unsigned>(m.counterpart_identity), static_cast<ull>(c.frames_received),
      static_cast<ull>(c.frames_sent), static_cast<ull>(c.frames_corrupted),
      static_cast<ull>(c.frames_missed));
  const io::PairTally& t = m.tally;
  std::printf(
      "  encoder messages  %llu sent, %llu received, %llu missed (twin -> ECS, %llu edges "
      "decoded; thesis Table 5.2)\n",
      static_cast<ull>(t.encoder.sent), static_cast<ull>(t.encoder.received),
      static_cast<ull>(t.encoder.missed()), static_cast<ull>(edges));
  std::printf("  PWM messages      %llu sent, %llu received, %llu missed (ECS -> twin)\n",
              static_cast<ull>(t.pwm.sent), static_cast<ull>(t.pwm.received),
              static_cast<ull>(t.pwm.missed()));
  std::printf("  encoder wraps     %llu counting up, %llu counting down (across +-8192)\n",
              static_cast<ull>(t.wraps_up), static_cast<ull>(t.wraps_down));
}

void PrintText(const IoTestOptions& options, const IoTestOutcome& o) {
  std::printf("io-test over %s%s, image %s (board identity %u), %.0f Hz\n",
              options.io_text.c_str(),
              o.mock ? " (twin and ECS boards in this process, unpaced)" : "",
              io::ToString(options.image), static_cast<unsigned>(o.init.identity), options.rate_hz);
  const io::LinkCounters& c = o.counters;
  PrintFrameLine("frames sent", c.frames_sent, c.init_frames_sent, c.test_frames_sent);
  PrintFrameLine("frames received", c.frames_received, c.init_frames_received,
                 c.test_frames_received);
  std::printf("  frames corrupted  %llu\n", static_cast<ull>(c.frames_corrupted));
  std::printf("  frames missed     %llu\n", static_cast<ull>(c.frames_missed));
  std::printf("  count errors      %llu (reader: %llu illegal, %llu too fast, %llu resyncs)\n",
              static_cast<ull>(o.count_errors), static_cast<ull>(o.reader.illegal_transitions),
              static_cast<ull>(o.reader.too_fast_edges), static_cast<ull>(o.reader.resyncs));
  std::printf("  counts over limit %llu\n", static_cast<ull>(c.counts_over_limit));
  std::printf("  transfer time     mean %.0f ns, max %lld ns\n", o.mean_transfer_ns(),
              static_cast<long long>(o.timing.max_ns));
  if (o.mock) PrintMockText(options, *o.mock, o.reader.edges);
  if (o.summary.frames_peer_absent > 0) {
    std::printf("  no peer           %lld of %lld frames\n",
                static_cast<long long>(o.summary.frames_peer_absent),
                static_cast<long long>(o.summary.frames));
  }
  std::printf("%s\n", o.ok ? "PASS" : "FAIL");
}

/// One direction of the mock's messages, for the error message: message k is sent in data frame
/// k and read by `reader` in its data frame k + `read_later`.
struct MessagePath {
  const char* what;
  const char* reader;
  int read_later;
};

/// What the first lost message of one direction was, named by its number and the frames that
/// carried it, for the error message.
std::string DescribeMiss(const MessagePath& path, const io::MessageTally& tally,
                         const io::FirstMiss& first) {
  std::string text = std::string(path.what) + " messages: " + std::to_string(tally.received) +
                     " of " + std::to_string(tally.sent) + " arrived as sent, " +
                     std::to_string(tally.missed()) + " missed";
  if (first.frame < 0) return text;
  text += "; the first is " + std::string(path.what) + " message " +
          std::to_string(first.frame) + " (sent in data frame " + std::to_string(first.frame) +
          ", read in " + path.reader + "'s data frame " +
          std::to_string(first.frame + path.read_later) + ")";
  if (*first.reason != '\0') return text + ", whose reading frame failed (" + first.reason + ")";
  return text + ", channel " + std::to_string(first.channel) + ": sent " +
         std::to_string(first.sent) + ", " + path.reader + " read " + std::to_string(first.read);
}

/// Mock: the end-to-end figures that failed, and the way out.
std::string MockFailure(const IoTestOptions& options, const MockFigures& m) {
  std::string what;
  if (m.tally.encoder.missed() > 0) {
    // The ECS reads encoder message k in its next frame: the emulator spreads it over a period.
    what = DescribeMiss({"encoder", "the ECS", 1}, m.tally.encoder, m.tally.first_encoder_miss);
  } else if (m.tally.pwm.missed() > 0) {
    what = DescribeMiss({"PWM", "the twin", 0}, m.tally.pwm, m.tally.first_pwm_miss);
  } else {
    what = "the link had errors (see the summary above)";
  }
  return what + (!options.fault
                     ? "; on a mock link no wire can fail, so this is a bug in the board model or "
                       "the drivers: report it with this output"
                     : "; this is what --inject-fault " + options.fault_text + " should cause");
}

/// Exit 5 with what went wrong and the way out; returns when the test passed.
void ThrowUnlessPassed(const IoTestOptions& options, io::Image image, const IoTestOutcome& o) {
  const Summary& summary = o.summary;
  if (summary.fault != nullptr) {
    throw CommandError(ExitCode::kIo,
                       std::string("link fault on ") + options.io_text + ": " + summary.fault);
  }
  if (summary.frames_peer_absent > 0) {
    const std::string other = SideName(io::Counterpart(image));
    const std::string what = summary.frames_peer_absent == summary.frames
                                 ? "no " + other + " process was attached to " + options.io_text +
                                       " during the whole run, so " + "nothing crossed the wire"
                                 : "no " + other + " process was attached to " + options.io_text +
                                       " for " + std::to_string(summary.frames_peer_absent) +
                                       " of " + std::to_string(summary.frames) +
                                       " frames, which tested nothing";
    throw CommandError(ExitCode::kIo,
                       what + "; " + NoPeerAdvice(options, image, options.wait_peer_s > 0.0));
  }
  if (o.ok) return;
  if (o.mock) throw CommandError(ExitCode::kIo, MockFailure(options, *o.mock));
  throw CommandError(ExitCode::kIo,
                     "the link had errors (see the summary above); check wiring, "
                     "cable length and SPI speed, then rerun; over a wire or real "
                     "link the other side must run io-test too (its pattern is "
                     "checked)");
}

}  // namespace

int RunIoTest(const IoTestOptions& options) {
  const io::Image image = options.image;
  const bool mock = options.io.kind == io::BackendSpec::Kind::kMock;
  const std::int64_t period_ns = kernel_glue::PeriodNsFromRateHz(options.rate_hz);
  IoTestOutcome outcome;
  if (mock) {
    outcome = RunMock(options, image, period_ns, options.fault.value_or(io::LinkFault{}));
  } else {
    const std::unique_ptr<io::IoBackend> backend = OpenIoTestBackend(options, image);
    if (options.wait_peer_s > 0.0) WaitForPeer(*backend, options, image);
    outcome = ExchangeFrames(*backend, options, image, period_ns);
  }
  if (options.json) {
    PrintJson(options, outcome);
  } else {
    PrintText(options, outcome);
  }
  ThrowUnlessPassed(options, image, outcome);
  return static_cast<int>(ExitCode::kPass);
}

}  // namespace hiltwin::app
