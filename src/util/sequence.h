// Low-discrepancy building blocks every layer may use (src/util).
#pragma once

#include <algorithm>
#include <cstdint>

namespace rlpbrt {

// Radical inverse of i in a prime base: the Halton sequence's coordinate, in [0, 1).
inline float radicalInverse(uint64_t i, uint64_t base) {
    const double invBase = 1.0 / static_cast<double>(base);
    double inv = invBase, value = 0.0;
    while (i > 0) {
        uint64_t next = i / base;
        value += static_cast<double>(i - next * base) * inv;
        inv *= invBase;
        i = next;
    }
    return std::min(static_cast<float>(value), 0x1.fffffep-1f);
}

}  // namespace rlpbrt
