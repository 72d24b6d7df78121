// Built with EIGEN_RUNTIME_NO_MALLOC and assertions on, together with the model's sources
// (see CMakeLists.txt): any Eigen heap allocation inside the guarded region aborts.
#ifndef EIGEN_RUNTIME_NO_MALLOC
#error "this test must be compiled with EIGEN_RUNTIME_NO_MALLOC"
#endif
#ifdef NDEBUG
#error "this test needs assertions (Eigen's allocation check is an eigen_assert)"
#endif

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "fakes/alloc_counter.h"
#include "hiltwin/relbot/relbot_model.h"

namespace hiltwin::app {
namespace {

/// Forbids Eigen heap allocation for its lifetime.
class NoEigenMalloc {
 public:
  NoEigenMalloc() { Eigen::internal::set_is_malloc_allowed(false); }
  ~NoEigenMalloc() { Eigen::internal::set_is_malloc_allowed(true); }
  NoEigenMalloc(const NoEigenMalloc&) = delete;
  NoEigenMalloc& operator=(const NoEigenMalloc&) = delete;
};

// The guard is live: a dynamic-size Eigen vector under it aborts the process.
TEST(RelbotNoMallocDeathTest, GuardCatchesADynamicEigenAllocation) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_DEATH(
      {
        NoEigenMalloc guard;
        Eigen::VectorXd v(64);
        v.setOnes();
        std::printf("%f\n", v.sum());
      },
      "is_malloc_allowed");
}

TEST(RelbotNoMalloc, StepOutputsAndFiniteCheckAllocateNothing) {
  for (const Integrator method : {Integrator::kEuler, Integrator::kRk2, Integrator::kRk4}) {
    RelbotModel model(RelbotParams{}, method, 2.5e-4);
    RelbotOutputs out;
    bool finite = false;
    std::uint64_t allocations = 0;
    {
      NoEigenMalloc guard;
      test::ScopedAllocationCount count;
      for (int k = 0; k < 4000; ++k) {
        model.Step(0.6 * ((k / 500) % 2 == 0 ? 1.0 : -0.5), 0.4);
        finite = model.StateIsFinite();
      }
      out = model.Outputs();
      model.Reset();
      model.Step(1.0, 1.0);
      allocations = count.count();
    }
    EXPECT_EQ(allocations, 0U) << IntegratorName(method);
    EXPECT_TRUE(finite);
    EXPECT_NE(out.wheel_left_m, 0.0);
    EXPECT_NE(out.theta_rad, 0.0);
  }
}

}  // namespace
}  // namespace hiltwin::app
