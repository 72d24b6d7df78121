// Issue 37, "Done when", end to end through the `hiltwin` binary as a user runs it:
// - every kind of controller (the built-in pid, lib:my_pd.so, 20sim:pid20sim, fmu:pid.fmu)
//   closes the thesis's 2.5 m loop against the twin in lockstep (`hil --clock virtual`, exact):
//   exit 0, both verdicts PASS, the thesis's bound, the figures of its law (the three PID
//   routes: the built-in one's, as doubles), and the report naming the code that ran (kind,
//   name, file, SHA-256 as `sha256sum` computes it) (ControllerKindsLoop); a relative path is
//   reported absolute (ControllerFile);
// - every malformed controller library is refused or stopped with its exit code and a message
//   that says what is wrong (ControllerMalformed, a table, on the mock board); in the loop, a
//   step error and a refused library end the pair with the twin safe (ControllerStopped); a
//   library that dereferences NULL kills its ECS with SIGSEGV and the twin goes safe as for any
//   killed ECS (ControllerCrash).
// The libraries are built from C in this build (tests/controllers), the FMU too (tests/fmus).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "fakes/process.h"
#include "fakes/test_paths.h"
#include "fakes/wire_scratch.h"

// Named: the suite's unity batch shares one anonymous namespace with hil_cli_test.cpp's.
namespace controller_kinds_test {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;
using Json = nlohmann::json;

std::string ControllerLib(const std::string& name) {
  return std::string(HILTWIN_TEST_CONTROLLER_DIR) + "/" + name + ".so";
}
std::string PidFmu() { return std::string(HILTWIN_TEST_FMU_DIR) + "/pid.fmu"; }
std::string Pid20simDir() {
  return (fs::path(HILTWIN_SOURCE_DIR) / "models/controllers/pid20sim").lexically_normal().string();
}

Json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return Json::parse(in);
}

