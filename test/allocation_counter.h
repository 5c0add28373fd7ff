// Counts heap allocations: this header defines malloc, calloc, realloc, free
// and the aligned allocators, so the dynamic linker binds every call in the
// process to them (ELF symbol interposition: operator new, Eigen's aligned
// buffers, nanoflann's pools and libgomp's teams all end in malloc). Each
// forwards to glibc's own entry (__libc_*) and, while counting is on, adds one.
//
// Include it in exactly one source file of an executable (it defines the
// symbols; a second copy is a link error). Under AddressSanitizer, which
// replaces the same symbols, nothing is defined and counting_available() is
// false: the tests that count then say so and pass.
#pragma once
#include <atomic>
#include <cstddef>

#if defined(__SANITIZE_ADDRESS__)
#define JSA_ALLOCATION_COUNTER 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer) || \
    __has_feature(thread_sanitizer)
#define JSA_ALLOCATION_COUNTER 0
#endif
#endif
#ifndef JSA_ALLOCATION_COUNTER
#define JSA_ALLOCATION_COUNTER 1
#endif

namespace allocation_counter {

inline std::atomic<bool> counting{false};
inline std::atomic<long> count{0};
// Called on every counted allocation when set (bench_step_allocations --where
// records a backtrace there); it must not allocate.
inline void (*on_allocation)() = nullptr;

inline bool counting_available() { return JSA_ALLOCATION_COUNTER != 0; }
inline void start() {
  count.store(0);
  counting.store(true);
}
// The allocations since start().
inline long stop() {
  counting.store(false);
  return count.load();
}
inline void add_one() {
  if (!counting.load(std::memory_order_relaxed)) return;
  count.fetch_add(1, std::memory_order_relaxed);
  if (on_allocation) on_allocation();
}

}  // namespace allocation_counter

#if JSA_ALLOCATION_COUNTER
extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void __libc_free(void*);
void* __libc_memalign(size_t, size_t);

void* malloc(size_t n) {
  allocation_counter::add_one();
  return __libc_malloc(n);
}
void* calloc(size_t n, size_t size) {
  allocation_counter::add_one();
  return __libc_calloc(n, size);
}
void* realloc(void* p, size_t n) {
  allocation_counter::add_one();
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
void* memalign(size_t alignment, size_t n) {
  allocation_counter::add_one();
  return __libc_memalign(alignment, n);
}
void* aligned_alloc(size_t alignment, size_t n) {
  allocation_counter::add_one();
  return __libc_memalign(alignment, n);
}
int posix_memalign(void** out, size_t alignment, size_t n) {
  allocation_counter::add_one();
  void* p = __libc_memalign(alignment, n);
  if (!p) return 12;  // ENOMEM
  *out = p;
  return 0;
}
}
#endif
