// Surface patches: the world's triangles cut into pieces about `size` across, each named by a
// key, so that a ray hit names its piece with a few loads and no search. The guiding layer
// maps each piece to one of its regions once (GuidingField::setPatches) instead of searching
// space at every path vertex. Quadrics and instanced geometry get no patches (kNone): the
// guide's spatial lookup serves them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "render/interaction.h"
#include "render/math.h"

namespace rlpbrt {

struct Primitive;

class SurfacePatches {
public:
    static constexpr uint32_t kNone = UINT32_MAX;
    // Cuts within a triangle per edge at most (a triangle has at most kMaxCuts^2 patches).
    static constexpr uint32_t kMaxCuts = 256;

    // Patches of the triangle meshes among `prims` (the world group's primitives, indexed by
    // Embree geomID as SurfaceInteraction::primitive is): a triangle whose longest edge is L
    // is cut into k = ceil(L / size) parts per edge (1 <= k <= kMaxCuts), k^2 cells over its
    // barycentric square (cells past the far edge are never hit). If the patches would exceed
    // maxPatches, size grows until they fit (each triangle keeps at least one). `prims` must
    // outlive this object. size must be > 0 and finite, else every triangle is one patch.
    SurfacePatches(const std::vector<Primitive>& prims, float size, uint64_t maxPatches);

    uint32_t count() const { return count_; }
    // The patch of a hit (si.primitive, si.primID, si.bary), or kNone.
    uint32_t key(const SurfaceInteraction& si) const {
        if (si.primitive < 0 || size_t(si.primitive) >= geoms_.size()) return kNone;
        const Geom& g = geoms_[size_t(si.primitive)];
        // A mesh of small triangles: one patch each, numbered as its triangles.
        if (g.firstTri == kWhole) return g.firstPatch + si.primID;
        if (g.firstTri == kNone) return kNone;
        const Tri& t = tris_[size_t(g.firstTri) + si.primID];
        const float k = float(t.cuts);
        const uint32_t last = t.cuts - 1;
        // Truncation is the floor for the non-negative barycentrics; values out of [0, k)
        // (rounding, NaN) clamp to the nearest cell before any conversion.
        const float fa = si.bary.x * k, fb = si.bary.y * k;
        const uint32_t a = fa > 0.f ? (fa < k ? uint32_t(fa) : last) : 0u;
        const uint32_t b = fb > 0.f ? (fb < k ? uint32_t(fb) : last) : 0u;
        return t.first + a * t.cuts + b;
    }
    // A point of the patch (the centre of its part of the triangle) and the unit geometric
    // normal of its triangle (in either orientation); false if patch >= count().
    bool centre(uint32_t patch, Vec3* p, Vec3* n) const;
    // The patch size used (grown from the requested one if maxPatches was reached).
    float size() const { return size_; }
    // Bytes of the tables.
    size_t bytes() const {
        return geoms_.capacity() * sizeof(Geom) + tris_.capacity() * sizeof(Tri) +
               patchedGeoms_.capacity() * sizeof(uint32_t);
    }

private:
    static constexpr uint32_t kWhole = UINT32_MAX - 1;  // Geom::firstTri: one patch per triangle
    struct Tri {
        uint32_t first;  // its first patch
        uint32_t cuts;   // k: k^2 patches
    };
    // Per primitive: its first patch, and the index of its first triangle in tris_, or kWhole
    // (every triangle one patch: no per-triangle entries), or kNone (no patches).
    struct Geom {
        uint32_t firstPatch = 0;
        uint32_t firstTri = kNone;
    };
    const std::vector<Primitive>* prims_;
    std::vector<Geom> geoms_;
    std::vector<Tri> tris_;             // triangles of the primitives that cut some of theirs
    std::vector<uint32_t> patchedGeoms_;  // primitives with patches, in patch order
    uint32_t count_ = 0;
    float size_ = 0.f;
};

}  // namespace rlpbrt
