#include "hiltwin/runtime/overrun_injection.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace hiltwin::runtime {
namespace {

TEST(OverrunInjection, AtCountAndEvery) {
  OverrunInjector injector;
  injector.Add(ParseOverrunInjection("at=40000,count=5,extra-us=600"));
  injector.Add(ParseOverrunInjection("every=1000,extra-us=300"));
  EXPECT_EQ(injector.ExtraNs(39'999), 0);
  EXPECT_EQ(injector.ExtraNs(40'000), 600'000 + 300'000);  // both match: times add up
  EXPECT_EQ(injector.ExtraNs(40'004), 600'000);
  EXPECT_EQ(injector.ExtraNs(40'005), 0);
  EXPECT_EQ(injector.ExtraNs(0), 300'000);
  EXPECT_EQ(injector.ExtraNs(2000), 300'000);
  EXPECT_EQ(injector.ExtraNs(2001), 0);
}

TEST(OverrunInjection, OffsetAndDefaults) {
  const OverrunInjection every = ParseOverrunInjection("every=10,offset=3,extra-us=1");
  EXPECT_EQ(every.kind, OverrunInjection::Kind::kEvery);
  EXPECT_EQ(every.offset, 3U);
  EXPECT_EQ(every.extra_ns, 1000);
  const OverrunInjection at = ParseOverrunInjection("extra-us=7,at=12");
  EXPECT_EQ(at.first_cycle, 12U);
  EXPECT_EQ(at.count, 1U);
}

TEST(OverrunInjection, RejectsMalformedSpecsWithTheAcceptedForms) {
  for (const char* bad :
       {"", "at=1", "extra-us=5", "at=1,every=2,extra-us=5", "at=x,extra-us=5", "at=1,extra-us=0",
        "at=1,extra-us=-3", "every=0,extra-us=5", "every=4,offset=4,extra-us=5",
        "at=1,offset=1,extra-us=5", "every=4,count=2,extra-us=5", "at=1,count=0,extra-us=5",
        "at=1,foo=2,extra-us=5", "at"}) {
    try {
      (void)ParseOverrunInjection(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("accepted forms"), std::string::npos) << e.what();
    }
  }
}

TEST(OverrunInjection, AtMostEightSpecs) {
  OverrunInjector injector;
  for (int i = 0; i < 8; ++i) injector.Add(ParseOverrunInjection("at=1,extra-us=1"));
  EXPECT_THROW(injector.Add(ParseOverrunInjection("at=1,extra-us=1")), std::length_error);
}

}  // namespace
}  // namespace hiltwin::runtime
