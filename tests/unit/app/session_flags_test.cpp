// The session flags are read once, at the command line (cli/session_flags.h): a command line
// parsed by CLI11, as `run`, `trace` and `ecs` parse it, gives typed settings equal to the
// expected values (the documented defaults resolved there too), and a bad value fails there,
// with the flag's name and the message the run used to give. Below the command layer only typed
// values exist: the static_asserts pin the types the runs take.
#include "session_flags.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <type_traits>
#include <vector>

#include "hiltwin/runs/command.h"
#include "hiltwin/runs/tune.h"

namespace hiltwin::app {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

static_assert(std::is_same_v<decltype(SessionSettings::io), io::BackendSpec>);
static_assert(std::is_same_v<decltype(SessionSettings::clock), runtime::ClockKind>);
static_assert(std::is_same_v<decltype(SessionSettings::overrun_policy), scheduler::OverrunPolicy>);
static_assert(std::is_same_v<decltype(SessionSettings::on_violation), qos::ViolationPolicy>);
static_assert(std::is_same_v<decltype(SessionSettings::qos_rules), std::vector<qos::RuleSpec>>);
static_assert(std::is_same_v<decltype(SessionSettings::overrun_injections),
                             std::vector<runtime::OverrunInjection>>);
static_assert(std::is_same_v<decltype(TwinRunOptions::link_faults),
                             std::vector<io::LinkFaultInjection>>);
static_assert(std::is_same_v<decltype(TuneOptions::clock), runtime::ClockKind>);

/// CLI11 parses `args` into `app` (it takes them last first, as its own main does).
void Parse(CLI::App& app, std::vector<std::string> args) {
  std::reverse(args.begin(), args.end());
  app.parse(args);
}

/// `hiltwin COMMAND ARGS`'s typed options, as cmd_run.cpp and cmd_trace.cpp make them.
TwinRunOptions TwinOptionsOf(const std::vector<std::string>& args, const char* command = "run") {
  CLI::App app;
  TwinRunFlags flags;
  AddTwinRunFlags(app, flags);
  Parse(app, args);
  return TwinRunOptionsFrom(flags, command);
}

/// The message of the usage error (exit 2) reading `args` gives.
std::string UsageErrorOf(const std::vector<std::string>& args, const char* command = "run") {
  try {
    static_cast<void>(TwinOptionsOf(args, command));
  } catch (const CommandError& e) {
    EXPECT_EQ(e.code(), ExitCode::kUsage) << e.what();
    return e.what();
  }
  return "no error";
}

TEST(SessionFlags, EveryTextBecomesItsTypedValue) {
  const TwinRunOptions o = TwinOptionsOf(
      {"--rate", "2000", "--duration", "3", "--io", "wire:pair-1", "--clock", "virtual",
       "--overrun-policy", "skip", "--on-violation", "abort", "--qos", "9:10", "--max-misses",
       "2:10", "--max-consecutive-misses", "3", "--max-miss-pct", "5", "--deadline-us", "400",
       "--inject-overrun", "at=20,count=5,extra-us=600", "--board-image", "icoboard",
       "--inject-link-fault", "drop-answer,at=40,count=3", "--input-rate", "500", "--no-progress"});
  const SessionSettings& s = o.session;
  EXPECT_EQ(s.io.kind, io::BackendSpec::Kind::kWire);
  EXPECT_EQ(s.io.argument, "pair-1");
  EXPECT_EQ(s.io_text, "wire:pair-1");
  EXPECT_EQ(s.clock, runtime::ClockKind::kVirtual);
  EXPECT_EQ(s.overrun_policy, scheduler::OverrunPolicy::kSkip);
  EXPECT_EQ(s.on_violation, qos::ViolationPolicy::kAbort);
  // In the report's order; --qos replaces the default (m,k) rule.
  const std::vector<qos::RuleSpec> rules = {
      qos::MakeMissRatioRule(5.0), qos::MakeMkRule(9, 10), qos::MakeMissesInWindowRule(2, 10),
      qos::MakeConsecutiveMissesRule(3)};
  EXPECT_EQ(s.qos_rules, rules);
  EXPECT_EQ(s.deadline_ns, 400'000);
  ASSERT_EQ(s.overrun_injections.size(), 1U);
  EXPECT_EQ(runtime::Describe(s.overrun_injections[0]), "at=20,count=5,extra-us=600");
  EXPECT_EQ(s.board_image, io::Image::kIcoboard);
  EXPECT_FALSE(s.progress);
  EXPECT_EQ(s.rate_hz, 2000.0);
  EXPECT_EQ(s.duration_s, 3.0);
  ASSERT_EQ(o.link_faults.size(), 1U);
  EXPECT_EQ(io::Describe(o.link_faults[0]), "drop-answer,at=40,count=3");
  EXPECT_EQ(o.controller_rate_hz, 500.0);
}

TEST(SessionFlags, WithoutFlagsTheDocumentedDefaultsAreResolvedThere) {
  const TwinRunOptions o = TwinOptionsOf({});
  const SessionSettings& s = o.session;
  EXPECT_EQ(s.io.kind, io::BackendSpec::Kind::kMock);
  EXPECT_EQ(s.io_text, "mock");
  EXPECT_EQ(s.clock, runtime::ClockKind::kRealtime);
  EXPECT_EQ(s.overrun_policy, scheduler::OverrunPolicy::kCatchUp);
  EXPECT_EQ(s.on_violation, qos::ViolationPolicy::kFlag);
  // Miss ratio < 1 % and (3,4)-firm: a 4 kHz twin under the thesis's 1 kHz controller.
  EXPECT_EQ(s.qos_rules, qos::DefaultRulesFor(4000.0, 1000.0));
  EXPECT_EQ(s.deadline_ns, 0);
  EXPECT_FALSE(s.board_image.has_value());
  EXPECT_TRUE(s.overrun_injections.empty());
  EXPECT_TRUE(s.progress);
  EXPECT_EQ(s.wait_peer_s, kDefaultWaitPeerS);
  EXPECT_TRUE(o.link_faults.empty());
  EXPECT_EQ(o.controller_rate_hz, 1000.0);
  // Below 1 kHz the controller runs at the twin's rate, and the default rule follows it.
  const TwinRunOptions slow = TwinOptionsOf({"--rate", "500"});
  EXPECT_EQ(slow.controller_rate_hz, 500.0);
  EXPECT_EQ(slow.session.qos_rules, qos::DefaultRulesFor(500.0, 500.0));
}

TEST(SessionFlags, TheControllerJudgesItsDefaultRuleAtItsOwnRate) {
  CLI::App app;
  SessionFlags flags;
  flags.rate_hz = 1000.0;  // `ecs`'s default, set before the flags are added, as cmd_ecs.cpp does
  AddSessionFlags(app, flags);
  Parse(app, {"--io", "spidev:/dev/spidev0.0", "--max-miss-pct", "0"});
  const SessionSettings s =
      SessionSettingsFrom(flags, {"ecs", "twin", "hiltwin run", 1000.0, "controller"});
  EXPECT_EQ(s.io.kind, io::BackendSpec::Kind::kSpidev);
  EXPECT_EQ(s.io.argument, "/dev/spidev0.0");
  EXPECT_EQ(s.qos_rules, (std::vector<qos::RuleSpec>{qos::MakeMkRule(1, 2)}));  // never 2 in a row
}

TEST(SessionFlags, ABadValueFailsAtTheCommandLineNamingItsFlag) {
  EXPECT_THAT(UsageErrorOf({"--io", "carrier-pigeon"}),
              HasSubstr("--io: I/O backend 'carrier-pigeon': unknown backend"));
  EXPECT_THAT(UsageErrorOf({"--qos", "11:10"}),
              AllOf(HasSubstr("QoS rules: "), HasSubstr("11:10"),
                    HasSubstr("(see 'hiltwin run --help' and docs/qos.md)")));
  EXPECT_THAT(UsageErrorOf({"--max-misses", "two"}, "trace"),
              AllOf(HasSubstr("QoS rules: "), HasSubstr("(see 'hiltwin trace --help'")));
  EXPECT_THAT(UsageErrorOf({"--max-miss-pct", "-5"}), HasSubstr("QoS rules: "));
  EXPECT_THAT(UsageErrorOf({"--inject-overrun", "at=5"}),
              AllOf(HasSubstr("--inject-overrun 'at=5'"), HasSubstr("extra-us")));
  EXPECT_THAT(UsageErrorOf({"--inject-link-fault", "melt,at=3"}),
              HasSubstr("--inject-link-fault 'melt,at=3'"));
  EXPECT_THAT(UsageErrorOf({"--deadline-us", "nan"}),
              HasSubstr("--deadline-us: must be between 0 (= the period) and the period (250 us)"));
  EXPECT_THAT(UsageErrorOf({"--deadline-us", "250.1"}), HasSubstr("--deadline-us: "));
  // The numbers are checked before anything derives from them: the rate, not a QoS rule.
  EXPECT_THAT(UsageErrorOf({"--rate", "0"}), HasSubstr("--rate: "));
  EXPECT_THAT(UsageErrorOf({"--input-rate", "-5"}), HasSubstr("--input-rate -5: "));
  // Issue 34: a given 0 was taken for "not given" and ran at the default rate.
  EXPECT_THAT(UsageErrorOf({"--input-rate", "0"}),
              HasSubstr("--input-rate 0: the controller rate must be positive and not above "
                        "--rate (4000 Hz)"));
  EXPECT_THAT(UsageErrorOf({"--input-rate", "nan"}), HasSubstr("--input-rate nan: "));
  EXPECT_EQ(UsageErrorOf({"--deadline-us", "250"}), "no error");  // exactly the period
}

TEST(SessionFlags, NinthInjectionIsRefusedAtTheCommandLine) {
  std::vector<std::string> args;
  for (int i = 0; i < 9; ++i) args.insert(args.end(), {"--inject-overrun", "every=10,extra-us=1"});
  EXPECT_THAT(UsageErrorOf(args), HasSubstr("--inject-overrun "));
}

}  // namespace
}  // namespace hiltwin::app
