#pragma once
// Small RAII wrappers over FFTW3 buffers and plans (private to the analysis module).

#include <fftw3.h>

#include <complex>
#include <cstddef>
#include <new>
#include <stdexcept>

namespace hiltwin::analysis::detail {

template <typename T>
class FftwBuffer {
 public:
  explicit FftwBuffer(std::size_t n) : size_(n), data_(static_cast<T*>(fftw_malloc(sizeof(T) * n))) {
    if (data_ == nullptr) throw std::bad_alloc();
  }
  ~FftwBuffer() { fftw_free(data_); }
  FftwBuffer(const FftwBuffer&) = delete;
  FftwBuffer& operator=(const FftwBuffer&) = delete;
  T* data() noexcept { return data_; }
  T& operator[](std::size_t i) noexcept { return data_[i]; }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }

 private:
  std::size_t size_;
  T* data_;
};

using ComplexBuffer = FftwBuffer<fftw_complex>;
using RealBuffer = FftwBuffer<double>;

class FftwPlan {
 public:
  explicit FftwPlan(fftw_plan plan) : plan_(plan) {
    if (plan_ == nullptr) throw std::runtime_error("FFTW could not create a plan");
  }
  ~FftwPlan() { fftw_destroy_plan(plan_); }
  FftwPlan(const FftwPlan&) = delete;
  FftwPlan& operator=(const FftwPlan&) = delete;
  void Execute() const noexcept { fftw_execute(plan_); }
  [[nodiscard]] fftw_plan get() const noexcept { return plan_; }

 private:
  fftw_plan plan_;
};

inline std::complex<double> ToComplex(const fftw_complex& c) { return {c[0], c[1]}; }

}  // namespace hiltwin::analysis::detail
