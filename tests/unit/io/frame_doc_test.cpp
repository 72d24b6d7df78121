// The worked frames of docs/spi-protocol.md: this test parses the document's hex lines (it does
// not keep its own copy of the bytes), builds each frame from the values the document states in
// prose, and checks that the codec encodes exactly the documented bytes and decodes them back.
// The worked pipelined exchange is replayed through the board model: the fetch's MISO must be
// the answer to the request of the transfer before.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <vector>
#include <sstream>
#include <string>

#include "fakes/test_paths.h"
#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/encoder_emulator.h"
#include "hiltwin/io/frame.h"

namespace hiltwin::io {
namespace {

bool IsHexByte(const std::string& token) {
  auto hex = [](char ch) { return (ch >= '0' && ch <= '9') || (ch >= 'A' && ch <= 'F'); };
  return token.size() == 2 && hex(token[0]) && hex(token[1]);
}

/// Lines of the form "name: 12 hex bytes" (std::regex is avoided: GCC 12 warns inside it
/// under the sanitizers).
std::map<std::string, FrameBytes> ReadWorkedFrames() {
  std::ifstream file(HILTWIN_SPI_PROTOCOL_DOC);
  EXPECT_TRUE(file.good()) << "cannot read " << HILTWIN_SPI_PROTOCOL_DOC;
  std::map<std::string, FrameBytes> frames;
  std::string line;
  while (std::getline(file, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos || colon == 0) continue;
    const std::string name = line.substr(0, colon);
    bool name_ok = true;
    for (const char ch : name) {
      name_ok = name_ok && ((ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '-' || ch == '_');
    }
    if (!name_ok) continue;
    std::istringstream rest(line.substr(colon + 1));
    std::vector<std::string> tokens;
    std::string token;
    while (rest >> token) tokens.push_back(token);
    if (tokens.size() != kFrameBytes) continue;
    FrameBytes bytes{};
    bool all_hex = true;
    for (std::size_t i = 0; i < kFrameBytes; ++i) {
      all_hex = all_hex && IsHexByte(tokens[i]);
      if (all_hex) bytes[i] = static_cast<std::uint8_t>(std::stoul(tokens[i], nullptr, 16));
    }
    if (all_hex) frames[name] = bytes;
  }
  return frames;
}

struct Case {
  const char* name;
  Direction direction;
  Image host_image;
  Frame frame;
};

/// The worked pipelined exchange: request transfer (ALL 3) and fetch transfer (NOOP 4).
void AddExchangeCases(std::vector<Case>& cases) {
  Frame f;
  f.opcode = Opcode::kAll;
  f.sequence = 3;
  f.enc = {EncWord{100, false}, EncWord{-100, false}, EncWord{0, false}, EncWord{0, false}};
  cases.push_back({"exchange-request-mosi", Direction::kRequest, Image::kIcoboardInverse, f});
  f = Frame{};
  f.sequence = 2;
  f.status = kStatusInitialised;
  cases.push_back({"exchange-request-miso", Direction::kAnswer, Image::kIcoboardInverse, f});
  f = Frame{};
  f.sequence = 4;
  cases.push_back({"exchange-fetch-mosi", Direction::kRequest, Image::kIcoboardInverse, f});
  f = Frame{};
  f.opcode = Opcode::kAll;
  f.sequence = 3;
  f.status = kStatusInitialised;
  f.pwm = {PwmWord{1024, false, false}, PwmWord{512, true, false}, PwmWord{0, false, false},
           PwmWord{2047, false, false}};
  cases.push_back({"exchange-fetch-miso", Direction::kAnswer, Image::kIcoboardInverse, f});
}

std::vector<Case> Cases() {
  std::vector<Case> cases;
  Frame f;
  f.opcode = Opcode::kInit;
  f.sequence = 1;
  f.init_request = {250'000, ClockDividerForStep(250'000)};
  cases.push_back({"init-request-twin", Direction::kRequest, Image::kIcoboardInverse, f});
  f = Frame{};
  f.opcode = Opcode::kInit;
  f.sequence = 1;
  f.status = kStatusInitialised;
  f.init_answer = {1, 4, kIdentityIcoboardInverse, 4};
  cases.push_back({"init-answer-icoboard_inverse", Direction::kAnswer, Image::kIcoboardInverse, f});
  f = Frame{};
  f.opcode = Opcode::kInit;
  f.sequence = 1;
  f.init_request = {1'000'000, 0};
  cases.push_back({"init-request-ecs", Direction::kRequest, Image::kIcoboard, f});
  f = Frame{};
  f.opcode = Opcode::kInit;
  f.sequence = 1;
  f.status = kStatusInitialised;
  f.init_answer = {1, 4, kIdentityIcoboard, 0};
  cases.push_back({"init-answer-icoboard", Direction::kAnswer, Image::kIcoboard, f});
  f = Frame{};
  f.opcode = Opcode::kAll;
  f.sequence = 2;
  f.pwm = {PwmWord{1024, false, false}, PwmWord{2048, true, true}, PwmWord{0, false, false},
           PwmWord{2047, false, false}};
  cases.push_back({"all-request-ecs", Direction::kRequest, Image::kIcoboard, f});
  f = Frame{};
  f.opcode = Opcode::kAll;
  f.sequence = 2;
  f.status = kStatusInitialised;
  f.enc = {EncWord{8191, false}, EncWord{-8192, false}, EncWord{-1, true}, EncWord{0, false}};
  cases.push_back({"all-answer-ecs", Direction::kAnswer, Image::kIcoboard, f});
  f = Frame{};
  f.opcode = Opcode::kAll;
  f.sequence = 2;
  f.enc = {EncWord{100, false}, EncWord{-100, false}, EncWord{8191, false}, EncWord{-8192, true}};
  cases.push_back({"all-request-twin", Direction::kRequest, Image::kIcoboardInverse, f});
  f = Frame{};
  f.opcode = Opcode::kAll;
  f.sequence = 2;
  f.status = kStatusInitialised | kStatusPulseLimit;
  f.pwm = {PwmWord{1024, false, false}, PwmWord{2047, true, false}, PwmWord{0, false, true},
           PwmWord{512, false, false}};
  cases.push_back({"all-answer-twin", Direction::kAnswer, Image::kIcoboardInverse, f});
  f = Frame{};
  f.opcode = Opcode::kPwm2;
  f.sequence = 3;
  f.status = kStatusInitialised;
  f.pwm[2] = PwmWord{300, true, false};
  cases.push_back({"pwm2-answer-twin", Direction::kAnswer, Image::kIcoboardInverse, f});
  f = Frame{};
  f.opcode = Opcode::kTest;
  f.sequence = 4;
  f.raw = {0xDE, 0xAD, 0xBE, 0xEF, 0x01, 0x23, 0x45, 0x67};
  cases.push_back({"test-request", Direction::kRequest, Image::kIcoboardInverse, f});
  f = Frame{};
  cases.push_back({"noop-request", Direction::kRequest, Image::kIcoboardInverse, f});
  AddExchangeCases(cases);
  return cases;
}

TEST(SpiProtocolDoc, WorkedFramesMatchTheCodec) {
  const auto documented = ReadWorkedFrames();
  const auto cases = Cases();
  ASSERT_EQ(documented.size(), cases.size()) << "the document lists a frame this test does not know";
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const auto it = documented.find(c.name);
    ASSERT_NE(it, documented.end()) << "missing from docs/spi-protocol.md";
    FrameBytes encoded;
    ASSERT_EQ(Encode(c.frame, c.direction, c.host_image, encoded), FrameError::kOk);
    EXPECT_EQ(encoded, it->second);
    Frame decoded;
    ASSERT_EQ(Decode(it->second, c.direction, c.host_image, decoded), FrameError::kOk);
    FrameBytes again;
    ASSERT_EQ(Encode(decoded, c.direction, c.host_image, again), FrameError::kOk);
    EXPECT_EQ(again, it->second);
  }
  // The identity sits at byte 4 of the INIT answers, 11 for the ECS image as in the seed.
  EXPECT_EQ(documented.at("init-answer-icoboard")[4], 11);
  EXPECT_EQ(documented.at("init-answer-icoboard_inverse")[4], kIdentityIcoboardInverse);
}

/// The duties of the worked exchange on the twin board's PWM inputs.
class WorkedDuties final : public PwmSignalSource {
 public:
  void DutyAt(std::int64_t /*t_ns*/, std::array<double, kChannels>& duty_out) noexcept override {
    duty_out = {0.5, -0.25, 0.0, 1.0};
  }
};

TEST(SpiProtocolDoc, WorkedExchangeIsWhatTheBoardModelSends) {
  const auto documented = ReadWorkedFrames();
  for (const char* name : {"exchange-request-mosi", "exchange-request-miso", "exchange-fetch-mosi",
                           "exchange-fetch-miso"}) {
    ASSERT_EQ(documented.count(name), 1U) << name << " missing from docs/spi-protocol.md";
  }
  EmulatedFpga board(Image::kIcoboardInverse);
  WorkedDuties duties;
  board.SetPwmSource(&duties);
  // The twin's INIT at 4 kHz (sequence 1) and its fetch (NOOP 2), as the driver sends them.
  Frame init;
  init.opcode = Opcode::kInit;
  init.sequence = 1;
  init.init_request = {250'000, ClockDividerForStep(250'000)};
  Frame fetch;
  fetch.sequence = 2;
  FrameBytes mosi{};
  FrameBytes miso{};
  ASSERT_EQ(Encode(init, Direction::kRequest, Image::kIcoboardInverse, mosi), FrameError::kOk);
  board.Exchange(mosi, miso);
  ASSERT_EQ(Encode(fetch, Direction::kRequest, Image::kIcoboardInverse, mosi), FrameError::kOk);
  board.Exchange(mosi, miso);
  ASSERT_TRUE(board.initialised());
  // Request transfer: MISO answers the fetch before; fetch transfer: MISO answers the request.
  board.Exchange(documented.at("exchange-request-mosi"), miso);
  EXPECT_EQ(miso, documented.at("exchange-request-miso"));
  board.Exchange(documented.at("exchange-fetch-mosi"), miso);
  EXPECT_EQ(miso, documented.at("exchange-fetch-miso"));
  // The answer echoes the request's opcode and sequence (bytes 0-1); the fetch is NOOP 4.
  EXPECT_EQ(miso[0], documented.at("exchange-request-mosi")[0]);
  EXPECT_EQ(miso[1], documented.at("exchange-request-mosi")[1]);
  EXPECT_EQ(documented.at("exchange-fetch-mosi")[1], documented.at("exchange-request-mosi")[1] + 1);
}

}  // namespace
}  // namespace hiltwin::io
