// A ray's hit on a surface, with the local geometry that shading needs.
#pragma once

#include "render/math.h"

namespace rlpbrt {

struct SurfaceInteraction {
    Vec3 p{0.f};      // world-space hit point
    float t = 0.f;    // ray parameter of the hit
    Vec3 wo{0.f};     // unit direction back along the incoming ray
    Vec3 ng{0.f};     // unit geometric normal (pbrt-v3 orientation rules)
    Vec3 ns{0.f};     // unit shading normal, in ng's hemisphere
    Vec2 uv{0.f};     // surface parametrisation
    Vec3 dpdu{0.f}, dpdv{0.f};  // partial derivatives of p (world space)
    Vec3 dndu{0.f}, dndv{0.f};  // partial derivatives of the shading normal
    Vec3 shadingTangent{0.f};   // optional per-vertex tangent (mesh "S"), else zero
    int material = -1;  // index into Scene::materials; -1 = interface only (no surface)
    int light = -1;     // index into Scene::lights when the surface emits
    int primitive = -1; // world hits: the shape record (Embree geomID); -1 for instances
    unsigned primID = 0;  // world hits: the triangle (or quadric) within it
    Vec2 bary{0.f};       // world hits: Embree's hit coordinates (triangles: b1, b2)
    // Media on the two sides (indices into Scene::media, -1 = none); a boundary when they
    // differ: a ray leaving along w enters mediumOutside if dot(w, ng) > 0, else mediumInside.
    int mediumInside = -1, mediumOutside = -1;
    bool isMediumTransition() const { return mediumInside != mediumOutside; }
    int mediumAfter(const Vec3& w, int current) const {
        if (mediumInside == mediumOutside) return current;
        return glm::dot(w, ng) > 0.f ? mediumOutside : mediumInside;
    }
};

}  // namespace rlpbrt
