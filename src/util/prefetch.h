// Cache prefetch hints every layer may use (src/util). No effect on results.
#pragma once

#include <cstddef>
#include <cstdint>

namespace rlpbrt {

// Starts loading the cache line at `addr` into every cache level (no effect on results). GCC
// 12 drops a __builtin_prefetch whose address is computed from a float difference converted
// to an integer, as keyOf's is (with NDEBUG, HemiField::prefetch compiled to a bare `ret`
// until session 14), so on x86 the instruction is written out.
inline void prefetchLine(const void* addr) {
#if defined(__x86_64__) || defined(__i386__)
    asm volatile("prefetcht0 %0" : : "m"(*static_cast<const char*>(addr)));
#else
    __builtin_prefetch(addr);
#endif
}

// Starts loading every cache line of [begin, begin + bytes): four prefetches per loop step,
// the address stepping by the line (a loop over elements costs twice the instructions, at
// every vertex of a guided path).
inline void prefetchLines(const void* begin, size_t bytes) {
    constexpr uintptr_t kLine = 64;
    uintptr_t a = reinterpret_cast<uintptr_t>(begin) & ~(kLine - 1);
    const uintptr_t end = reinterpret_cast<uintptr_t>(begin) + bytes;
    for (; a + 3 * kLine < end; a += 4 * kLine) {
        prefetchLine(reinterpret_cast<const void*>(a));
        prefetchLine(reinterpret_cast<const void*>(a + kLine));
        prefetchLine(reinterpret_cast<const void*>(a + 2 * kLine));
        prefetchLine(reinterpret_cast<const void*>(a + 3 * kLine));
    }
    for (; a < end; a += kLine) prefetchLine(reinterpret_cast<const void*>(a));
}

}  // namespace rlpbrt
