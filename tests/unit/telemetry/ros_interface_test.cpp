// The ROS 2 interface package ros2/hiltwin_msgs against what the binary publishes: Timing.msg
// and the IDL hiltwin compiles (observe/telemetry/idl/ros_types.idl) must agree field for field
// under ROS 2's .msg-to-IDL mapping, or `ros2 topic echo /NS/timing` would decode garbage; and
// the numeric codes (Timing.msg's constants, docs/telemetry.md's table) must be the enums'.
#include <gtest/gtest.h>

#include <cctype>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "fakes/test_paths.h"
#include "hiltwin/telemetry/codes.h"

namespace hiltwin::telemetry {
namespace {

using Fields = std::vector<std::pair<std::string, std::string>>;  // (type, name), in order

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string Trim(const std::string& text) {
  const std::size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string::npos) return {};
  return text.substr(begin, text.find_last_not_of(" \t") - begin + 1);
}

// A .msg file's fields (type, name) and constants (NAME -> value), comments dropped.
struct Msg {
  Fields fields;
  std::map<std::string, long> constants;
};

Msg ParseMsg(const std::string& text) {
  Msg msg;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    line = Trim(line.substr(0, line.find('#')));
    if (line.empty()) continue;
    const std::size_t space = line.find(' ');
    const std::string type = line.substr(0, space);
    const std::string rest = Trim(line.substr(space + 1));
    const std::size_t equals = rest.find('=');
    if (equals == std::string::npos) {
      msg.fields.emplace_back(type, rest);
    } else {
      msg.constants[Trim(rest.substr(0, equals))] = std::stol(rest.substr(equals + 1));
    }
  }
  return msg;
}

// The members of `module_name`'s struct `struct_name` in an IDL text, types as written.
Fields ParseIdlStruct(const std::string& idl, const std::string& module_name,
                      const std::string& struct_name) {
  const std::size_t module = idl.find("module " + module_name + " ");
  const std::size_t open = idl.find("struct " + struct_name + " {", module);
  if (module == std::string::npos || open == std::string::npos) return {};
  const std::size_t body = idl.find('{', open) + 1;
  std::istringstream in(idl.substr(body, idl.find("};", body) - body));
  Fields fields;
  static const std::regex kMember(R"(^\s*(.+\S)\s+(\w+)\s*;\s*(//.*)?$)");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_match(line, m, kMember)) fields.emplace_back(m[1], m[2]);
  }
  return fields;
}

// ROS 2's mapping of .msg field types onto IDL (design.ros2.org, "Interface definition").
std::string IdlTypeOf(const std::string& msg_type) {
  static const std::map<std::string, std::string> kPrimitive = {{"bool", "boolean"},
                                                                {"byte", "octet"},
                                                                {"char", "uint8"},
                                                                {"float32", "float"},
                                                                {"float64", "double"},
                                                                {"int8", "int8"},
                                                                {"uint8", "uint8"},
                                                                {"int16", "short"},
                                                                {"uint16", "unsigned short"},
                                                                {"int32", "long"},
                                                                {"uint32", "unsigned long"},
                                                                {"int64", "long long"},
                                                                {"uint64", "unsigned long long"},
                                                                {"string", "string"}};
  if (msg_type.ends_with("[]")) {
    return "sequence<" + IdlTypeOf(msg_type.substr(0, msg_type.size() - 2)) + ">";
  }
  const auto it = kPrimitive.find(msg_type);
  return it != kPrimitive.end() ? it->second : "?" + msg_type;
}

std::string PackageName() {
  static const std::regex kName(R"(<name>\s*([a-z0-9_]+)\s*</name>)");
  const std::string xml = ReadText(std::string(HILTWIN_ROS_PACKAGE) + "/package.xml");
  std::smatch m;
  return std::regex_search(xml, m, kName) ? m[1].str() : "";
}

std::string Upper(std::string text) {
  for (char& c : text) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return text;
}

