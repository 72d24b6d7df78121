#pragma once
// What the plant integration tests share: a per-test temporary folder with files written into
// it, and the analytic answer the mass-spring-damper plants are checked against.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

namespace hiltwin::test {

/// A fresh folder per test, removed after it.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("hiltwin_plant_" + std::to_string(getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  [[nodiscard]] std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  /// Writes `text` to the folder's `name` and returns its path.
  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(Path(name)) << text;
    return Path(name);
  }

  std::filesystem::path dir_;
};

/// x(t) of m x'' + c x' + k x = 0 from x(0) = x0 at rest, under-damped (c^2 < 4 k m).
inline double UnderdampedFreeResponseM(double x0_m, double m_kg, double k_n_per_m,
                                       double c_n_s_per_m, double t_s) {
  const double wn = std::sqrt(k_n_per_m / m_kg);
  const double zeta = c_n_s_per_m / (2.0 * std::sqrt(k_n_per_m * m_kg));
  const double wd = wn * std::sqrt(1.0 - zeta * zeta);
  return x0_m * std::exp(-zeta * wn * t_s) *
         (std::cos(wd * t_s) + zeta * wn / wd * std::sin(wd * t_s));
}

}  // namespace hiltwin::test
