#include "render/patches.h"

#include <cmath>

#include "render/scene.h"

namespace rlpbrt {

namespace {
float longestEdge(const TriangleMesh& m, size_t tri) {
    const Vec3& p0 = m.p[m.indices[3 * tri]];
    const Vec3& p1 = m.p[m.indices[3 * tri + 1]];
    const Vec3& p2 = m.p[m.indices[3 * tri + 2]];
    return std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
}

uint32_t cutsFor(float edge, double size) {
    if (!(size > 0.0) || !std::isfinite(size) || !std::isfinite(edge)) return 1;
    const double k = std::ceil(double(edge) / size);
    return k <= 1.0 ? 1u : k >= double(SurfacePatches::kMaxCuts) ? SurfacePatches::kMaxCuts
                                                                 : uint32_t(k);
}
}  // namespace

SurfacePatches::SurfacePatches(const std::vector<Primitive>& prims, float size,
                               uint64_t maxPatches)
    : prims_(&prims) {
    geoms_.assign(prims.size(), Geom());
    uint64_t triangles = 0;
    for (const Primitive& prim : prims)
        if (prim.shape.mesh) triangles += prim.shape.mesh->triangleCount();
    // One patch per triangle at least, and keys below kWhole.
    if (triangles == 0 || triangles > maxPatches || triangles >= uint64_t(kWhole)) return;
    std::vector<float> edges;
    edges.reserve(size_t(triangles));
    for (const Primitive& prim : prims)
        if (const TriangleMesh* m = prim.shape.mesh.get())
            for (size_t t = 0; t < m->triangleCount(); ++t) edges.push_back(longestEdge(*m, t));
    // Grow the size until the patches fit the budget (at size = infinity: one per triangle).
    double s = size;
    for (int attempt = 0;; ++attempt) {
        uint64_t total = 0;
        for (float e : edges) {
            const uint64_t k = cutsFor(e, s);
            total += k * k;
        }
        if (total <= maxPatches && total < uint64_t(kWhole)) break;
        if (attempt >= 60) {
            s = 0.0;  // every triangle one patch (fits: triangles <= maxPatches)
            break;
        }
        s *= std::max(1.1, std::sqrt(double(total) / double(maxPatches)));
    }
    size_ = float(s);
    uint32_t next = 0;
    size_t e = 0;
    for (size_t g = 0; g < prims.size(); ++g) {
        const TriangleMesh* m = prims[g].shape.mesh.get();
        if (!m || m->triangleCount() == 0) continue;
        const size_t n = m->triangleCount();
        geoms_[g].firstPatch = next;
        patchedGeoms_.push_back(uint32_t(g));
        bool whole = true;
        for (size_t t = 0; t < n && whole; ++t) whole = cutsFor(edges[e + t], s) == 1;
        if (whole) {
            geoms_[g].firstTri = kWhole;
            next += uint32_t(n);
            e += n;
            continue;
        }
        geoms_[g].firstTri = uint32_t(tris_.size());
        for (size_t t = 0; t < n; ++t) {
            const uint32_t k = cutsFor(edges[e++], s);
            tris_.push_back(Tri{next, k});
            next += k * k;
        }
    }
    count_ = next;
}

bool SurfacePatches::centre(uint32_t patch, Vec3* p, Vec3* n) const {
    if (patch >= count_) return false;
    // The primitive: the last whose first patch is <= patch; then its triangle likewise.
    const uint32_t g = *(std::upper_bound(patchedGeoms_.begin(), patchedGeoms_.end(), patch,
                                          [this](uint32_t v, uint32_t geom) {
                                              return v < geoms_[geom].firstPatch;
                                          }) -
                         1);
    const Geom& geom = geoms_[g];
    const TriangleMesh& m = *(*prims_)[g].shape.mesh;
    size_t local = 0;
    uint32_t k = 1, cell = 0;
    if (geom.firstTri == kWhole) {
        local = patch - geom.firstPatch;
    } else {
        const auto first = tris_.begin() + geom.firstTri;
        const auto tri = std::upper_bound(first, first + std::ptrdiff_t(m.triangleCount()),
                                          patch,
                                          [](uint32_t v, const Tri& t) { return v < t.first; }) -
                         1;
        local = size_t(tri - first);
        k = tri->cuts;
        cell = patch - tri->first;
    }
    const float a = float(cell / k), b = float(cell % k), kf = float(k);
    // The cell's centre in the barycentric square; in a cell the far edge cuts, its lower
    // triangle's centroid; past the edge (never hit), the edge point in its direction.
    const uint32_t diagonal = cell / k + cell % k;
    float b1 = (a + 0.5f) / kf, b2 = (b + 0.5f) / kf;
    if (diagonal + 1 >= k) b1 = (a + 1.f / 3.f) / kf, b2 = (b + 1.f / 3.f) / kf;
    if (diagonal >= k) {
        const float sum = b1 + b2;
        b1 /= sum;
        b2 /= sum;
    }
    const Vec3& p0 = m.p[m.indices[3 * local]];
    const Vec3& p1 = m.p[m.indices[3 * local + 1]];
    const Vec3& p2 = m.p[m.indices[3 * local + 2]];
    *p = (1.f - b1 - b2) * p0 + b1 * p1 + b2 * p2;
    const Vec3 c = glm::cross(p0 - p2, p1 - p2);
    const float len = glm::length(c);
    *n = len > 0.f && std::isfinite(len) ? c / len : Vec3(0.f);
    return true;
}

}  // namespace rlpbrt
