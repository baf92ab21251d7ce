// Counts every heap allocation of the test executable that includes it (once).
//
// Under a sanitizer (APPELL_SANITIZED: ASan owns malloc, replacing it would
// fight the sanitizer) the count comes from the sanitizer's own allocation
// hook instead, so these tests keep asserting in sanitized builds.
//
// The global operator new / delete are replaced, and so are malloc, calloc,
// realloc and the aligned allocators: Eigen's dynamic matrices allocate through
// malloc, not operator new, so counting only `new` would miss exactly the
// allocations that matter. The replacements forward to glibc's __libc_* entry
// points. Counting is off until g_counting is set.
#pragma once

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>

#if defined(APPELL_SANITIZED)
#include <sanitizer/allocator_interface.h>
namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
void countingHook(const volatile void*, size_t) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
void ignoreFree(const volatile void*) {}
[[maybe_unused]] const int g_hooks_installed = __sanitizer_install_malloc_and_free_hooks(countingHook, ignoreFree);
}  // namespace
#else
extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
void __libc_free(void*);
}

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
inline void note() {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

extern "C" {
void* malloc(size_t n) {
  note();
  return __libc_malloc(n);
}
void* calloc(size_t n, size_t s) {
  note();
  return __libc_calloc(n, s);
}
void* realloc(void* p, size_t n) {
  note();
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
void* aligned_alloc(size_t align, size_t n) {
  note();
  return __libc_memalign(align, n);
}
void* memalign(size_t align, size_t n) {
  note();
  return __libc_memalign(align, n);
}
int posix_memalign(void** out, size_t align, size_t n) {
  note();
  *out = __libc_memalign(align, n);
  return *out ? 0 : ENOMEM;
}
}

void* operator new(size_t n) {
  note();
  if (void* p = __libc_malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](size_t n) { return operator new(n); }
void* operator new(size_t n, std::align_val_t a) {
  note();
  if (void* p = __libc_memalign(static_cast<size_t>(a), n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](size_t n, std::align_val_t a) { return operator new(n, a); }
void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete[](void* p) noexcept { __libc_free(p); }
void operator delete(void* p, size_t) noexcept { __libc_free(p); }
void operator delete[](void* p, size_t) noexcept { __libc_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete(void* p, size_t, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, size_t, std::align_val_t) noexcept { __libc_free(p); }

#endif  // APPELL_SANITIZED

/// Allocations made by `fn` over `reps` calls, after one warm-up call (which may
/// size workspaces).
template <typename F>
long allocationsIn(F&& fn, int reps = 20) {
  fn();
  g_allocations = 0;
  g_counting = true;
  for (int r = 0; r < reps; ++r) fn();
  g_counting = false;
  return g_allocations.load();
}
