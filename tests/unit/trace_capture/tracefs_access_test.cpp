// Why the kernel recorder refuses, for conditions a root test machine cannot produce for real:
// the facts are injected, the judgement is the one KernelRecorder::WhyCannotRecord gives.
#include "hiltwin/trace_capture/tracefs_access.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cerrno>

namespace {

using hiltwin::trace_capture::ExplainTracefsAccess;
using hiltwin::trace_capture::TracefsAccessFacts;
using ::testing::AllOf;
using ::testing::HasSubstr;

TracefsAccessFacts Mounted(bool writable, int access_errno) {
  TracefsAccessFacts facts;
  facts.mounted = true;
  facts.writable = writable;
  facts.access_errno = access_errno;
  return facts;
}

TEST(TracefsAccess, MountedAndWritableMayRecord) {
  EXPECT_EQ(ExplainTracefsAccess(Mounted(true, 0)), "");
}

TEST(TracefsAccess, NotWritableSaysWhichDirectoryWhyAndWhatToDo) {
  EXPECT_THAT(ExplainTracefsAccess(Mounted(false, EACCES)),
              AllOf(HasSubstr("/sys/kernel/tracing/instances"), HasSubstr("not writable"),
                    HasSubstr("EACCES"), HasSubstr("as root"), HasSubstr("without --kernel")));
  TracefsAccessFacts read_only = Mounted(false, EROFS);
  read_only.mount_point = "/mnt/tracing";
  EXPECT_THAT(ExplainTracefsAccess(read_only),
              AllOf(HasSubstr("/mnt/tracing/instances"), HasSubstr("EROFS")));
}

TEST(TracefsAccess, NotMountedAndNotAllowedToMountSaysHowToMount) {
  TracefsAccessFacts facts;
  facts.may_mount = false;
  EXPECT_THAT(
      ExplainTracefsAccess(facts),
      AllOf(HasSubstr("not mounted"), HasSubstr("mount -t tracefs nodev /sys/kernel/tracing")));
}

TEST(TracefsAccess, AFailedMountSaysWhyAndWhatToDo) {
  TracefsAccessFacts facts;
  facts.mount_attempted = true;
  facts.mount_errno = EPERM;
  EXPECT_THAT(ExplainTracefsAccess(facts),
              AllOf(HasSubstr("mounting it at /sys/kernel/tracing failed"), HasSubstr("EPERM"),
                    HasSubstr("as root")));
}

}  // namespace
