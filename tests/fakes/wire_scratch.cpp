#include "fakes/wire_scratch.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <system_error>

namespace hiltwin::test {

namespace fs = std::filesystem;

WireScratch::WireScratch(const std::string& prefix) {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string test = info != nullptr ? info->name() : "no-test";
  // A parameterised test is named CASE/PARAM: one path component and a valid wire name.
  std::replace(test.begin(), test.end(), '/', '_');
  const std::string pid = std::to_string(::getpid());
  wire_ = prefix + "-" + pid + "-" + test.substr(0, 24);
  dir_ = fs::temp_directory_path() / ("hiltwin_" + prefix + "_" + pid + "_" + test);
  fs::create_directories(dir_);
}

WireScratch::~WireScratch() {
  std::error_code ignored;  // a destructor must not throw; a leftover is reported by the test
  fs::remove(SegmentPath(), ignored);
  fs::remove_all(dir_, ignored);
}

}  // namespace hiltwin::test
