// Counting the process's heap allocations, for `floedem bench`. Linked into the floedem
// executable only (not the libraries).
//
// With glibc, and no sanitizer that brings its own allocator, the executable defines malloc,
// calloc, realloc, free and the aligned forms, each forwarding to glibc's own (__libc_malloc and
// kin, the entry points glibc exports for this; "Replacing malloc" in the glibc manual). That
// counts every allocation: operator new's (it calls malloc), and what Eigen, HDF5 and the C
// library ask of malloc directly. Elsewhere (AddressSanitizer, ThreadSanitizer, other C
// libraries) only the global operator new is replaced and counted.
#include "app/allocation_count.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

#include "app/sanitizer.hpp"

#if defined(__GLIBC__) && !defined(FLOEDEM_SANITIZER_ALLOCATOR)
#define FLOEDEM_COUNT_MALLOC 1
#endif

namespace {
std::atomic<std::uint64_t> g_allocations{0};

inline void count() { g_allocations.fetch_add(1, std::memory_order_relaxed); }

#if FLOEDEM_COUNT_MALLOC
inline void count_in_new() {}  // malloc counts it
#else
inline void count_in_new() { count(); }
#endif

void* allocate(std::size_t size) {
  count_in_new();
  if (size == 0) size = 1;
  for (;;) {
    if (void* p = std::malloc(size)) return p;
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}

void* allocate_aligned(std::size_t size, std::align_val_t align) {
  count_in_new();
  const auto a = static_cast<std::size_t>(align);
  const std::size_t rounded = ((size == 0 ? 1 : size) + a - 1) / a * a;  // aligned_alloc needs a multiple
  for (;;) {
    if (void* p = std::aligned_alloc(a, rounded)) return p;
    std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}
}  // namespace

#if FLOEDEM_COUNT_MALLOC
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t size) {
  count();
  return __libc_malloc(size);
}
void* calloc(std::size_t n, std::size_t size) {
  count();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t size) {
  if (size != 0 || p == nullptr) count();  // realloc(p, 0) frees
  return __libc_realloc(p, size);
}
void free(void* p) { __libc_free(p); }
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  count();
  return __libc_memalign(alignment, size);
}
void* memalign(std::size_t alignment, std::size_t size) {
  count();
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  // EINVAL (22) unless a power of two that is a multiple of sizeof(void*); ENOMEM (12).
  if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0) return 22;
  count();
  void* p = __libc_memalign(alignment, size);
  if (p == nullptr && size != 0) return 12;
  *out = p;
  return 0;
}
}
#endif

std::uint64_t floedem::allocations_so_far() { return g_allocations.load(std::memory_order_relaxed); }

void* operator new(std::size_t size) { return allocate(size); }
void* operator new[](std::size_t size) { return allocate(size); }
void* operator new(std::size_t size, std::align_val_t align) { return allocate_aligned(size, align); }
void* operator new[](std::size_t size, std::align_val_t align) { return allocate_aligned(size, align); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return allocate(size);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return allocate(size);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