TEST(RosInterfacePackage, TimingMsgIsTheIdlTheBinaryPublishes) {
  const std::string package = PackageName();
  ASSERT_EQ(package, "hiltwin_msgs");
  // ROS 2 names the DDS type <package>::msg::dds_::<Type>_: the IDL's module is the package.
  const Fields idl = ParseIdlStruct(ReadText(HILTWIN_ROS_IDL), package, "Timing_");
  const Msg msg = ParseMsg(ReadText(std::string(HILTWIN_ROS_PACKAGE) + "/msg/Timing.msg"));
  ASSERT_FALSE(idl.empty()) << "no struct Timing_ in module " << package;
  ASSERT_EQ(msg.fields.size(), idl.size()) << "Timing.msg and ros_types.idl differ in length";
  for (std::size_t i = 0; i < idl.size(); ++i) {
    SCOPED_TRACE("field " + std::to_string(i + 1) + " of Timing.msg: " + msg.fields[i].second);
    EXPECT_EQ(msg.fields[i].second, idl[i].second) << "name";
    EXPECT_EQ(IdlTypeOf(msg.fields[i].first), idl[i].first) << "type " << msg.fields[i].first;
  }
}

TEST(RosInterfacePackage, TheMappingCatchesADifference) {
  // The checks above would pass on two empty parses: prove the parsers see a real difference.
  const Msg msg = ParseMsg("uint8 A=1  # one\nint32 x  # m\nfloat64[] y\n");
  EXPECT_EQ(msg.constants.at("A"), 1);
  ASSERT_EQ(msg.fields.size(), 2U);
  EXPECT_EQ(IdlTypeOf(msg.fields[0].first), "long");
  EXPECT_EQ(IdlTypeOf(msg.fields[1].first), "sequence<double>");
  const Fields idl = ParseIdlStruct(
      "module p { module msg { module dds_ {\n  struct T_ {\n    long long x;  // why\n"
      "    sequence<double> y;\n  };\n}; }; };\n",
      "p", "T_");
  ASSERT_EQ(idl.size(), 2U);
  EXPECT_NE(IdlTypeOf(msg.fields[0].first), idl[0].first);  // int32 is long, not long long
  EXPECT_EQ(IdlTypeOf(msg.fields[1].first), idl[1].first);
}

// Every value of the enum, with its name: codes from 0 until the enum's ToString says unknown.
template <typename Enum, typename Name>
std::map<std::string, long> EnumCodes(Name&& name, const std::string& prefix) {
  std::map<std::string, long> codes;
  for (int code = 0; code < 256; ++code) {
    const std::string text = name(static_cast<Enum>(code));
    if (Upper(text) == "UNKNOWN") break;
    codes[prefix + Upper(text)] = code;
  }
  return codes;
}

std::map<std::string, long> AllCodes() {
  std::map<std::string, long> codes =
      EnumCodes<qos::Verdict>([](qos::Verdict v) { return qos::ToString(v); }, "VERDICT_");
  const auto states = EnumCodes<lifecycle::State>(
      [](lifecycle::State s) { return lifecycle::ToString(s); }, "STATE_");
  codes.insert(states.begin(), states.end());
  return codes;
}

TEST(RosInterfacePackage, TimingMsgConstantsAreTheEnumsCodes) {
  const Msg msg = ParseMsg(ReadText(std::string(HILTWIN_ROS_PACKAGE) + "/msg/Timing.msg"));
  EXPECT_EQ(msg.constants, AllCodes());
  EXPECT_EQ(VerdictCode(qos::Verdict::kAborted), 2);
  EXPECT_EQ(StateCode(lifecycle::State::kSafeStop), 7);
}

// docs/telemetry.md's table "| code | verdict | state |": one row per code.
TEST(RosInterfacePackage, TheDocsCodeTableIsTheEnumsCodes) {
  std::istringstream in(ReadText(HILTWIN_TELEMETRY_DOC));
  static const std::regex kRow(R"(^\| (\d+) \| (`([A-Z]+)`)? *\| (`([a-z_]+)`)? *\|$)");
  std::map<std::string, long> documented;
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_match(line, m, kRow)) continue;
    const long code = std::stol(m[1]);
    if (m[3].matched) documented["VERDICT_" + m[3].str()] = code;
    if (m[5].matched) documented["STATE_" + Upper(m[5].str())] = code;
  }
  EXPECT_EQ(documented, AllCodes());
}

}  // namespace
}  // namespace hiltwin::telemetry
