#pragma once
// NoEigenMalloc: while one lives, an Eigen heap allocation fails eigen_assert (the test aborts at the
// allocating line). Live only in a build with -DMANNEQUIN_CHECK_RUNTIME_MALLOC=ON, which defines
// EIGEN_RUNTIME_NO_MALLOC and keeps asserts on (-UNDEBUG); elsewhere it does nothing and
// NoEigenMalloc::kActive is false. Complements alloc_counter.hpp (which counts every malloc).
#include <Eigen/Core>

class NoEigenMalloc {
 public:
#if defined(EIGEN_RUNTIME_NO_MALLOC) && !defined(NDEBUG)
  static constexpr bool kActive = true;
  NoEigenMalloc() : previous_(Eigen::internal::is_malloc_allowed()) { Eigen::internal::set_is_malloc_allowed(false); }
  ~NoEigenMalloc() { Eigen::internal::set_is_malloc_allowed(previous_); }

 private:
  bool previous_;

 public:
#else
  static constexpr bool kActive = false;
  NoEigenMalloc() {}   // user-provided: a guard variable is "used" in both builds
  ~NoEigenMalloc() {}
#endif
  NoEigenMalloc(const NoEigenMalloc&) = delete;
  NoEigenMalloc& operator=(const NoEigenMalloc&) = delete;
};
