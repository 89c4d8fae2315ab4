// NURBS surfaces with pbrt-v3's "nurbs" semantics: a tensor-product B-spline patch over
// homogeneous control points (pbrt-v3's "Pw": x, y, z already multiplied by the weight w; "P":
// w = 1), evaluated exactly (value and first derivatives) and tessellated into pbrt-v3's mesh:
// a 30 x 30 grid of points over [u0, u1] x [v0, v1], uv = the parameter values, shading normals
// normalize(dP/du x dP/dv), two triangles per grid cell.
#pragma once

#include <string>
#include <vector>

#include "render/math.h"

namespace rlpbrt {

struct NurbsPatch {
    int nu = 0, nv = 0;          // control points along u and v
    int uOrder = 0, vOrder = 0;  // order = degree + 1
    std::vector<float> uKnots, vKnots;  // nu + uOrder and nv + vOrder values, non-decreasing
    std::vector<glm::vec4> cp;   // nu * nv homogeneous points, u fastest (index v * nu + u)
    float u0 = 0.f, u1 = 1.f, v0 = 0.f, v1 = 1.f;  // the parameter range to tessellate
};

// Checks sizes, orders, knot vectors and the parameter range; false with *error if bad.
bool validateNurbs(const NurbsPatch& patch, std::string* error);

// The surface point at (u, v) (inside the valid knot range) and, if asked, its partial
// derivatives (of the rational surface).
Vec3 evaluateNurbs(const NurbsPatch& patch, float u, float v, Vec3* dpdu = nullptr,
                   Vec3* dpdv = nullptr);

// pbrt-v3's tessellation (see above): positions, shading normals (zero where the derivatives
// are parallel), uv and triangle indices.
constexpr int kNurbsDice = 30;
void tessellateNurbs(const NurbsPatch& patch, std::vector<Vec3>* p, std::vector<Vec3>* n,
                     std::vector<Vec2>* uv, std::vector<uint32_t>* indices);

}  // namespace rlpbrt
