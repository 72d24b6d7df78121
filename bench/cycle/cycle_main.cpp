// Instructions per twin cycle, component by component (issue 36): the figure of merit for the
// loop's speed, counted by callgrind (load-independent; this VM has no hardware counters). Each
// component runs in its own process under `valgrind --tool=callgrind --collect-atstart=no`,
// counting only between two ToggleCounting() on the thread that does the work, for 4,000 and
// 12,000 items; the difference per item cancels the set-up (callgrind_count.h). Every component
// is the real one, built as `hiltwin run --clock virtual` builds it (its flags parsed by the
// command's own parser, the twin by BuildTwin, the session by MakeSessionConfig):
//   model      the plant's step through plant::Plant (RELbot, RK4), the twin's inputs
//   executive  scheduler::Executive on a virtual clock with an empty task
//   exchange   the mock board's exchange as the twin does it (IcoBoardInverse::Exchange with
//              the counts the twin sent, the input profile playing into the board)
//   qos        QosMonitor::Record with the run's default rules
//   histogram  the five LogLinearHistogram::Record a cycle makes (one per timing statistic),
//              with the values of a virtual-clock cycle (all 0: the loop takes no time)
//   producer   CsvLogger::TryLog of the run's rows (the loop's side of --log)
//   writer     the writer's work per row: drain, format and write(2) (run on the calling
//              thread by Stop, so it can be bracketed); its file must equal the run's log
//   whole      a whole RunSession cycle on the loop thread, no log (the hooks bracket the loop)
// What the components are fed is recorded first, uncounted: the plant's inputs and the counts
// the exchange sent by a twin of their own, the log rows by a run with --log (read back from
// its file), so the model, the exchange and the logger see the values of a real run.
//   hiltwin_bench_cycle            the table (callgrind; time figures only without valgrind)
//   hiltwin_bench_cycle --time     the time figures (ns per cycle), in this process
//   hiltwin_bench_cycle --count COMPONENT N   one bracketed run (run under callgrind)
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench_stats.h"
#include "callgrind_count.h"
#include "cycle_table.h"
#include "hiltwin/kernel_glue/clock.h"
#include "hiltwin/kernel_glue/stop_signal.h"
#include "hiltwin/qos/monitor.h"
#include "hiltwin/runs/session_assembly.h"
#include "hiltwin/runs/twin_build.h"
#include "hiltwin/runs/twin_run.h"
#include "hiltwin/runtime/run_session.h"
#include "hiltwin/scheduler/executive.h"
#include "hiltwin/scheduler/log_linear_histogram.h"
#include "hiltwin/tracing/csv_logger.h"
#include "session_flags.h"

namespace {

namespace fs = std::filesystem;
namespace app = hiltwin::app;
namespace sched = hiltwin::scheduler;
using hiltwin::bench::BenchClock;
using hiltwin::bench::CycleComponent;

constexpr std::uint64_t kFew = 4'000;
constexpr std::uint64_t kMany = 12'000;
constexpr double kRateHz = 4000.0;  // `hiltwin run`'s default rate
constexpr double kWholeTarget = 1800.0;
constexpr double kWriterTarget = 2500.0;
/// The columns of the RELbot twin's log row, time_s included (the table names them; CountLog
/// checks them against the run's log).
constexpr std::size_t kLogColumns = 15;

/// Brackets the measured work: callgrind counts between the two toggles (on this thread), and
/// the steady clock times it for the figures without valgrind.
class Bracket {
 public:
  void Open() noexcept {
    hiltwin::bench::ToggleCounting();
    start_ = BenchClock::now();
  }
  void Close() noexcept {
    end_ = BenchClock::now();
    hiltwin::bench::ToggleCounting();
  }
  [[nodiscard]] double Ns() const {
    return std::chrono::duration<double, std::nano>(end_ - start_).count();
  }