/// What `sh -c script` prints, its trailing newline cut; fails the test when it fails.
std::string Shell(const std::string& script) {
  const auto r = hiltwin::test::Run({"/bin/sh", "-c", script});
  EXPECT_EQ(r.exit_code, 0) << script << ": " << r.err;
  std::string out = r.out;
  while (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

/// The SHA-256 of a file as `sha256sum` computes it: an independent tool, not hiltwin's own.
std::string Sha256sum(const std::string& file) {
  return Shell("sha256sum '" + file + "' | cut -d' ' -f1");
}

/// The SHA-256 docs/20sim.md gives a 20-sim controller's folder: that of the listing
/// "SHA-256  name" of its .cpp, .c, .h and .hpp files in name order, one per line, which is
/// what `sha256sum` prints for them.
std::string FolderSha256sum(const std::string& dir) {
  return Shell("cd '" + dir + "' && ls *.cpp *.c *.h *.hpp 2>/dev/null | LC_ALL=C sort | " +
               "xargs sha256sum | sha256sum | cut -d' ' -f1");
}

/// One `hil --clock virtual` run: what it printed and its combined report.
struct HilRun {
  hiltwin::test::RunResult result;
  Json report;
};

class ControllerLockstep : public ::testing::Test {
 protected:
  void TearDown() override {
    EXPECT_FALSE(fs::exists(scratch_.SegmentPath()))
        << "shared memory left behind: " << scratch_.SegmentPath();
  }
  /// `hiltwin hil --clock virtual` on this test's wire with `extra`, its report in NAME.json;
  /// `before`, if given, is the command that runs it (`env VAR=VALUE`).
  HilRun Hil(const std::string& name, const std::vector<std::string>& extra,
             const std::vector<std::string>& before = {}) const {
    std::vector<std::string> argv = before;
    argv.insert(argv.end(),
                {HILTWIN_BINARY, "hil", "--clock", "virtual", "--wire", scratch_.WireName(),
                 "--no-progress", "--report", scratch_.Path(name + ".json")});
    argv.insert(argv.end(), extra.begin(), extra.end());
    HilRun run{hiltwin::test::Run(argv, 120'000), Json()};
    const std::string report = scratch_.Path(name + ".json");
    if (fs::exists(report)) run.report = ReadJson(report);
    return run;
  }
  /// The built-in PID's run, once per test program.
  const HilRun& PidRun() const {
    static const HilRun pid = Hil("pid", {"--controller", "pid"});
    return pid;
  }

  hiltwin::test::WireScratch scratch_{"ctlkinds"};
};

// --- Each kind closes the thesis's loop ---------------------------------------------------

/// A kind of controller and what its run must show.
struct Kind {
  std::string spec;    ///< --controller
  std::string kind;    ///< the report's controller.kind
  std::string name;    ///< the report's controller.name
  std::string file;    ///< the report's controller.file ("" for the built-in one)
  std::string sha256;  ///< its content_sha256, by an independent tool ("" for the built-in)
  bool pid_law;        ///< the same law as the built-in pid: its figures exactly
};

/// The kind a test's parameter names (built in the test: the paths are found at run time).
Kind KindNamed(const std::string& label) {
  if (label == "lib_my_pd") {
    const std::string my_pd = ControllerLib("my_pd");
    return {"lib:" + my_pd, "C ABI shared library", "my_pd", my_pd, Sha256sum(my_pd), false};
  }
  if (label == "twentysim_pid20sim") {
    return {"20sim:pid20sim",
            "20-sim C++ class",
            "pid20sim",
            Pid20simDir(),
            FolderSha256sum(Pid20simDir()),
            true};
  }
  if (label == "fmu_pid") {
    // Its name is the modelDescription's modelName (tests/fmus/pid.xml.in).
    return {"fmu:" + PidFmu(), "FMI 2.0 co-simulation", "PositionPid",
            PidFmu(),          Sha256sum(PidFmu()),     true};
  }
  return {"pid", "built-in", "pid", "", "", true};
}

class ControllerKindsLoop : public ControllerLockstep,
                            public ::testing::WithParamInterface<const char*> {};

/// One encoder count in metres (WheelGeometryOf(DefaultRelbotParams()): 0.0785 mm).
constexpr double kCountM = 7.85e-5;
// The thesis's bound (§7.2, appendix E): each wheel's error below 3 mm throughout and at rest.
constexpr double kThesisBoundM = 3e-3;

TEST_P(ControllerKindsLoop, ClosesTheThesisLoopAgainstTheTwinWithBothVerdictsPass) {
  const Kind kind = KindNamed(GetParam());
  const HilRun run = Hil("kind", {"--controller", kind.spec});
  ASSERT_EQ(run.result.exit_code, 0) << run.result.out << run.result.err;
  const Json& hil = run.report;
  EXPECT_EQ(hil["exit_code"], 0);
  EXPECT_EQ(hil["ecs"]["verdict"], "PASS");
  EXPECT_EQ(hil["twin"]["verdict"], "PASS");
  EXPECT_EQ(hil["ecs"]["stop_reason"], "finished");
  EXPECT_EQ(hil["ecs"]["cycles_run"], 12'000);
  EXPECT_EQ(hil["link_errors"], 0) << hil["link_error_parts"].dump();
  const double max_left_m = hil["tracking_error_max_m"]["left"].get<double>();
  const double max_right_m = hil["tracking_error_max_m"]["right"].get<double>();
  const double rms_m = hil["tracking_error_rms_m"].get<double>();
  const double final_m = hil["final_error_m"].get<double>();
  EXPECT_LT(max_left_m, kThesisBoundM);
  EXPECT_LT(max_right_m, kThesisBoundM);
  EXPECT_LT(final_m, kThesisBoundM);
  EXPECT_LT(final_m, kCountM);  // at rest on the count nearest 2.5 m

  if (kind.pid_law) {
    // The figures measured when the kinds were merged; a change of law moves them by far more
    // than the half micrometre allowed.
    EXPECT_NEAR(max_left_m, 1.059e-3, 0.5e-6);
    EXPECT_NEAR(rms_m, 0.585e-3, 0.5e-6);
    if (kind.spec != "pid") {
      // The same law through another route: the built-in PID's figures, as doubles.
      const Json& pid = PidRun().report;
      ASSERT_EQ(PidRun().result.exit_code, 0) << PidRun().result.err;
      EXPECT_EQ(hil["ecs"]["tracking"], pid["ecs"]["tracking"]);
      for (const char* key : {"tracking_error_max_m", "tracking_error_rms_m", "final_error_m"}) {
        EXPECT_EQ(hil[key], pid[key]) << key;
      }
    }
  } else {
    // my_pd: a PD (no integral, the derivative on the wheel), with figures of its own.
    EXPECT_NEAR(max_left_m, 2.486e-3, 0.5e-6);
    EXPECT_NEAR(rms_m, 1.214e-3, 0.5e-6);
  }

  // The report names the code that produced the figures, and so does the summary.
  const Json& c = hil["controller"];
  EXPECT_EQ(c["spec"], kind.spec);
  EXPECT_EQ(c["kind"], kind.kind);
  EXPECT_EQ(c["name"], kind.name);
  EXPECT_EQ(c["file"], kind.file);
  EXPECT_EQ(c["content_sha256"], kind.sha256);
  EXPECT_TRUE(c["fault"].is_null()) << c["fault"];
  EXPECT_EQ(hil["ecs"]["controller"], c);
  std::string line = "controller " + kind.spec + " (" + kind.kind + "): " + kind.name;
  if (!kind.file.empty()) line += "; " + kind.file + ", sha256 " + kind.sha256;
  EXPECT_THAT(run.result.out, HasSubstr(line + "\n"));
}

INSTANTIATE_TEST_SUITE_P(EveryKind, ControllerKindsLoop,
                         ::testing::Values("pid", "lib_my_pd", "twentysim_pid20sim", "fmu_pid"),
                         [](const auto& kind) { return std::string(kind.param); });

// --- The file a report names ----------------------------------------------------------

// A controller given by a relative path (the tutorial's `lib:./my_pd.so`): the spec as typed,
// the file absolute, so a report read elsewhere still says which file ran; lib and fmu alike.
class ControllerFile : public ::testing::TestWithParam<const char*> {
 protected:
  hiltwin::test::WireScratch scratch_{"ctlfile"};
};

TEST_P(ControllerFile, ARelativePathIsReportedAbsolute) {
  const bool lib = std::string(GetParam()) == "lib";
  const std::string dir = lib ? HILTWIN_TEST_CONTROLLER_DIR : HILTWIN_TEST_FMU_DIR;
  const std::string spec = lib ? "lib:./my_pd.so" : "fmu:./pid.fmu";
  const std::string report = scratch_.Path("ecs.json");
  const auto r = hiltwin::test::Run(
      {"/bin/sh", "-c",
       "cd '" + dir + "' && exec '" + HILTWIN_BINARY + "' ecs --no-progress --clock virtual " +
           "--duration 0.01 --controller " + spec + " --report '" + report + "'"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const std::string file = (fs::path(dir) / (lib ? "my_pd.so" : "pid.fmu")).lexically_normal();
  const Json ecs = ReadJson(report);
  EXPECT_EQ(ecs["controller"]["spec"], spec);
  EXPECT_EQ(ecs["controller"]["file"], file);
  EXPECT_EQ(ecs["controller"]["content_sha256"], Sha256sum(file));
  EXPECT_THAT(r.out, HasSubstr("controller file " + file + ", sha256 "));
}

INSTANTIATE_TEST_SUITE_P(LibAndFmu, ControllerFile, ::testing::Values("lib", "fmu"));

// --- Every malformed controller, with its exit code and message -------------------------

/// A library of tests/controllers and what `hiltwin ecs --controller lib:LIB` on the mock
/// board must end with.
struct Malformed {
  const char* library;
  int exit_code;
  std::string message;  ///< in stderr
  bool names_file;      ///< stderr gives the spec with the library's path
  std::string fault;    ///< the ECS report's controller.fault, whole; "" when it never ran
};

void PrintTo(const Malformed& m, std::ostream* out) { *out << m.library; }

/// Refused by the loader before the board opens: exit 2, the spec and what to do.
Malformed Refused(const char* library, const std::string& message) {
  return {library, 2, message, true, ""};
}
/// Refused by the controller map (the RELbot's default one) before the board opens; the
/// message ends naming the spec, so the library's path.
Malformed RefusedByTheMap(const char* library, const std::string& message) {
  return {library, 2, message, true, ""};
}
/// Stopped during the run with safe outputs: exit 1, a model fault, and the report's fault.
Malformed Stopped(const char* library, const std::string& message, const std::string& fault) {
  return {library, 1, message, true, fault};
}

class ControllerMalformed : public ::testing::TestWithParam<Malformed> {
 protected:
  hiltwin::test::WireScratch scratch_{"ctlbad"};
};

TEST_P(ControllerMalformed, EndsTheEcsWithItsExitCodeAndAMessageThatSaysWhat) {
  const Malformed& m = GetParam();
  const std::string library = ControllerLib(m.library);
  if (!fs::exists(library)) {  // foreign_machine: only where the build has a compiler for it
    GTEST_SKIP() << library << " is not built here (tests/controllers/CMakeLists.txt)";
  }
  const std::string report = scratch_.Path("ecs.json");
  const auto r = hiltwin::test::Run({HILTWIN_BINARY, "ecs", "--no-progress", "--clock", "virtual",
                                     "--duration", "0.05", "--controller", "lib:" + library,
                                     "--report", report});
  EXPECT_EQ(r.exit_code, m.exit_code) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr(m.message)) << r.out;
  if (m.names_file) {
    EXPECT_THAT(r.err, HasSubstr("lib:" + library)) << r.out;
  }
  if (m.fault.empty()) {
    EXPECT_FALSE(fs::exists(report)) << "refused before the run, yet a report";
    return;
  }
  const Json ecs = ReadJson(report);
  EXPECT_EQ(ecs["controller"]["fault"], Json::parse(m.fault));
  EXPECT_EQ(ecs["stop_reason"], "model_fault");
  EXPECT_EQ(ecs["final_state"], "safe_stop");
  EXPECT_EQ(ecs["outputs_safe"], true);
  // The summary line names the controller's own text as well.
  const Json fault = Json::parse(m.fault);
  EXPECT_THAT(r.out, HasSubstr("controller lib:" + library + " stopped at cycle " +
                               std::to_string(fault["cycle"].get<int>()) + ": " +
                               fault["kind"].get<std::string>()));
}

INSTANTIATE_TEST_SUITE_P(
    EveryWayALibraryIsWrong, ControllerMalformed,
    ::testing::Values(
        Refused("bad_abi_version",
                "built against controller ABI version 99, but this hiltwin speaks version 1"),
        Refused("bad_no_entry", "the library does not export the symbol hiltwin_controller"),
        Refused("bad_null_descriptor", "hiltwin_controller() returned NULL"),
        Refused("bad_null_step", "the descriptor's entry point step is NULL"),
        Refused("bad_duplicate_port",
                "inputs[3]: the input wheel_left_m is listed twice: give every input its own "
                "name"),
        Refused("bad_null_unit", "inputs[3] (wheel_right_m) has a NULL unit"),
        Refused("bad_no_outputs", "the controller has no outputs"),
        Refused("not_a_library", "cannot be loaded"),
        Refused("foreign_machine",
                "it was built for arm64 (aarch64), but this machine is x86-64 (amd64): build it "
                "here, or with a compiler for this machine"),
        Refused("fixed_step",
                "runs only at its own step of 0.002 s, but the ECS's period is 0.001 s: run the "
                "ECS at --rate 500, or regenerate the controller for this step"),
        RefusedByTheMap("bad_wrong_unit",
                        "the built-in RELbot controller map: encoder input 'wheel_right_m' is in "
                        "rad but the map gives it m: make the units agree (the map's unit, or "
                        "the controller's) (controller lib:"),
        Refused("bad_create_null", "its create() returned NULL"),
        Refused("bad_start_fails",
                "returned 3: start refused: the test library was built to refuse; the run "
                "did not start"),
        // Its third step (cycle 2) returns 1 with a last_error text.
        // The last line says why in the library's own words.
        Stopped("step_error",
                "stopped: its step returned an error (wheel runaway: the test library stops at "
                "its third step); the motors were stopped",
                R"({"kind": "error status", "output": "", "value": 0.0, "duty_limit": 0.0,
                    "reason": "wheel runaway: the test library stops at its third step",
                    "cycle": 2})"),
        Stopped("step_error_no_text",
                "stopped: its step returned an error (the controller's step() returned nonzero "
                "and it has no last_error text); the motors were stopped",
                R"({"kind": "error status", "output": "", "value": 0.0, "duty_limit": 0.0,
                    "reason": "the controller's step() returned nonzero and it has no )"
                R"(last_error text", "cycle": 2})"),
        Stopped("step_nan",
                "stopped: output 'duty_right' is not finite (NaN or infinite); the motors were "
                "stopped",
                R"({"kind": "not finite", "output": "duty_right", "value": "nan",
                    "duty_limit": 1.0, "reason": "", "cycle": 0})"),
        Stopped("step_duty_1_5",
                "stopped: output 'duty_left' asks for a duty beyond its duty_limit 1; the motors "
                "were stopped",
                R"({"kind": "beyond duty_limit", "output": "duty_left", "value": 1.5,
                    "duty_limit": 1.0, "reason": "", "cycle": 0})")),
    [](const auto& row) { return std::string(row.param.library); });

// --- A controller stopped in the loop ---------------------------------------------------

// In the closed loop against the twin: a step error stops the controller with safe outputs,
// the twin ends cleanly as its peer stopped, and hil's combined report names the controller and
// its fault, the library's own text included.
class ControllerStopped : public ControllerLockstep {};

TEST_F(ControllerStopped, AStepErrorEndsThePairWithTheLibrarysTextInTheCombinedReport) {
  const std::string library = ControllerLib("step_error");
  const HilRun run = Hil("stopped", {"--controller", "lib:" + library});
  EXPECT_EQ(run.result.exit_code, 1) << run.result.out << run.result.err;
  const Json& hil = run.report;
  ASSERT_TRUE(hil.is_object()) << run.result.out << run.result.err;
  EXPECT_EQ(hil["exit_code"], 1);
  EXPECT_EQ(hil["controller"]["spec"], "lib:" + library);
  EXPECT_EQ(hil["controller"]["fault"]["kind"], "error status");
  EXPECT_EQ(hil["controller"]["fault"]["reason"],
            "wheel runaway: the test library stops at its third step");
  EXPECT_EQ(hil["controller"]["fault"]["cycle"], 2);
  EXPECT_EQ(hil["ecs"]["stop_reason"], "model_fault");
  EXPECT_EQ(hil["ecs"]["outputs_safe"], true);
  EXPECT_EQ(hil["ecs"]["cycles_run"], 3);
  EXPECT_EQ(hil["twin"]["stop_reason"], "peer_stopped");
  EXPECT_EQ(hil["twin"]["peer_stopped"], "wire: the ECS stopped on a fault (see its report)");
  EXPECT_EQ(hil["twin"]["outputs_safe"], true);
  EXPECT_EQ(hil["twin_exit"]["exit_code"], 0);
  EXPECT_THAT(run.result.out, HasSubstr("hil       exit 1 (the worse of twin 0 and ECS 1)"));
  EXPECT_THAT(run.result.err,
              HasSubstr("ecs| controller lib:" + library +
                        " stopped at cycle 2: error status "
                        "(wheel runaway: the test library stops at its third step); safe "
                        "outputs\n"));
  // The pair's own summary says it where it names the controller.
  EXPECT_THAT(run.result.out,
              HasSubstr("; stopped at cycle 2: error status (wheel runaway: the test library "
                        "stops at its third step)\n"));
}

// hil makes and binds the controller itself before it starts either side: a library the
// loader refuses, or one whose ports do not fit the map, is hil's own exit 2 naming it, with no
// twin started, no report and no wire left.
TEST_F(ControllerStopped, ARefusedOrUnfittingLibraryIsHilsExitTwoBeforeEitherSideStarts) {
  const std::string refused = ControllerLib("bad_abi_version");
  const HilRun run = Hil("refused", {"--controller", "lib:" + refused});
  EXPECT_EQ(run.result.exit_code, 2) << run.result.out << run.result.err;
  EXPECT_THAT(run.result.err,
              HasSubstr("controller lib:" + refused +
                        ": built against controller ABI version 99, but this hiltwin speaks "
                        "version 1"));
  EXPECT_THAT(run.result.err, Not(HasSubstr("ecs|")));  // no ECS process said it
  EXPECT_THAT(run.result.out, Not(HasSubstr("twin ")));
  EXPECT_TRUE(run.report.is_null()) << "a report of a pair that never started";

  const std::string unfitting = ControllerLib("bad_wrong_unit");
  const HilRun misfit = Hil("misfit", {"--controller", "lib:" + unfitting});
  EXPECT_EQ(misfit.result.exit_code, 2) << misfit.result.out << misfit.result.err;
  EXPECT_THAT(misfit.result.err, HasSubstr("make the units agree"));
  EXPECT_THAT(misfit.result.err, Not(HasSubstr("ecs|")));
  EXPECT_TRUE(misfit.report.is_null());
}

// --- A crash of the user's code ------------------------------------------------------------

/// `env` with the sanitizers' options plus handle_segv=0: under ASan (the sanitizer stage) or
/// TSan (the concurrency stage) a process's own SIGSEGV handler would report and exit; this
/// leaves the signal to kill, as in the program that ships (the loader's crash test does the
/// same). The options the stage set are kept.
std::vector<std::string> LeaveSegvToKill() {
  std::vector<std::string> argv = {"env"};
  for (const char* name : {"ASAN_OPTIONS", "TSAN_OPTIONS"}) {
    const char* set = std::getenv(name);  // NOLINT(concurrency-mt-unsafe): one thread
    argv.push_back(std::string(name) + "=" + (set != nullptr ? std::string(set) + ":" : "") +
                   "handle_segv=0");
  }
  return argv;
}

// A library whose step() writes through NULL: the ECS process dies of SIGSEGV (the loader
// cannot catch it, and must not try), and the twin ends as it does for any killed ECS: an I/O
// fault with safe outputs, naming the ECS as gone; hil's summary names the ECS's signal.
class ControllerCrash : public ControllerLockstep {};

TEST_F(ControllerCrash, ANullDereferenceKillsTheEcsAndTheTwinGoesSafe) {
  const HilRun run = Hil("crash",
                         {"--controller", "lib:" + ControllerLib("null_dereference"), "--log-dir",
                          scratch_.Path("logs")},
                         LeaveSegvToKill());
  // The pair's code is the worse of the two: the twin's I/O fault (5) and the crashed ECS,
  // which counts as 1 (a side that did not exit: hil_report.cpp's ExitCodeOf).
  EXPECT_EQ(run.result.exit_code, 1) << run.result.out << run.result.err;
  const Json& hil = run.report;
  ASSERT_TRUE(hil.is_object()) << run.result.out << run.result.err;
  const std::string segv = "killed by signal " + std::to_string(SIGSEGV) + " (SIGSEGV)";
  EXPECT_EQ(hil["ecs_exit"]["ended"], segv) << hil["ecs_exit"];
  EXPECT_TRUE(hil["ecs"].is_null()) << "a killed ECS writes no report";
  const Json& twin = hil["twin"];
  EXPECT_GT(twin["cycles_run"].get<int>(), 0) << "the ECS died in the run, not at its start";
  EXPECT_EQ(twin["stop_reason"], "io_fault");
  EXPECT_EQ(twin["final_state"], "safe_stop");
  EXPECT_EQ(twin["outputs_safe"], true);
  EXPECT_THAT(twin["fault"]["reason"].get<std::string>(),
              HasSubstr("lockstep: the ECS process is gone (killed or crashed)"));
  EXPECT_EQ(hil["exit_code"], 1);
  EXPECT_EQ(hil["twin_exit"]["exit_code"], 5);
  EXPECT_EQ(hil["ecs_exit"]["exit_code"], 1);
  EXPECT_THAT(run.result.out, HasSubstr("ecs   no report (" + segv + ")\n"));
  EXPECT_THAT(run.result.out, HasSubstr("twin  PASS     stop io_fault "));
  EXPECT_THAT(run.result.err, HasSubstr("hiltwin hil: the ecs ended with " + segv));
  // The exit line says how the ECS ended, not an exit code it never gave.
  EXPECT_THAT(run.result.out,
              HasSubstr("hil       exit 1 (the worse of twin 5 and ECS 1, " + segv + ")\n"));
}

}  // namespace
}  // namespace controller_kinds_test
