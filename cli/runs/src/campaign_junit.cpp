// `hiltwin test --junit`: the JUnit XML CI servers read, valid against the schema of Jenkins's
// xunit plugin (junit-10.xsd; tests/unit/campaign/junit.xsd), which GitLab's and GitHub's test
// reporters read as well.
//
// A scenario that could not be judged (ScenarioResult::error: its command crashed, wrote no
// report) is an <error>, one whose criteria failed a <failure> per failed criterion: JUnit's
// own distinction between a test that could not run to its assertions and an assertion that
// did not hold, which Jenkins and GitLab show apart ("errors" and "failures" of a suite). A
// scenario with an error has only the <error>: its criteria failed because it did not run, and
// its message lists them in its text, so the count of failing scenarios is errors + failures.

#include <cmath>
#include <cstdint>

#include "campaign_text.h"
#include "hiltwin/report_kit/string_format.h"
#include "hiltwin/runs/campaign_report.h"

namespace hiltwin::app {
namespace campaign_junit {

using analysis::detail::Format;

constexpr char32_t kReplacement = 0xFFFD;

// What a UTF-8 lead byte announces: how many continuation bytes follow, the code point's bits
// in the lead byte, and the smallest code point that needs that many bytes (a smaller one is
// an overlong encoding). {0, 0, 0} for a byte that starts no sequence.
struct Utf8Lead {
  std::size_t continuation = 0;
  char32_t bits = 0;
  char32_t smallest = 0;
};

Utf8Lead LeadOf(unsigned char lead) {
  if ((lead & 0xE0U) == 0xC0U) return {1, lead & 0x1FU, 0x80};
  if ((lead & 0xF0U) == 0xE0U) return {2, lead & 0x0FU, 0x800};
  if ((lead & 0xF8U) == 0xF0U) return {3, lead & 0x07U, 0x10000};
  return {};
}

// The code point at `text[at]`, advancing `at`; kReplacement for a byte that starts no valid
// UTF-8 sequence (an error may quote a program's output, which is bytes, not text).
char32_t NextCodePoint(std::string_view text, std::size_t& at) {
  const auto lead = static_cast<unsigned char>(text[at++]);
  if (lead < 0x80) return lead;
  const Utf8Lead expected = LeadOf(lead);
  if (expected.continuation == 0 || at + expected.continuation > text.size()) return kReplacement;
  char32_t code = expected.bits;
  for (std::size_t i = 0; i < expected.continuation; ++i) {
    const auto byte = static_cast<unsigned char>(text[at + i]);
    if ((byte & 0xC0U) != 0x80U) return kReplacement;
    code = (code << 6) | (byte & 0x3FU);
  }
  at += expected.continuation;
  const bool surrogate = code >= 0xD800 && code <= 0xDFFF;
  return (code < expected.smallest || surrogate || code > 0x10FFFF) ? kReplacement : code;
}

// XML 1.0's Char production: tab, line feed, carriage return and everything from the space on
// but surrogates, U+FFFE and U+FFFF. Any other character makes the document unreadable.
bool AllowedInXml(char32_t code) {
  if (code < 0x20) return code == 0x9 || code == 0xA || code == 0xD;
  return code != 0xFFFE && code != 0xFFFF;
}

void AppendUtf8(std::string& out, char32_t code) {
  if (code < 0x80) {
    out += static_cast<char>(code);
  } else if (code < 0x800) {
    out += static_cast<char>(0xC0 | (code >> 6));
    out += static_cast<char>(0x80 | (code & 0x3F));
  } else if (code < 0x10000) {
    out += static_cast<char>(0xE0 | (code >> 12));
    out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (code & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (code >> 18));
    out += static_cast<char>(0x80 | ((code >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (code & 0x3F));
  }
}

// The entity or character reference `code` is written as; nullptr: as itself. In an
// attribute, tab and line breaks are written as character references, which a parser keeps (it
// turns literal ones into spaces); a carriage return everywhere, which a parser would turn
// into a line feed.
const char* ReferenceFor(char32_t code, bool in_attribute) {
  switch (code) {
    case '&': return "&amp;";
    case '<': return "&lt;";
    case '>': return "&gt;";
    case '"': return "&quot;";
    case '\'': return "&apos;";
    case '\r': return "&#13;";
    case '\t': return in_attribute ? "&#9;" : nullptr;
    case '\n': return in_attribute ? "&#10;" : nullptr;
    default: return nullptr;
  }
}

// `text` as XML character data or (in_attribute) a double-quoted attribute value: markup
// characters as references, characters XML 1.0 does not allow and invalid UTF-8 as U+FFFD.
std::string Escape(std::string_view text, bool in_attribute) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t at = 0; at < text.size();) {
    const char32_t code = NextCodePoint(text, at);
    if (const char* reference = ReferenceFor(code, in_attribute)) {
      out += reference;
    } else {
      AppendUtf8(out, AllowedInXml(code) ? code : kReplacement);
    }
  }
  return out;
}

std::string Attribute(const char* name, std::string_view value) {
  return std::string(" ") + name + "=\"" + Escape(value, true) + "\"";
}

// The schema's time: digits and a decimal point only (no sign, no exponent).
std::string Seconds(double wall_s) {
  return Format("%.3f", std::isfinite(wall_s) && wall_s > 0.0 ? wall_s : 0.0);
}

struct Counts {
  std::size_t tests = 0;
  std::size_t failures = 0;  // failed scenarios without an error
  std::size_t errors = 0;    // scenarios with an error
};

Counts CountOf(const CampaignResult& result) {
  Counts counts;
  counts.tests = result.scenarios.size();
  for (const ScenarioResult& scenario : result.scenarios) {
    if (!scenario.error.empty()) {
      ++counts.errors;
    } else if (!scenario.passed()) {
      ++counts.failures;
    }
  }
  return counts;
}

std::string CountAttributes(const Counts& counts) {
  return Attribute("tests", std::to_string(counts.tests)) +
         Attribute("failures", std::to_string(counts.failures)) +
         Attribute("errors", std::to_string(counts.errors));
}

std::string Properties(const CampaignResult& result) {
  std::string xml = "    <properties>\n";
  const auto property = [&xml](const char* name, const std::string& value) {
    xml += "      <property" + Attribute("name", name) + Attribute("value", value) + "/>\n";
  };
  property("file", result.file);
  property("scenarios_in_file", std::to_string(result.scenarios_in_file));
  property("filter", result.filter);
  property("shards", campaign_text::ShardsLabel(result));
  return xml + "    </properties>\n";
}

std::string ErrorElement(const ScenarioResult& scenario) {
  std::string text = scenario.error;
  for (const CriterionResult& criterion : scenario.criteria) {
    if (!criterion.passed)
      text += "\n" + criterion.name + ": " + campaign_text::Shortfall(criterion);
  }
  return "      <error" + Attribute("message", campaign_text::OneLine(scenario.error)) +
         Attribute("type", "scenario error") + ">" + Escape(text, false) + "</error>\n";
}

std::string FailureElements(const ScenarioResult& scenario) {
  std::string xml;
  for (const CriterionResult& criterion : scenario.criteria) {
    if (criterion.passed) continue;
    const std::string message = criterion.name + ": " + campaign_text::Shortfall(criterion);
    xml += "      <failure" + Attribute("message", message) + Attribute("type", criterion.name) +
           ">" + Escape(message, false) + "</failure>\n";
  }
  return xml;
}

// What the scenario was, for the CI server's page of the test case.
std::string SystemOut(const ScenarioResult& scenario) {
  std::string text = "kind " + scenario.kind + ", clock " + scenario.clock;
  if (!scenario.controller.empty()) text += ", controller " + scenario.controller;
  text += ", exit code " + std::to_string(scenario.exit_code);
  if (!scenario.verdict.empty()) text += ", verdict " + scenario.verdict;
  return "      <system-out>" + Escape(text, false) + "</system-out>\n";
}

std::string TestCase(const std::string& campaign, const ScenarioResult& scenario) {
  std::string xml = "    <testcase" + Attribute("classname", campaign) +
                    Attribute("name", scenario.name) + Attribute("time", Seconds(scenario.wall_s)) +
                    ">\n";
  xml += scenario.error.empty() ? FailureElements(scenario) : ErrorElement(scenario);
  xml += SystemOut(scenario);
  return xml + "    </testcase>\n";
}

}  // namespace campaign_junit

std::string ToJunitXml(const CampaignResult& result) {
  using campaign_junit::Attribute;
  const std::string counts = campaign_junit::CountAttributes(campaign_junit::CountOf(result));
  const std::string time = Attribute("time", campaign_junit::Seconds(result.wall_s));
  std::string xml = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  xml += "<testsuites" + Attribute("name", result.name) + counts + time + ">\n";
  xml += "  <testsuite" + Attribute("name", result.name) + counts + Attribute("skipped", "0") +
         time + ">\n";
  xml += campaign_junit::Properties(result);
  for (const ScenarioResult& scenario : result.scenarios) {
    xml += campaign_junit::TestCase(result.name, scenario);
  }
  return xml + "  </testsuite>\n</testsuites>\n";
}

}  // namespace hiltwin::app
