#include "engine/line_vector.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace floedem {

void advise_huge_pages(void* p, std::size_t bytes) noexcept {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  (void)madvise(p, bytes, MADV_HUGEPAGE);  // a hint: on failure (EINVAL without THP) small pages serve as before
#else
  (void)p;
  (void)bytes;
#endif
}

}  // namespace floedem
