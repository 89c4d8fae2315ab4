// Basic math types and helpers of the render layer (over util/math.h). RGB spectra are glm::vec3.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

#include "util/math.h"

namespace rlpbrt {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Vec4 = glm::vec4;
using Mat4 = glm::mat4;
// Linear RGB radiometric quantity (pbrt-v3's default RGB build).
using Spectrum = glm::vec3;

inline float radians(float deg) { return deg * (Pi / 180.f); }
inline float degrees(float rad) { return rad * (180.f / Pi); }
template <typename T>
inline T clamp(T v, T lo, T hi) { return v < lo ? lo : (v > hi ? hi : v); }
inline float lerp(float t, float a, float b) { return (1 - t) * a + t * b; }
inline float safeSqrt(float x) { return std::sqrt(std::max(0.f, x)); }
inline float safeAcos(float x) { return std::acos(clamp(x, -1.f, 1.f)); }
inline float safeAsin(float x) { return std::asin(clamp(x, -1.f, 1.f)); }
inline float luminance(const Spectrum& s) {
    return 0.212671f * s.x + 0.715160f * s.y + 0.072169f * s.z;  // pbrt-v3's y()
}
inline bool isBlack(const Spectrum& s) { return s.x == 0.f && s.y == 0.f && s.z == 0.f; }
inline float maxComponent(const Vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
inline bool isFinite(const Vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace rlpbrt
