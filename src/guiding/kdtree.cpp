#include "guiding/kdtree.h"

#include <algorithm>
#include <cfloat>

namespace rlpbrt::guiding {

namespace {
constexpr uint32_t kLeaf = 3;
}  // namespace

PointKdTree::PointKdTree(const std::vector<glm::vec3>& points) {
    const size_t n = points.size();
    ids_.resize(n);
    for (size_t i = 0; i < n; ++i) ids_[i] = static_cast<uint32_t>(i);
    depth_ = 0;
    while ((size_t(kLeafSize) << depth_) < n && depth_ < kMaxDepth - 1) ++depth_;
    nodes_.resize((size_t(1) << (depth_ + 1)) - 1);
    build(points, 0, 0, n, 0);
    points_.resize(n);
    for (size_t i = 0; i < n; ++i) points_[i] = points[ids_[i]];
}

void PointKdTree::build(const std::vector<glm::vec3>& points, size_t node, size_t begin,
                        size_t end, int level) {
    Node& nd = nodes_[node];
    nd.begin = static_cast<uint32_t>(begin);
    nd.end = static_cast<uint32_t>(end);
    if (level == depth_) {
        nd.axis = kLeaf;
        nd.split = 0.f;
        return;
    }
    glm::vec3 lo(FLT_MAX), hi(-FLT_MAX);
    for (size_t i = begin; i < end; ++i) {
        lo = glm::min(lo, points[ids_[i]]);
        hi = glm::max(hi, points[ids_[i]]);
    }
    const glm::vec3 ext = hi - lo;
    const int axis = ext.x >= ext.y ? (ext.x >= ext.z ? 0 : 2) : (ext.y >= ext.z ? 1 : 2);
    const size_t mid = begin + (end - begin) / 2;
    if (end > begin) {
        std::nth_element(ids_.begin() + long(begin), ids_.begin() + long(mid),
                         ids_.begin() + long(end), [&](uint32_t a, uint32_t b) {
                             const float pa = points[a][axis], pb = points[b][axis];
                             return pa < pb || (pa == pb && a < b);
                         });
    }
    nd.axis = static_cast<uint32_t>(axis);
    nd.split = end > begin ? points[ids_[mid]][axis] : 0.f;
    build(points, 2 * node + 1, begin, mid, level + 1);
    build(points, 2 * node + 2, mid, end, level + 1);
}

template <class VisitPoint, class Bound>
void PointKdTree::search(const glm::vec3& q, VisitPoint&& visit, Bound&& bound) const {
    // Depth first, nearer child first; a subtree is skipped when its splitting plane is no
    // closer than bound() (the current pruning distance).
    StackItem stack[kMaxDepth];
    int sp = 0;
    uint32_t node = 0;
    for (;;) {
        const Node& nd = nodes_[node];
        if (nd.axis == kLeaf) {
            for (uint32_t i = nd.begin; i < nd.end; ++i) {
                const glm::vec3 d = points_[i] - q;
                visit(i, glm::dot(d, d));
            }
            bool found = false;
            while (sp > 0) {
                const StackItem& it = stack[--sp];
                if (it.dist2 < bound()) {
                    node = it.node;
                    found = true;
                    break;
                }
            }
            if (!found) return;
            continue;
        }
        const float diff = q[int(nd.axis)] - nd.split;
        const uint32_t left = 2 * node + 1;
        stack[sp++] = StackItem{diff < 0.f ? left + 1 : left, diff * diff};
        node = diff < 0.f ? left : left + 1;
    }
}

int PointKdTree::nearest(const glm::vec3& q, float* dist2) const {
    float best = FLT_MAX;
    int bestIndex = -1;
    if (!ids_.empty()) {
        search(
            q,
            [&](uint32_t i, float dd) {
                if (dd < best) {
                    best = dd;
                    bestIndex = static_cast<int>(i);
                }
            },
            [&] { return best; });
    }
    *dist2 = best;
    return bestIndex < 0 ? -1 : static_cast<int>(ids_[size_t(bestIndex)]);
}

int PointKdTree::knn(const glm::vec3& q, int k, uint32_t* indices, float* dist2) const {
    k = std::min({k, kMaxK, static_cast<int>(std::min(ids_.size(), size_t(kMaxK)))});
    if (k <= 0) return 0;
    // Sorted candidates (closest first); the search prunes with the k-th distance.
    uint32_t cand[kMaxK];
    float candD[kMaxK];
    int count = 0;
    auto worst = [&] { return count < k ? FLT_MAX : candD[k - 1]; };
    search(
        q,
        [&](uint32_t i, float dd) {
            if (!(dd < worst())) return;
            int pos = count < k ? count++ : k - 1;
            while (pos > 0 && candD[pos - 1] > dd) {
                candD[pos] = candD[pos - 1];
                cand[pos] = cand[pos - 1];
                --pos;
            }
            candD[pos] = dd;
            cand[pos] = i;
        },
        worst);
    for (int i = 0; i < count; ++i) {
        indices[i] = ids_[cand[i]];
        dist2[i] = candD[i];
    }
    return count;
}

size_t PointKdTree::bytes() const {
    return nodes_.capacity() * sizeof(Node) + points_.capacity() * sizeof(glm::vec3) +
           ids_.capacity() * sizeof(uint32_t);
}

}  // namespace rlpbrt::guiding
