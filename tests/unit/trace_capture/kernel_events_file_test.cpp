// kernel_events.csv / kernel_tasks.csv: what is written reads back equal, and every kind of
// bad input is refused with file:line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "hiltwin/traces/kernel_events.h"
#include "hiltwin/traces/timing_trace.h"

namespace {

namespace fs = std::filesystem;
using hiltwin::analysis::HasKernelTrace;
using hiltwin::analysis::KernelEvent;
using hiltwin::analysis::KernelEventKind;
using hiltwin::analysis::KernelTask;
using hiltwin::analysis::KernelTrace;
using hiltwin::analysis::ReadKernelTrace;
using hiltwin::analysis::TraceReadError;
using hiltwin::analysis::WriteKernelTrace;
using ::testing::HasSubstr;

constexpr const char* kHeader =
    "time_ns,cpu,event,pid,comm,prio,next_pid,next_comm,next_prio,prev_state,target_cpu,irq,"
    "name,address\n";
constexpr const char* kComment = "# hiltwin kernel events 1 cpus=0,1 lost=3\n";
constexpr const char* kTasks = "pid,comm,policy,rt_priority\n42,loop,SCHED_FIFO,80\n";

class KernelEventsFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("hiltwin_kernel_events_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void WriteFile(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }
  // The message of the TraceReadError reading dir_ throws ("" when it does not throw).
  [[nodiscard]] std::string ReadError() const {
    try {
      (void)ReadKernelTrace(dir_.string());
    } catch (const TraceReadError& error) {
      return error.what();
    }
    return "";
  }
  [[nodiscard]] std::string EventsPath() const { return (dir_ / "kernel_events.csv").string(); }

  fs::path dir_;
};

KernelEvent Event(std::int64_t time_ns, int cpu, KernelEventKind kind) {
  KernelEvent event;
  event.time_ns = time_ns;
  event.cpu = cpu;
  event.kind = kind;
  return event;
}

KernelEvent Task(KernelEvent event, int pid, const std::string& comm, int prio) {
  event.pid = pid;
  event.comm = comm;
  event.prio = prio;
  return event;
}

KernelEvent Irq(KernelEvent event, int irq, const std::string& name) {
  event.irq = irq;
  event.name = name;
  return event;
}

// One event of every kind, with the fields its kind carries, given out of time order.
KernelTrace EveryKind() {
  KernelTrace trace;
  trace.cpus = {0, 1};
  trace.lost_events = 12;
  trace.preemption_model = "PREEMPT_NONE";
  trace.preemption_source = "PREEMPT_DYNAMIC, kernel config default; debugfs not mounted";
  KernelEvent preempted =
      Task(Event(1'000'500, 0, KernelEventKind::kSchedSwitch), 7, "cap-victim", 120);
  preempted.next_pid = 8;
  preempted.next_comm = "cap-hog";
  preempted.next_prio = 9;
  KernelEvent sleeping = preempted;
  sleeping.time_ns = 1'000'900;
  sleeping.prev_state = 1;
  KernelEvent wakeup = Task(Event(1'000'000, 1, KernelEventKind::kSchedWakeup), 8, "cap-hog", 9);
  wakeup.target_cpu = 0;
  KernelEvent fault =
      Task(Event(1'000'400, 1, KernelEventKind::kPageFaultUser), 7, "cap-victim", 0);
  fault.address = 0x7ffd'1234'5678;
  trace.events = {
      sleeping,
      wakeup,
      preempted,
      Irq(Event(1'000'100, 0, KernelEventKind::kIrqEntry), 24, "virtio0-input.0"),
      Irq(Event(1'000'150, 0, KernelEventKind::kIrqExit), 24, ""),
      Event(1'000'200, 0, KernelEventKind::kLocalTimerEntry),
      Event(1'000'250, 0, KernelEventKind::kLocalTimerExit),
      Irq(Event(1'000'300, 0, KernelEventKind::kSoftirqEntry), 1, "TIMER"),
      Irq(Event(1'000'350, 0, KernelEventKind::kSoftirqExit), 1, "TIMER"),
      fault,
  };
  trace.tasks = {
      KernelTask{.pid = 7, .comm = "cap-victim", .policy = "SCHED_OTHER", .rt_priority = 0},
      KernelTask{.pid = 8, .comm = "cap-hog", .policy = "SCHED_FIFO", .rt_priority = 90},
      KernelTask{.pid = 9, .comm = "gone", .policy = "", .rt_priority = 0}};
  return trace;
}

TEST_F(KernelEventsFileTest, WhatIsWrittenReadsBackEqualInTimeOrder) {
  const KernelTrace written = EveryKind();
  WriteKernelTrace(dir_.string(), written);
  ASSERT_TRUE(HasKernelTrace(dir_.string()));
  const KernelTrace read = ReadKernelTrace(dir_.string());

  KernelTrace expected = written;
  std::stable_sort(
      expected.events.begin(), expected.events.end(),
      [](const KernelEvent& a, const KernelEvent& b) { return a.time_ns < b.time_ns; });
  ASSERT_EQ(read.events.size(), expected.events.size());
  for (std::size_t i = 0; i < read.events.size(); ++i) {
    EXPECT_EQ(read.events[i], expected.events[i]) << "event " << i;
  }
  EXPECT_EQ(read.tasks, expected.tasks);
  EXPECT_EQ(read.cpus, (std::vector<int>{0, 1}));
  EXPECT_EQ(read.lost_events, 12U);
  EXPECT_EQ(read, expected);
  EXPECT_EQ(read.events.front().kind, KernelEventKind::kSchedWakeup);
}

TEST_F(KernelEventsFileTest, TheFileSaysWhatTheHeaderPromises) {
  WriteKernelTrace(dir_.string(), EveryKind());
  std::ifstream in(EventsPath());
  std::string comment;
  std::string preemption;
  std::string header;
  std::string first;
  std::getline(in, comment);
  std::getline(in, preemption);
  std::getline(in, header);
  std::getline(in, first);
  EXPECT_EQ(comment, "# hiltwin kernel events 2 cpus=0,1 lost=12");
  EXPECT_EQ(preemption,
            "# preemption PREEMPT_NONE | PREEMPT_DYNAMIC, kernel config default; debugfs not "
            "mounted");
  EXPECT_EQ(header + "\n", kHeader);
  // A wakeup fills pid, comm, prio and target_cpu; the rest stays empty.
  EXPECT_EQ(first, "1000000,1,sched_wakeup,8,cap-hog,9,,,,,0,,,");
}

// Recordings made before the preemption model was recorded (version 1) have no such line: it
// is not known. kComment is such a file's first line.
TEST_F(KernelEventsFileTest, ARecordingWithoutThePreemptionLineReadsWithTheModelUnknown) {
  WriteFile("kernel_events.csv",
            std::string(kComment) + kHeader + "5,0,local_timer_entry,,,,,,,,,,,\n");
  WriteFile("kernel_tasks.csv", kTasks);
  const KernelTrace read = ReadKernelTrace(dir_.string());
  EXPECT_EQ(read.events.size(), 1U);
  EXPECT_EQ(read.preemption_model, "");
  EXPECT_EQ(read.preemption_source, "");
  // One that has it but not in its shape is refused with its line.
  WriteFile("kernel_events.csv",
            "# hiltwin kernel events 2 cpus=0 lost=0\n# preemption PREEMPT_NONE\n" +
                std::string(kHeader));
  EXPECT_THAT(ReadError(), HasSubstr("kernel_events.csv:2: the preemption line needs"));
}

TEST_F(KernelEventsFileTest, CommasAndLineBreaksInNamesBecomeUnderscores) {
  KernelTrace trace;
  trace.events = {Task(Event(5, 0, KernelEventKind::kSchedWakeup), 3, "a,b\nc", 120)};
  trace.tasks = {KernelTask{.pid = 3, .comm = "x,y", .policy = "SCHED_OTHER", .rt_priority = 0}};
  WriteKernelTrace(dir_.string(), trace);
  const KernelTrace read = ReadKernelTrace(dir_.string());
  ASSERT_EQ(read.events.size(), 1U);
  EXPECT_EQ(read.events[0].comm, "a_b_c");
  EXPECT_EQ(read.tasks.at(0).comm, "x_y");
}

TEST_F(KernelEventsFileTest, AnUnknownEventNameIsRefusedWithFileAndLine) {
  WriteFile("kernel_events.csv", std::string(kComment) + kHeader +
                                     "100,0,local_timer_entry,,,,,,,,,,,\n"
                                     "200,0,sched_swatch,1,a,120,2,b,120,0,,,,\n");
  WriteFile("kernel_tasks.csv", kTasks);
  const std::string error = ReadError();
  EXPECT_THAT(error, HasSubstr(EventsPath() + ":4:"));
  EXPECT_THAT(error, HasSubstr("unknown event name 'sched_swatch'"));
}

TEST_F(KernelEventsFileTest, ATornLastLineIsRefusedWithItsLine) {
  WriteFile("kernel_events.csv", std::string(kComment) + kHeader +
                                     "100,0,local_timer_entry,,,,,,,,,,,\n"
                                     "200,0,sched_switch,1,a,120");  // cut short, no '\n'
  WriteFile("kernel_tasks.csv", kTasks);
  const std::string error = ReadError();
  EXPECT_THAT(error, HasSubstr(EventsPath() + ":4:"));
  EXPECT_THAT(error, HasSubstr("torn last line"));
}

TEST_F(KernelEventsFileTest, AWrongFieldCountOrABadNumberIsRefusedWithItsLine) {
  WriteFile("kernel_tasks.csv", kTasks);
  WriteFile("kernel_events.csv",
            std::string(kComment) + kHeader + "100,0,local_timer_entry,,,,,,,,,,\n");
  EXPECT_THAT(ReadError(), HasSubstr(EventsPath() + ":3: 13 fields, expected 14"));
  WriteFile("kernel_events.csv",
            std::string(kComment) + kHeader + "100,0,sched_wakeup,1x,a,120,,,,,0,,,\n");
  EXPECT_THAT(ReadError(), HasSubstr(EventsPath() + ":3: bad number '1x' in column pid"));
  WriteFile("kernel_events.csv",
            std::string(kComment) + kHeader + "100,0,page_fault_user,1,a,,,,,,,,,12345\n");
  EXPECT_THAT(ReadError(), HasSubstr(":3: bad number '12345' in column address"));
}

TEST_F(KernelEventsFileTest, AMissingCommentOrHeaderLineIsRefused) {
  WriteFile("kernel_tasks.csv", kTasks);
  WriteFile("kernel_events.csv", std::string(kHeader) + "100,0,local_timer_entry,,,,,,,,,,,\n");
  EXPECT_THAT(ReadError(), HasSubstr(EventsPath() + ":1: missing the comment line"));
  WriteFile("kernel_events.csv", std::string(kComment) + "100,0,local_timer_entry,,,,,,,,,,,\n");
  EXPECT_THAT(ReadError(), HasSubstr(EventsPath() + ":2: missing the header row"));
  WriteFile("kernel_events.csv", "");
  EXPECT_THAT(ReadError(), HasSubstr(EventsPath() + ":1: missing the comment line"));
  // A version this reader does not know (a newer recorder's) is named, with those it reads.
  WriteFile("kernel_events.csv",
            "# hiltwin kernel events 3 cpus=0 lost=0\n" + std::string(kHeader));
  EXPECT_THAT(ReadError(),
              HasSubstr("versions 1 and 2 are read; found '# hiltwin kernel events 3"));
}

TEST_F(KernelEventsFileTest, AMissingFileIsRefusedByName) {
  EXPECT_FALSE(HasKernelTrace(dir_.string()));
  EXPECT_THAT(ReadError(), HasSubstr(EventsPath() + ": cannot open"));
  // The events without their tasks: the tasks file is named.
  WriteFile("kernel_events.csv", std::string(kComment) + kHeader);
  EXPECT_THAT(ReadError(), HasSubstr((dir_ / "kernel_tasks.csv").string() + ": cannot open"));
}

TEST_F(KernelEventsFileTest, ABadTaskRowIsRefusedWithItsLine) {
  WriteFile("kernel_events.csv", std::string(kComment) + kHeader);
  WriteFile("kernel_tasks.csv", "pid,comm,policy,rt_priority\n42,loop,SCHED_FIFO\n");
  EXPECT_THAT(ReadError(),
              HasSubstr((dir_ / "kernel_tasks.csv").string() + ":2: 3 fields, expected 4"));
}

}  // namespace
