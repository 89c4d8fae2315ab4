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

}  // namespace rlpbrt::guiding
