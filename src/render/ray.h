// A semi-infinite ray segment o + t d, t in (0, tMax).
#pragma once

#include "render/math.h"

namespace rlpbrt {

struct Ray {
    Vec3 o{0.f};            // origin (world space unless stated otherwise)
    Vec3 d{0.f, 0.f, 1.f};  // direction; unit length where the producer says so
    float tMax = Infinity;  // parametric end of the segment (units of |d|)

    Ray() = default;
    Ray(const Vec3& o_, const Vec3& d_, float tMax_ = Infinity) : o(o_), d(d_), tMax(tMax_) {}
    // The point at parameter t.
    Vec3 operator()(float t) const { return o + t * d; }
};

}  // namespace rlpbrt
