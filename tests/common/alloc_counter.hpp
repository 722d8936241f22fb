#pragma once
// Counts heap allocations by interposing malloc (glibc). Include it in ONE translation unit of a test
// executable (it defines malloc). Without AddressSanitizer only: ASan owns malloc, so there
// countAllocations runs f and returns −1 (tests skip).
#include <cstddef>

#if !defined(__SANITIZE_ADDRESS__)
namespace {
long g_allocations = 0;
bool g_counting = false;
}  // namespace
extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* malloc(std::size_t size) {
  if (g_counting) ++g_allocations;
  return __libc_malloc(size);
}
#endif

namespace {
/// Allocations made while f runs (−1 under AddressSanitizer).
template <class F>
long countAllocations(F&& f) {
#if !defined(__SANITIZE_ADDRESS__)
  g_allocations = 0;
  g_counting = true;
  f();
  g_counting = false;
  return g_allocations;
#else
  f();
  return -1;
#endif
}
}  // namespace
