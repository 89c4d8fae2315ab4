#include "guiding/cell_cache.h"

#include <algorithm>

namespace rlpbrt::guiding {

CellCache::CellCache(const glm::vec3& boundsMin, const glm::vec3& boundsMax, float cellSize,
                     size_t capacity)
    : origin_(boundsMin) {
    const glm::vec3 extent = glm::max(boundsMax - boundsMin, glm::vec3(0.f));
    const float longest = std::max({extent.x, extent.y, extent.z});
    const float minCell = longest / float((1 << kAxisBits) - 1);
    cell_ = std::max(cellSize, minCell);
    if (!(cell_ > 0.f) || !std::isfinite(cell_))
        cell_ = std::isfinite(longest) && longest > 0.f ? longest : 1.f;
    invCell_ = 1.f / cell_;
    size_t cap = 1024;
    while (cap < capacity && cap < (size_t(1) << 28)) cap <<= 1;
    mask_ = cap - 1;
    entries_ = std::make_unique<Entry[]>(cap);
}

uint64_t CellCache::keyOf(const glm::vec3& p, glm::vec3* centre) const {
    constexpr int64_t maxCell = (int64_t(1) << kAxisBits) - 1;
    uint64_t key = 0;
    for (int a = 0; a < 3; ++a) {
        const float f = std::floor((p[a] - origin_[a]) * invCell_);
        const int64_t c = f <= 0.f ? 0 : f >= float(maxCell) ? maxCell : int64_t(f);
        (*centre)[a] = origin_[a] + (float(c) + 0.5f) * cell_;
        key |= uint64_t(c) << (a * kAxisBits);
    }
    return key;
}

}  // namespace rlpbrt::guiding
