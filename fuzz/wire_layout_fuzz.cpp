// The wire backend's shared-memory segment (/dev/shm/hiltwin-wire-NAME, io/wire_bus.h): what
// another process (a crashed one, another version, a stray writer) may have left in it. Each
// input becomes the segment's bytes; then both sides attach and exchange frames. WireBus's
// constructor documents std::invalid_argument and std::runtime_error (a segment it cannot use);
// transfers are noexcept. Anything else, a crash, a sanitizer report or a hang is a finding.
//
// Input: byte 0 chooses when the bytes land (0: in a fresh segment before either side
// attaches; 1: after the ECS attached, before the twin does; 2 and 3: after both attached,
// between transfers); the rest is the segment, zero-padded or cut to its size.
//
// The segment's size is private to wire_bus.cpp: it is taken from the file the first WireBus
// creates. The bytes are written through this process's own mmap of /dev/shm/hiltwin-wire-NAME.
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "fuzz_util.h"
#include "hiltwin/io/frame.h"
#include "hiltwin/io/wire_bus.h"

namespace {

using namespace hiltwin::io;

const std::string& WireName() {
  static const std::string name = "fuzz-" + std::to_string(::getpid());
  return name;
}

std::string ShmPath() { return "/dev/shm" + WireBus::SegmentName(WireName()); }

/// The segment's size, learnt once from a segment the real code made.
std::size_t SegmentSize() {
  static const std::size_t size = [] {
    WireBus::Unlink(WireName());
    std::size_t bytes = 0;
    {
      WireBus probe(WireName(), Image::kIcoboard);
      struct stat info {};
      if (::stat(ShmPath().c_str(), &info) != 0) std::abort();
      bytes = static_cast<std::size_t>(info.st_size);
    }
    WireBus::Unlink(WireName());
    return bytes;
  }();
  return size;
}

/// Writes the input over the segment (creating it at its real size when absent).
void Overwrite(const std::uint8_t* data, std::size_t size) {
  const std::size_t bytes = SegmentSize();
  const int fd = ::open(ShmPath().c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0 || ::ftruncate(fd, static_cast<off_t>(bytes)) != 0) std::abort();
  void* map = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  if (map == MAP_FAILED) std::abort();
  auto* target = static_cast<std::uint8_t*>(map);
  std::memset(target, 0, bytes);
  std::memcpy(target, data, std::min(size, bytes));
  // The first word is the layout state: anything but 0 (fresh) or 2 (ready) makes an attaching
  // side wait a bounded second for a layout that never finishes, which only slows the fuzzer
  // down (every random word would), so the others are folded onto those two.
  std::uint32_t state = 0;
  std::memcpy(&state, target, sizeof state);
  if (state != 0 && state != 2) {
    state = (state & 1U) != 0 ? 0U : 2U;
    std::memcpy(target, &state, sizeof state);
  }
  ::munmap(map, bytes);
}

FrameBytes Make(const Frame& frame, Image image) {
  FrameBytes bytes{};
  if (Encode(frame, Direction::kRequest, image, bytes) != FrameError::kOk) std::abort();
  return bytes;
}

/// INIT, then a few ALL exchanges with moving values, on one side.
void Exchange(WireBus& bus, Image image, int round) {
  FrameBytes request_miso{};
  FrameBytes answer{};
  const FrameBytes noop = Make(Frame{}, image);
  if (round == 0) {
    Frame init{};
    init.opcode = Opcode::kInit;
    init.init_request = InitRequest{250'000, image == Image::kIcoboard ? 0U : 100U};
    (void)bus.TransferPair(Make(init, image), request_miso, noop, answer);
  }
  Frame all{};
  all.opcode = Opcode::kAll;
  all.sequence = static_cast<std::uint8_t>(round);
  for (std::size_t c = 0; c < kChannels; ++c) {
    all.pwm[c] = PwmWord{static_cast<std::uint16_t>(400 * (c + 1)), (round & 1) != 0, c == 0};
    all.enc[c] = EncWord{static_cast<std::int16_t>(round * 37 * static_cast<int>(c + 1)), false};
  }
  (void)bus.TransferPair(Make(all, image), request_miso, noop, answer);
  (void)bus.Transfer(noop, answer);
  (void)bus.Poll();
  (void)bus.PeerStatus();
  EncoderPeriod period{};
  (void)bus.ReadEncoderPeriod(static_cast<std::uint64_t>(round), period);
}

std::unique_ptr<WireBus> Attach(Image side) {
  try {
    return std::make_unique<WireBus>(WireName(), side);
  } catch (const std::invalid_argument&) {
  } catch (const std::runtime_error&) {
  }
  HILTWIN_FUZZ_UNDOCUMENTED("WireBus::WireBus")
  return nullptr;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const unsigned when = data[0] & 3U;
  ++data;
  --size;
  (void)SegmentSize();
  WireBus::Unlink(WireName());
  if (when == 0) Overwrite(data, size);
  std::unique_ptr<WireBus> ecs = Attach(Image::kIcoboard);
  if (when == 1) Overwrite(data, size);
  std::unique_ptr<WireBus> twin = Attach(Image::kIcoboardInverse);
  for (int round = 0; round < 4; ++round) {
    if (when >= 2 && round == static_cast<int>(when) - 1) Overwrite(data, size);
    if (twin) Exchange(*twin, Image::kIcoboardInverse, round);
    if (ecs) Exchange(*ecs, Image::kIcoboard, round);
  }
  if (ecs) ecs->AnnounceStop(StopCause::kFinished);
  twin.reset();
  ecs.reset();
  WireBus::Unlink(WireName());  // whatever pid the bytes named as a live peer
  return 0;
}
