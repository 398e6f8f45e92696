#pragma once
// Whether this build runs under a sanitizer that brings its own allocator (AddressSanitizer,
// ThreadSanitizer, MemorySanitizer): then malloc is the sanitizer's, `floedem bench` counts only
// operator new (allocation_count.cpp), and a long run is several times slower (the tests shorten
// theirs). GCC names them __SANITIZE_*__, clang __has_feature(*_sanitizer).
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define FLOEDEM_SANITIZER_ALLOCATOR 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define FLOEDEM_SANITIZER_ALLOCATOR 1
#endif

namespace floedem {
#if defined(FLOEDEM_SANITIZER_ALLOCATOR)
inline constexpr bool kSanitizerAllocator = true;
#else
inline constexpr bool kSanitizerAllocator = false;
#endif
}  // namespace floedem
