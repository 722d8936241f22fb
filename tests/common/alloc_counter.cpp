// The allocation counter of alloc_counter.hpp: malloc interposed, or an AddressSanitizer allocator hook.
#include "alloc_counter.hpp"

#include <cstddef>

#if defined(__SANITIZE_ADDRESS__)
#define MANNEQUIN_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MANNEQUIN_TEST_ASAN 1
#endif
#endif

namespace mannequin::testutil {
long g_allocations = 0;
bool g_counting = false;
}  // namespace mannequin::testutil

#if defined(MANNEQUIN_TEST_ASAN)
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*, std::size_t),
                                                         void (*free_hook)(const volatile void*));
namespace {
void countingMallocHook(const volatile void*, std::size_t) {
  if (mannequin::testutil::g_counting) ++mannequin::testutil::g_allocations;
}
void ignoringFreeHook(const volatile void*) {}
// installed before main, while the process has one thread (as the sanitizer interface requires)
const bool g_hook_installed = __sanitizer_install_malloc_and_free_hooks(countingMallocHook, ignoringFreeHook) > 0;
}  // namespace

bool mannequin::testutil::allocationsCountable() { return g_hook_installed; }
#else
extern "C" void* __libc_malloc(std::size_t size);
extern "C" void* malloc(std::size_t size) {
  if (mannequin::testutil::g_counting) ++mannequin::testutil::g_allocations;
  return __libc_malloc(size);
}

bool mannequin::testutil::allocationsCountable() { return true; }
#endif
