#pragma once
/// The files a test reads or runs, found at run time beside the test program
/// (hiltwin_test_paths in cmake/HiltwinTargets.cmake): the build gives each as a path relative
/// to the test program's folder, so no compile command holds the clone's folder and a second
/// clone's compiler cache hits the test units the first one compiled.

namespace hiltwin::test {

/// `relative` (to the folder of the running test program, /proc/self/exe) as an absolute,
/// normalised path. The string lives until the program ends; thread-safe.
const char* BesideTest(const char* relative);

}  // namespace hiltwin::test