 private:
  BenchClock::time_point start_;
  BenchClock::time_point end_;
};

/// `hiltwin run --clock virtual --duration <cycles / rate> --no-progress`, as the command's own
/// parser reads it, so every default (board, input, plant, QoS rules) is the command's.
app::TwinRunOptions RunOptions(std::uint64_t cycles) {
  CLI::App cli;
  app::TwinRunFlags flags;
  app::AddTwinRunFlags(cli, flags);
  cli.parse("--clock virtual --no-progress --duration " +
                std::to_string(static_cast<double>(cycles) / kRateHz),
            false);
  return app::TwinRunOptionsFrom(flags, "run");
}

std::unique_ptr<app::Twin> MakeTwin(const app::TwinRunOptions& o) {
  return app::BuildTwin(o, hiltwin::kernel_glue::PeriodNsFromRateHz(o.session.rate_hz));
}

/// What the twin's cycles carried: per cycle the plant's inputs and the counts the exchange
/// sent.
struct TwinRecord {
  std::vector<std::vector<double>> inputs;
  std::vector<std::array<std::int32_t, hiltwin::io::kChannels>> counts;
};

/// Runs a twin of its own for `cycles` cycles (exchange, step) and records what they carried.
TwinRecord RecordTwin(const app::TwinRunOptions& o, std::uint64_t cycles) {
  const std::unique_ptr<app::Twin> twin = MakeTwin(o);
  hiltwin::plant::PlantTwinTask& task = *twin->task;
  TwinRecord record;
  for (std::uint64_t k = 0; k < cycles; ++k) {
    static_cast<void>(task.Exchange(true));
    record.counts.push_back(task.encoder_sent());
    static_cast<void>(task.Step(sched::CycleContext{.cycle = k}));
    record.inputs.emplace_back(task.inputs().begin(), task.inputs().end());
  }
  return record;
}

double CountModel(std::uint64_t items) {
  const app::TwinRunOptions o = RunOptions(items);
  const TwinRecord record = RecordTwin(o, items);
  const std::unique_ptr<app::Twin> twin = MakeTwin(o);
  std::vector<double> y(twin->plant->Info().outputs.size());
  Bracket bracket;
  bracket.Open();
  for (const std::vector<double>& u : record.inputs) static_cast<void>(twin->plant->Step(u, y));
  bracket.Close();
  return bracket.Ns();
}

double CountExchange(std::uint64_t items) {
  const app::TwinRunOptions o = RunOptions(items);
  const TwinRecord record = RecordTwin(o, items);
  const std::unique_ptr<app::Twin> twin = MakeTwin(o);
  hiltwin::io::TwinInputs in;
  Bracket bracket;
  bracket.Open();
  for (const auto& counts : record.counts) static_cast<void>(twin->driver->Exchange(counts, in));
  bracket.Close();
  return bracket.Ns();
}

class EmptyTask final : public sched::CyclicTask {
 public:
  sched::CycleAction Step(const sched::CycleContext&) noexcept override {
    return sched::CycleAction::kContinue;
  }
};

double CountExecutive(std::uint64_t items) {
  hiltwin::kernel_glue::VirtualClock clock;
  sched::ExecutiveConfig config;
  config.period_ns = hiltwin::kernel_glue::PeriodNsFromRateHz(kRateHz);
  config.max_cycles = items;
  sched::Executive executive(clock, config);
  EmptyTask task;
  Bracket bracket;
  bracket.Open();
  static_cast<void>(executive.Run(task));
  bracket.Close();
  return bracket.Ns();
}

/// The run's QoS configuration, as MakeSessionConfig makes it for the twin.
hiltwin::qos::QosConfig RunQosConfig(std::uint64_t items) {
  const app::TwinRunOptions o = RunOptions(items);
  const std::unique_ptr<app::Twin> twin = MakeTwin(o);
  return app::MakeSessionConfig(o.session, app::TwinRole("run", o.controller_rate_hz),
                                *twin->backend)
      .qos;
}

double CountQos(std::uint64_t items) {
  hiltwin::qos::QosMonitor monitor(RunQosConfig(items));
  bool stop = false;
  Bracket bracket;
  bracket.Open();
  for (std::uint64_t k = 0; k < items; ++k) stop = monitor.Record(k, false) || stop;
  bracket.Close();
  if (stop) throw std::runtime_error("the default QoS rules stopped a run without misses");
  return bracket.Ns();
}

double CountHistogram(std::uint64_t items) {
  std::array<sched::LogLinearHistogram, 5> statistics;
  volatile std::int64_t value = 0;  // what a virtual-clock cycle records, not folded away
  Bracket bracket;
  bracket.Open();
  for (std::uint64_t k = 0; k < items; ++k) {
    for (sched::LogLinearHistogram& h : statistics) h.Record(value);
  }
  bracket.Close();
  return bracket.Ns();
}

/// Brackets the loop thread's loop (the hooks run on it around the loop).
class LoopBracket final : public hiltwin::runtime::LoopThreadHooks {
 public:
  void BeforeLoop() noexcept override { bracket.Open(); }
  void AfterLoop() noexcept override { bracket.Close(); }
  Bracket bracket;
};

/// Runs `o` as RunTwin assembles it (no link faults, no shown setpoint; nothing printed), with
/// the loop bracketed when `counted` (a recording run must not toggle: callgrind would count
/// its loop into the figure it records for); returns the bracket's time.
double RunSessionOf(const app::TwinRunOptions& o, std::uint64_t cycles, bool counted) {
  hiltwin::kernel_glue::InstallStopSignalHandlers();
  const std::unique_ptr<app::Twin> twin = MakeTwin(o);
  hiltwin::runtime::SessionConfig config = app::MakeSessionConfig(
      o.session, app::TwinRole("run", o.controller_rate_hz), *twin->backend);
  config.task_name = "RELbot twin";
  hiltwin::runtime::RunSession session(std::move(config), *twin->task);
  LoopBracket hooks;
  if (counted) session.SetLoopThreadHooks(&hooks);
  const hiltwin::runtime::RunReport report = session.Run();
  twin->plant->Finish();
  if (report.cycles_run != cycles) {
    throw std::runtime_error("the run ran " + std::to_string(report.cycles_run) + " of " +
                             std::to_string(cycles) + " cycles");
  }
  return hooks.bracket.Ns();
}

/// `hiltwin run --clock virtual` for `items` cycles, the loop thread's loop bracketed.
double CountWhole(std::uint64_t items) { return RunSessionOf(RunOptions(items), items, true); }

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// The rows of a --log file: its value columns (time_s apart) and, per row, time and values.
struct LogRows {
  std::vector<std::string> columns;
  std::vector<double> times;
  std::vector<std::vector<double>> values;
};

LogRows ReadLog(const fs::path& path) {
  std::ifstream in(path);
  LogRows rows;
  std::string line;
  while (std::getline(in, line) && line.starts_with("#")) {}
  std::istringstream header(line);
  for (std::string name; std::getline(header, name, ',');) rows.columns.push_back(name);
  rows.columns.erase(rows.columns.begin());  // time_s
  while (std::getline(in, line)) {
    std::istringstream cells(line);
    std::string cell;
    std::getline(cells, cell, ',');
    rows.times.push_back(std::strtod(cell.c_str(), nullptr));
    rows.values.emplace_back();
    while (std::getline(cells, cell, ',')) {
      rows.values.back().push_back(std::strtod(cell.c_str(), nullptr));
    }
  }
  return rows;
}

/// The rows `hiltwin run --clock virtual --log` writes in `items` cycles, read back from its
/// log (the twin's columns and the run's timing columns).
LogRows RecordLog(std::uint64_t items, const fs::path& path) {
  app::TwinRunOptions o = RunOptions(items);
  o.session.log_path = path.string();
  static_cast<void>(RunSessionOf(o, items, false));
  LogRows rows = ReadLog(path);
  if (rows.values.size() != items) throw std::runtime_error("the run's log has too few rows");
  return rows;
}

/// The producer's TryLog of every row of a run's log (`producer`), or the writer's Stop
/// draining them all (`writer`), bracketed; the writer's file is the run's, byte for byte.
double CountLog(std::uint64_t items, bool writer) {
  const std::string stem = "hiltwin_bench_cycle_" + std::to_string(getpid());
  const fs::path run_log = fs::temp_directory_path() / (stem + "_run.csv");
  const fs::path path = fs::temp_directory_path() / (stem + ".csv");
  const LogRows rows = RecordLog(items, run_log);
  if (rows.columns.size() + 1 != kLogColumns) {
    throw std::runtime_error("the run's log has " + std::to_string(rows.columns.size() + 1) +
                             " columns: update kLogColumns");
  }
  hiltwin::tracing::CsvLoggerConfig config;
  config.path = path.string();
  config.columns = rows.columns;
  config.queue_capacity_rows = std::size_t{1} << 14;
  static_assert(kMany <= (1 << 14), "every row is queued");
  hiltwin::tracing::CsvLogger logger(config);
  Bracket bracket;
  if (!writer) bracket.Open();
  for (std::size_t k = 0; k < rows.values.size(); ++k) {
    static_cast<void>(logger.TryLog(rows.times[k], rows.values[k]));
  }
  if (!writer) bracket.Close();
  if (writer) bracket.Open();
  logger.Stop();
  if (writer) bracket.Close();
  const bool same = ReadFile(path) == ReadFile(run_log);
  fs::remove(path);
  fs::remove(run_log);
  if (!same) throw std::runtime_error("the writer's file differs from the run's log");
  return bracket.Ns();
}

struct Component {
  const char* key;   ///< --count's name
  std::string name;  ///< the table's
  double (*count)(std::uint64_t items);
  std::optional<double> target;  ///< instructions per cycle
};

double CountProducer(std::uint64_t items) { return CountLog(items, false); }
double CountWriter(std::uint64_t items) { return CountLog(items, true); }

/// The components in the table's order, the whole cycle last.
std::vector<Component> Components() {
  const std::string columns = std::to_string(kLogColumns) + " columns";
  return {{"model", "model step (plant::Plant::Step, RELbot RK4)", CountModel, {}},
          {"executive", "executive alone (empty task, virtual clock)", CountExecutive, {}},
          {"exchange", "mock board exchange (IcoBoardInverse)", CountExchange, {}},
          {"qos", "QoS Record (default rules)", CountQos, {}},
          {"histogram", "histogram (5 x LogLinearHistogram::Record)", CountHistogram, {}},
          {"producer", "log producer (TryLog, " + columns + ")", CountProducer, {}},
          {"writer", "log writer per row (" + columns + ")", CountWriter, kWriterTarget},
          {"whole", "whole virtual-clock cycle (no log)", CountWhole, kWholeTarget}};
}

/// Why callgrind cannot count here; empty when it can.
std::string WhyNoCallgrind() {
#if defined(HILTWIN_UNDER_SANITIZER)
  return "a sanitizer's runtime and valgrind do not run in one process";
#elif !defined(HILTWIN_BENCH_HAS_CALLGRIND)
  return "built without valgrind's headers (apt-get install valgrind, then rebuild)";
#else
  const bool found = hiltwin::kernel_glue::RunProcess(
                         {"sh", "-c", "command -v valgrind"},
                         {.out = hiltwin::kernel_glue::OutputTarget::Discard(),
                          .err = hiltwin::kernel_glue::OutputTarget::Discard()})
                         .status.Success();
  return found ? "" : "valgrind is not installed (apt-get install valgrind)";
#endif
}

void PrintTable(const std::vector<Component>& components, const std::vector<double>& figures,
                const char* unit, bool with_targets) {
  std::vector<CycleComponent> rows;
  for (std::size_t i = 0; i < components.size(); ++i) {
    rows.push_back({components[i].name, figures[i],
                    with_targets ? components[i].target : std::nullopt});
  }
  for (const std::string& line : hiltwin::bench::FormatCycleTable(rows, figures.back(), unit)) {
    std::printf("%s\n", line.c_str());
  }
}

/// Per component, the callgrind count of its run of kFew and of kMany items, per item.
void ReportInstructions(const std::vector<Component>& components, const char* self) {
  std::vector<double> figures;
  for (const Component& c : components) {
    const auto count = [&](std::uint64_t items) {
      return hiltwin::bench::CountInstructions({self, "--count", c.key, std::to_string(items)});
    };
    figures.push_back(hiltwin::bench::InstructionsPerItem(kFew, count(kFew), kMany, count(kMany)));
  }
  std::printf("instructions per twin cycle (callgrind, %llu against %llu cycles; RELbot twin, "
              "mock board, default QoS, as `hiltwin run --clock virtual`):\n",
              static_cast<unsigned long long>(kMany), static_cast<unsigned long long>(kFew));
  PrintTable(components, figures, "instructions", true);
}

/// Per component, its time per item in this process (kMany against kFew items, median of 3).
void ReportTimes(const std::vector<Component>& components) {
  std::vector<double> figures;
  for (const Component& c : components) {
    std::vector<double> rounds;
    for (int round = 0; round < 3; ++round) {
      const double few = c.count(kFew);
      rounds.push_back((c.count(kMany) - few) / static_cast<double>(kMany - kFew));
    }
    figures.push_back(hiltwin::bench::Median(rounds));
  }
  std::printf("time per twin cycle (steady clock, %llu against %llu cycles, median of 3; "
              "load-dependent, targets are in instructions):\n",
              static_cast<unsigned long long>(kMany), static_cast<unsigned long long>(kFew));
  PrintTable(components, figures, "ns", false);
}

int CountOne(const std::vector<Component>& components, const char* key, const char* items_text) {
  const std::uint64_t items = std::strtoull(items_text, nullptr, 10);
  for (const Component& c : components) {
    if (std::strcmp(c.key, key) != 0 || items == 0) continue;
    static_cast<void>(c.count(items));
    return 0;
  }
  std::fprintf(stderr, "usage: hiltwin_bench_cycle --count COMPONENT N(>0); components:");
  for (const Component& c : components) std::fprintf(stderr, " %s", c.key);
  std::fprintf(stderr, "\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::vector<Component> components = Components();
    if (argc == 4 && std::strcmp(argv[1], "--count") == 0) {
      return CountOne(components, argv[2], argv[3]);
    }
    if (argc == 2 && std::strcmp(argv[1], "--time") == 0) {
      ReportTimes(components);
      return 0;
    }
    if (argc != 1) {
      std::fprintf(stderr, "usage: %s [--time | --count COMPONENT N]\n", argv[0]);
      return 2;
    }
    if (const std::string why = WhyNoCallgrind(); !why.empty()) {
      std::printf("no instruction counts: %s; the time figures only\n", why.c_str());
      ReportTimes(components);
      return 0;
    }
    ReportInstructions(components, fs::read_symlink("/proc/self/exe").c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "hiltwin_bench_cycle: %s\n", e.what());
    return 1;
  }
  return 0;
}
