// The other process of the wire integration tests.
//   hiltwin_io_wire_peer twin NAME RATE_HZ   twin side: encoder position = PWM value of the same
//                                            channel (a static-gain plant), so the ECS sees its own
//                                            PWM come back through the encoder path
//   hiltwin_io_wire_peer ecs NAME RATE_HZ    ECS side: PWM channel c = 100·(c+1)
// Prints "ready" once attached and initialised, then runs until SIGTERM/SIGINT (or SIGKILL, which
// the tests use to simulate a crash).
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "hiltwin/io/icoboard.h"
#include "hiltwin/io/wire_bus.h"
#include "hiltwin/kernel_glue/clock.h"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
  using namespace hiltwin;
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s twin|ecs NAME RATE_HZ\n", argv[0]);
    return 2;
  }
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);
  const std::string side = argv[1];
  const double rate_hz = std::atof(argv[3]);
  const std::int64_t period_ns = kernel_glue::PeriodNsFromRateHz(rate_hz);
  const io::Image image = side == "ecs" ? io::Image::kIcoboard : io::Image::kIcoboardInverse;
  io::WireBus bus(argv[2], image);
  kernel_glue::MonotonicClock clock;
  std::int64_t release_ns = clock.NowNs();
  if (image == io::Image::kIcoboardInverse) {
    io::IcoBoardInverse driver(bus);
    if (!driver.Init(period_ns).ok) return 5;
    std::printf("ready\n");
    std::fflush(stdout);
    io::TwinInputs in;
    std::array<std::int32_t, io::kChannels> out{};
    while (g_stop == 0) {
      (void)driver.Exchange(out, in);
      out = in.pwm;  // the plant: position follows the PWM value, output one period later
      release_ns += period_ns;
      clock.SleepUntilNs(release_ns);
    }
  } else {
    io::IcoBoard driver(bus);
    if (!driver.Init(period_ns).ok) return 5;
    std::printf("ready\n");
    std::fflush(stdout);
    io::EcsInputs in;
    while (g_stop == 0) {
      (void)driver.Exchange({100, 200, 300, 400}, in);
      release_ns += period_ns;
      clock.SleepUntilNs(release_ns);
    }
  }
  return 0;
}
