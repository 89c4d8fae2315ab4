#include "guiding/dir_tree.h"

#include <algorithm>
#include <cmath>

#include "guiding/directional.h"
#include "util/math.h"

namespace rlpbrt::guiding {

namespace {

// The largest float below 1: rescaled sample coordinates stay in [0, 1).
constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

float clampUnit(float x) {
    if (!(x > 0.f)) return 0.f;  // also NaN
    return x < 1.f ? x : 1.f;
}

// Child k's share of a node of mass m with children masses c[0..3]: m > 0 ? c[k] / m : 1/4.
float share(float childMass, float mass) { return mass > 0.f ? childMass / mass : 0.25f; }

}  // namespace

DirTree::DirTree() : nodes_(1) { nodes_[0].mass = 1.f; }

uint32_t DirTree::leafOf(glm::vec2 a, int* depth) const {
    a.x = clampUnit(a.x);
    a.y = clampUnit(a.y);
    uint32_t i = 0;
    int d = 0;
    while (!nodes_[i].leaf()) {
        // The point's coordinates within the node's square, doubled at each level.
        const int bx = a.x >= 0.5f, by = a.y >= 0.5f;
        a.x = a.x * 2.f - float(bx);
        a.y = a.y * 2.f - float(by);
        i = nodes_[i].child + uint32_t(bx + 2 * by);
        ++d;
    }
    if (depth) *depth = d;
    return i;
}

void DirTree::square(uint32_t target, glm::vec2* origin, float* edge) const {
    // Nodes know their children, not their parents: find the parent of each node on the way
    // up (a walk over the nodes; for tests and rebuilds, not per vertex).
    glm::vec2 o(0.f);
    float e = 1.f;
    uint32_t i = target;
    while (i != 0) {
        uint32_t parent = 0;
        for (uint32_t n = 0; n < nodes_.size(); ++n) {
            const uint32_t c = nodes_[n].child;
            if (c != 0 && c <= i && i < c + 4) {
                parent = n;
                break;
            }
        }
        const uint32_t k = i - nodes_[parent].child;
        o = 0.5f * (o + glm::vec2(float(k & 1), float(k >> 1)));
        e *= 0.5f;
        i = parent;
    }
    *origin = o;
    *edge = e;
}

std::vector<glm::vec3> DirTree::squares() const {
    // Parents come before their children: one forward sweep.
    std::vector<glm::vec3> sq(nodes_.size());
    sq[0] = glm::vec3(0.f, 0.f, 1.f);
    for (size_t i = 0; i < nodes_.size(); ++i) {
        if (nodes_[i].leaf()) continue;
        const float e = 0.5f * sq[i].z;
        for (uint32_t k = 0; k < 4; ++k)
            sq[nodes_[i].child + k] = glm::vec3(sq[i].x + e * float(k & 1),
                                                sq[i].y + e * float(k >> 1), e);
    }
    return sq;
}

float DirTree::density(glm::vec2 a, uint32_t* leaf) const {
    a.x = clampUnit(a.x);
    a.y = clampUnit(a.y);
    uint32_t i = 0;
    float d = 1.f;
    while (!nodes_[i].leaf()) {
        const int bx = a.x >= 0.5f, by = a.y >= 0.5f;
        a.x = a.x * 2.f - float(bx);
        a.y = a.y * 2.f - float(by);
        const uint32_t c = nodes_[i].child + uint32_t(bx + 2 * by);
        d *= 4.f * share(nodes_[c].mass, nodes_[i].mass);
        i = c;
    }
    if (leaf) *leaf = i;
    return d;
}

glm::vec2 DirTree::sample(glm::vec2 u, float* density, uint32_t* leaf) const {
    u.x = std::min(clampUnit(u.x), kOneMinusEpsilon);
    u.y = std::min(clampUnit(u.y), kOneMinusEpsilon);
    glm::vec2 origin(0.f);
    float edge = 1.f, d = 1.f;
    uint32_t i = 0;
    while (!nodes_[i].leaf()) {
        const uint32_t c = nodes_[i].child;
        const float m = nodes_[i].mass;
        float s[4];
        for (int k = 0; k < 4; ++k) s[k] = share(nodes_[c + k].mass, m);
        // The half in x, then the half in y within it; each coordinate is rescaled to [0, 1)
        // within the chosen half so that the next level draws from it again.
        const float left = s[0] + s[2];
        int bx;
        if (u.x < left || s[1] + s[3] <= 0.f) {
            bx = 0;
            u.x = left > 0.f ? u.x / left : 0.f;
        } else {
            bx = 1;
            u.x = (u.x - left) / (1.f - left);
        }
        const float lower = s[bx], upper = s[bx + 2], column = lower + upper;
        int by;
        if (u.y * column < lower || upper <= 0.f) {
            by = 0;
            u.y = lower > 0.f ? u.y * column / lower : 0.f;
        } else {
            by = 1;
            u.y = (u.y * column - lower) / upper;
        }
        u.x = std::min(clampUnit(u.x), kOneMinusEpsilon);
        u.y = std::min(clampUnit(u.y), kOneMinusEpsilon);
        const int k = bx + 2 * by;
        d *= 4.f * s[k];
        edge *= 0.5f;
        origin += edge * glm::vec2(float(bx), float(by));
        i = c + uint32_t(k);
    }
    if (density) *density = d;
    if (leaf) *leaf = i;
    // The point inside the leaf's square, kept inside it against rounding.
    glm::vec2 a = origin + edge * u;
    const float maxX = std::nextafter(origin.x + edge, 0.f);
    const float maxY = std::nextafter(origin.y + edge, 0.f);
    a.x = std::min(a.x, maxX);
    a.y = std::min(a.y, maxY);
    return a;
}

void DirTree::setLeafMasses(const std::vector<float>& mass) {
    // Children come after their parents, so one backward sweep sums every subtree.
    for (size_t n = nodes_.size(); n-- > 0;) {
        Node& node = nodes_[n];
        if (node.leaf()) {
            const float m = n < mass.size() ? mass[n] : 0.f;
            node.mass = std::isfinite(m) && m > 0.f ? m : 0.f;
        } else {
            const uint32_t c = node.child;
            node.mass = nodes_[c].mass + nodes_[c + 1].mass + nodes_[c + 2].mass +
                        nodes_[c + 3].mass;
        }
    }
}

DirTree DirTree::refined(double splitShare, int maxDepth, std::vector<Source>* sources) const {
    maxDepth = std::clamp(maxDepth, 0, kMaxDepth);
    splitShare = std::clamp(splitShare, 1e-9, 1.0);
    DirTree out;
    std::vector<Source> src(1);
    const double total = nodes_[0].mass;
    out.nodes_[0].mass = nodes_[0].mass;
    if (!(total > 0.0) || !std::isfinite(total)) {
        if (sources) *sources = std::move(src);
        return out;
    }
    // Breadth-first over the new tree: a new node n knows its old source (a node, or a piece
    // of an old leaf) and its depth; it is split while its mass share is above splitShare.
    struct Item {
        uint32_t node;
        int depth;
    };
    std::vector<Item> queue{{0, 0}};
    for (size_t q = 0; q < queue.size(); ++q) {
        const Item it = queue[q];
        const float mass = out.nodes_[it.node].mass;
        if (!(double(mass) > splitShare * total) || it.depth >= maxDepth) continue;
        const Source s = src[it.node];
        const Node& old = nodes_[s.from];
        const uint32_t c = uint32_t(out.nodes_.size());
        out.nodes_[it.node].child = c;
        for (int k = 0; k < 4; ++k) {
            Node child;
            Source cs;
            if (s.fraction == 1.f && !old.leaf()) {
                // The old node was split too: its child is the source, whole.
                cs.from = old.child + uint32_t(k);
                cs.fraction = 1.f;
                child.mass = nodes_[cs.from].mass;
            } else {
                // A piece of an old leaf: a quarter of this node's share of it.
                cs.from = s.from;
                cs.fraction = s.fraction * 0.25f;
                child.mass = mass * 0.25f;
            }
            out.nodes_.push_back(child);
            src.push_back(cs);
            queue.push_back({c + uint32_t(k), it.depth + 1});
        }
    }
    if (sources) *sources = std::move(src);
    return out;
}

glm::vec3 DirTree::hemisphereDirection(glm::vec2 a) {
    const float z = clampUnit(a.x);
    const float r = std::sqrt(std::max(0.f, 1.f - z * z));
    const float phi = TwoPi * a.y;
    return glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
}

bool DirTree::hemispherePoint(const glm::vec3& local, glm::vec2* a) {
    if (!(local.z > 0.f)) return false;
    const float phi = azimuth(local.x, local.y);
    if (!(phi >= 0.f)) return false;
    *a = glm::vec2(std::min(local.z, 1.f), std::min(phi / TwoPi, kOneMinusEpsilon));
    return true;
}

glm::vec3 DirTree::sphereDirection(glm::vec2 a) {
    const float z = std::clamp(2.f * a.x - 1.f, -1.f, 1.f);
    const float r = std::sqrt(std::max(0.f, 1.f - z * z));
    const float phi = TwoPi * a.y;
    return glm::vec3(r * std::cos(phi), r * std::sin(phi), z);
}

bool DirTree::spherePoint(const glm::vec3& local, glm::vec2* a) {
    if (!(local.z == local.z)) return false;
    const float phi = azimuth(local.x, local.y);
    if (!(phi >= 0.f)) return false;
    const float z = std::clamp(local.z, -1.f, 1.f);
    *a = glm::vec2(std::min(0.5f * (z + 1.f), kOneMinusEpsilon),
                   std::min(phi / TwoPi, kOneMinusEpsilon));
    return true;
}

}  // namespace rlpbrt::guiding
