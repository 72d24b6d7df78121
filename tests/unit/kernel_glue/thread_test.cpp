// kernel_glue::NamedThread: a thread started from a SCHED_FIFO, pinned thread runs at
// SCHED_OTHER on the CPUs it was given, under its name, from its first instruction.
#include "hiltwin/kernel_glue/thread.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace hiltwin::kernel_glue {
namespace {

struct Seen {
  int policy = -1;
  int priority = -1;
  std::vector<int> cpus;
  std::string name;
};

Seen LookAtMyself() {
  Seen seen;
  sched_param param{};
  pthread_getschedparam(pthread_self(), &seen.policy, &param);
  seen.priority = param.sched_priority;
  cpu_set_t set;
  CPU_ZERO(&set);
  pthread_getaffinity_np(pthread_self(), sizeof set, &set);
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(static_cast<std::size_t>(cpu), &set)) seen.cpus.push_back(cpu);
  }
  char name[16] = {};
  pthread_getname_np(pthread_self(), name, sizeof name);
  seen.name = name;
  return seen;
}

TEST(NamedThread, NeverInheritsTheCreatorsRealTimePolicyOrCpus) {
  const std::vector<int> allowed = AllowedCpus();
  if (allowed.size() < 2) GTEST_SKIP() << "needs two CPUs";
  const int creator_cpu = allowed.front();
  const int helper_cpu = allowed.back();
  bool creator_fifo = false;
  Seen helper;
  // The creator plays the loop: pinned and, where allowed, SCHED_FIFO.
  std::thread creator([&] {
    ASSERT_EQ(SetCallingThreadCpus(std::vector<int>{creator_cpu}), 0);
    sched_param param{};
    param.sched_priority = 20;
    creator_fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
    NamedThread thread({"hiltwin-test", {helper_cpu}}, [&] { helper = LookAtMyself(); });
    thread.Join();
  });
  creator.join();
  EXPECT_EQ(helper.policy, SCHED_OTHER) << "creator was SCHED_FIFO: " << creator_fifo;
  EXPECT_EQ(helper.priority, 0);
  EXPECT_EQ(helper.cpus, std::vector<int>{helper_cpu});
  EXPECT_EQ(helper.name, "hiltwin-test");
}

TEST(NamedThread, NoCpusMeansEveryCpuNotTheCreatorsPinning) {
  const std::vector<int> allowed = AllowedCpus();
  if (allowed.size() < 2) GTEST_SKIP() << "needs two CPUs";
  Seen helper;
  std::thread creator([&] {
    ASSERT_EQ(SetCallingThreadCpus(std::vector<int>{allowed.front()}), 0);
    NamedThread thread({"hiltwin-any", {}}, [&] { helper = LookAtMyself(); });
  });  // the destructor joins
  creator.join();
  EXPECT_EQ(helper.cpus, allowed);
}

TEST(NamedThread, RejectsBadSpecs) {
  EXPECT_THROW(NamedThread({"", {}}, [] {}), std::invalid_argument);
  EXPECT_THROW(NamedThread({"a-name-of-sixteen", {}}, [] {}), std::invalid_argument);
  EXPECT_THROW(NamedThread({"bad-cpu", {-1}}, [] {}), std::invalid_argument);
  EXPECT_EQ(SetCallingThreadCpus(std::vector<int>{-3}), EINVAL);
}

TEST(HelperCpus, AreTheAllowedOnesWithoutTheLoopsAndNeverNone) {
  const std::vector<int> allowed = {0, 1, 2, 3};
  EXPECT_EQ(HelperCpus(allowed, std::vector<int>{3}), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(HelperCpus(allowed, std::vector<int>{}), allowed);
  EXPECT_EQ(HelperCpus(allowed, std::vector<int>{0, 1, 2, 3}),
            allowed);  // a helper must run somewhere
}

}  // namespace
}  // namespace hiltwin::kernel_glue
