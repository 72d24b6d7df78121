#pragma once
// Where the test controller libraries are (tests/controllers), and the call counters the test
// library exports.
#include <dlfcn.h>

#include <array>
#include <string>

#include "fakes/test_paths.h"

namespace hiltwin::controller::test {

/// <build>/tests/controllers/<name>.so
inline std::string Lib(const std::string& name) {
  return std::string(hiltwin::test::BesideTest(HILTWIN_TEST_CONTROLLER_DIR)) + "/" + name +
         ".so";
}

/// How often each entry point of a test_controller.c library was called: create, start, step,
/// finish, destroy. Read from the library the loader has open (RTLD_NOLOAD: never a second
/// copy), so all zero when it is not loaded.
inline std::array<int, 5> Calls(const std::string& library) {
  void* handle = dlopen(library.c_str(), RTLD_NOW | RTLD_NOLOAD);
  if (handle == nullptr) return {};
  const auto* calls = static_cast<const int*>(dlsym(handle, "hiltwin_test_calls"));
  std::array<int, 5> out{};
  if (calls != nullptr) {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = calls[i];
  }
  dlclose(handle);
  return out;
}

}  // namespace hiltwin::controller::test
