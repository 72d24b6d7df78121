// Rule parsing, validation, descriptions and the documented defaults.

#include "hiltwin/qos/rules.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace hiltwin::qos {
namespace {

std::string MessageOf(std::string_view text) {
  try {
    (void)ParseMkRule(text);
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "";
}

TEST(QosRules, ParsesMk) {
  EXPECT_EQ(ParseMkRule("9:10"), MakeMkRule(9, 10));
  EXPECT_EQ(ParseMkRule("1:1"), MakeMkRule(1, 1));
  EXPECT_EQ(ParseMkRule("1000:1000"), MakeMkRule(1000, 1000));
  EXPECT_EQ(ParseMkRule("99999:100000").k, 100'000U);
  const RuleSpec rule = ParseMkRule("3:4");
  EXPECT_EQ(rule.kind, RuleKind::kMkFirm);
  EXPECT_EQ(rule.m, 3U);
  EXPECT_EQ(rule.k, 4U);
}

TEST(QosRules, RejectsMalformedMkWithTheTextAndTheAcceptedForm) {
  for (const char* bad : {"", "9", "9:", ":10", "a:b", "9:10:11", " 9:10", "9:10 ", "9.5:10",
                          "-1:10", "+9:10", "9/10", "9:1e2"}) {
    const std::string message = MessageOf(bad);
    ASSERT_FALSE(message.empty()) << "accepted '" << bad << "'";
    EXPECT_NE(message.find("'" + std::string(bad) + "'"), std::string::npos) << message;
    EXPECT_NE(message.find("M:K"), std::string::npos) << message;
  }
}

TEST(QosRules, RejectsOutOfRangeMk) {
  for (const char* bad : {"10:9", "0:5", "0:0", "5:0", "1:100001", "4294967296:1"}) {
    const std::string message = MessageOf(bad);
    ASSERT_FALSE(message.empty()) << "accepted '" << bad << "'";
    EXPECT_NE(message.find("1 <= M <= K <= 100000"), std::string::npos) << message;
  }
}

TEST(QosRules, ParsesMissesInWindow) {
  const RuleSpec rule = ParseMissesInWindowRule("2:10");
  EXPECT_EQ(rule.kind, RuleKind::kMissesInWindow);
  EXPECT_EQ(rule.n, 2U);
  EXPECT_EQ(rule.k, 10U);
  EXPECT_EQ(ParseMissesInWindowRule("0:1").n, 0U);
  EXPECT_THROW((void)ParseMissesInWindowRule("10:10"), std::invalid_argument);
  EXPECT_THROW((void)ParseMissesInWindowRule("x"), std::invalid_argument);
}

TEST(QosRules, CheckedConstructorsValidate) {
  EXPECT_THROW((void)MakeMkRule(0, 4), std::invalid_argument);
  EXPECT_THROW((void)MakeMkRule(5, 4), std::invalid_argument);
  EXPECT_THROW((void)MakeMkRule(1, kMaxWindowCycles + 1), std::invalid_argument);
  EXPECT_THROW((void)MakeMissesInWindowRule(4, 4), std::invalid_argument);
  EXPECT_THROW((void)MakeMissRatioRule(0.0), std::invalid_argument);
  EXPECT_THROW((void)MakeMissRatioRule(-1.0), std::invalid_argument);
  EXPECT_THROW((void)MakeMissRatioRule(100.5), std::invalid_argument);
  EXPECT_THROW((void)MakeMissRatioRule(std::nan("")), std::invalid_argument);
  EXPECT_THROW((void)MakeConsecutiveMissesRule(UINT32_MAX), std::invalid_argument);
  EXPECT_NO_THROW((void)MakeConsecutiveMissesRule(0));
  EXPECT_NO_THROW((void)MakeMissRatioRule(100.0));
}

TEST(QosRules, DescribeAndKindNames) {
  EXPECT_EQ(Describe(MakeMkRule(9, 10)), "(9,10)-firm");
  EXPECT_EQ(Describe(MakeMissesInWindowRule(2, 10)), "at most 2 misses in any 10 cycles");
  EXPECT_EQ(Describe(MakeConsecutiveMissesRule(3)), "at most 3 consecutive misses");
  EXPECT_EQ(Describe(MakeMissRatioRule(1.0)), "miss ratio < 1 %");
  EXPECT_EQ(Describe(MakeMissRatioRule(0.25)), "miss ratio < 0.25 %");
  EXPECT_STREQ(ToString(RuleKind::kMkFirm), "mk_firm");
  EXPECT_STREQ(ToString(RuleKind::kMissesInWindow), "misses_in_window");
  EXPECT_STREQ(ToString(RuleKind::kConsecutiveMisses), "max_consecutive_misses");
  EXPECT_STREQ(ToString(RuleKind::kMissRatio), "miss_ratio");
}

TEST(QosRules, DefaultsAreOnePercentAndAtMostOneMissPerControllerPeriod) {
  const auto rules = DefaultRules();
  ASSERT_EQ(rules.size(), 2U);
  EXPECT_EQ(rules[0], MakeMissRatioRule(1.0));
  EXPECT_EQ(rules[1], MakeMkRule(3, 4));
  EXPECT_EQ(DefaultRulesFor(8000, 1000)[1], MakeMkRule(7, 8));
  EXPECT_EQ(DefaultRulesFor(20000, 1000)[1], MakeMkRule(19, 20));
  EXPECT_EQ(DefaultRulesFor(4500, 1000)[1], MakeMkRule(3, 4));  // whole periods only
  EXPECT_EQ(DefaultRulesFor(1000, 1000)[1], MakeMkRule(1, 2));  // never two in a row
  EXPECT_EQ(DefaultRulesFor(500, 1000)[1], MakeMkRule(1, 2));
  EXPECT_EQ(DefaultRulesFor(1e9, 1)[1], MakeMkRule(kMaxWindowCycles - 1, kMaxWindowCycles));
  EXPECT_THROW((void)DefaultRulesFor(0, 1000), std::invalid_argument);
  EXPECT_THROW((void)DefaultRulesFor(4000, -1), std::invalid_argument);
  EXPECT_THROW((void)DefaultRulesFor(std::nan(""), 1000), std::invalid_argument);
}

}  // namespace
}  // namespace hiltwin::qos
