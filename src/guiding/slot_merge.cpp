#include "guiding/slot_merge.h"

#include <cstdlib>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace rlpbrt::guiding {

namespace {
constexpr size_t kHugePage = size_t(2) << 20;
constexpr size_t kLargeBuffer = size_t(4) << 20;
}  // namespace

void* allocateLargeBuffer(size_t bytes) {
    if (bytes < kLargeBuffer) return ::operator new(bytes);
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    void* p = std::aligned_alloc(kHugePage, rounded);
    if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    madvise(p, rounded, MADV_HUGEPAGE);  // advice only: without huge pages nothing changes
#endif
    return p;
}

void releaseLargeBuffer(void* p, size_t bytes) noexcept {
    if (!p) return;
    if (bytes < kLargeBuffer)
        ::operator delete(p);
    else
        std::free(p);
}

}  // namespace rlpbrt::guiding
