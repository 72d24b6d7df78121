// A hiltwin built with -DHILTWIN_WITH_LTTNG=OFF: a session cannot be made, and the error says
// how to trace without LTTng.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "hiltwin/trace_capture/capture_error.h"
#include "hiltwin/trace_capture/lttng_session.h"

namespace {

using hiltwin::trace_capture::CaptureError;
using hiltwin::trace_capture::LttngSession;
using hiltwin::trace_capture::LttngSessionConfig;
using ::testing::HasSubstr;

TEST(LttngSessionWithoutLttng, SaysHowToTraceWithATimingLog) {
  try {
    LttngSession session(LttngSessionConfig{.output_dir = "/nonexistent"});
    ADD_FAILURE() << "no CaptureError";
  } catch (const CaptureError& error) {
    EXPECT_THAT(error.what(), HasSubstr("built without LTTng (HILTWIN_WITH_LTTNG=OFF)"));
    EXPECT_THAT(error.what(), HasSubstr("hiltwin run --timing-log FILE"));
    EXPECT_THAT(error.what(), HasSubstr("hiltwin trace --analyze FILE"));
  }
}

TEST(LttngSessionWithoutLttng, TheChannelSizingStillWorks) {
  EXPECT_EQ(hiltwin::trace_capture::ChannelSizeFor(100'000.0).subbuf_bytes, 1024U * 1024U);
}

}  // namespace
