#pragma once
// Counts heap allocations while a function runs. A test executable that counts lists
// tests/common/alloc_counter.cpp among its sources (it defines the counter, and malloc):
// - without AddressSanitizer it interposes malloc (glibc): operator new and Eigen's allocations go through it;
// - under AddressSanitizer (which owns malloc) it installs an allocator hook
//   (__sanitizer_install_malloc_and_free_hooks) that ASan's allocator calls for every allocation.
// countAllocations returns −1 (and the tests skip) only when the hook could not be installed.

namespace mannequin::testutil {

/// Allocations counted since the last reset, and whether counting is on (alloc_counter.cpp).
extern long g_allocations;
extern bool g_counting;

/// Whether countAllocations counts (false only when the sanitizer hook could not be installed).
bool allocationsCountable();

/// Allocations made while f runs (−1 when they cannot be counted).
template <class F>
long countAllocations(F&& f) {
  if (!allocationsCountable()) {
    f();
    return -1;
  }
  g_allocations = 0;
  g_counting = true;
  f();
  g_counting = false;
  return g_allocations;
}

}  // namespace mannequin::testutil

using mannequin::testutil::allocationsCountable;
using mannequin::testutil::countAllocations;
