// Transformations with pbrt-v3's conventions (column vectors, matrices as glm::mat4).
#pragma once

#include <array>

#include "render/math.h"

namespace rlpbrt {

Mat4 translateMatrix(const Vec3& d);
Mat4 scaleMatrix(const Vec3& s);
// Rotation by `deg` degrees about `axis` (right-hand rule, as pbrt-v3's Rotate).
Mat4 rotateMatrix(float deg, const Vec3& axis);
// pbrt-v3's LookAt: the camera-from-world matrix for an eye looking at `look`, with the
// camera's +x = normalize(cross(up, dir)), +y = cross(dir, x), +z = dir. False (and
// identity) when up and the view direction are parallel or eye == look.
bool lookAtMatrix(const Vec3& eye, const Vec3& look, const Vec3& up, Mat4* m);
// The 16 numbers of a Transform/ConcatTransform directive as a matrix.
Mat4 matrixFromPbrt(const std::array<float, 16>& v);

inline Vec3 transformPoint(const Mat4& m, const Vec3& p) {
    Vec4 r = m * Vec4(p, 1.f);
    return (r.w == 1.f || r.w == 0.f) ? Vec3(r) : Vec3(r) / r.w;
}
inline Vec3 transformVector(const Mat4& m, const Vec3& v) { return glm::mat3(m) * v; }
// Normals transform with the inverse transpose; pass the inverse of the point transform.
inline Vec3 transformNormal(const Mat4& inv, const Vec3& n) {
    return glm::transpose(glm::mat3(inv)) * n;
}
// True when the transform flips handedness (negative determinant of the 3x3 part).
inline bool swapsHandedness(const Mat4& m) { return glm::determinant(glm::mat3(m)) < 0.f; }

}  // namespace rlpbrt
