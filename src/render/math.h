// Basic math types and helpers of the render layer. RGB spectra are glm::vec3.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

namespace rlpbrt {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Vec4 = glm::vec4;
using Mat4 = glm::mat4;
// Linear RGB radiometric quantity (pbrt-v3's default RGB build).
using Spectrum = glm::vec3;

constexpr float Pi = 3.14159265358979323846f;
constexpr float InvPi = 0.31830988618379067154f;
constexpr float Inv2Pi = 0.15915494309189533577f;
constexpr float Inv4Pi = 0.07957747154594766788f;
constexpr float PiOver2 = 1.57079632679489661923f;
constexpr float PiOver4 = 0.78539816339744830961f;
constexpr float Infinity = std::numeric_limits<float>::infinity();
// Largest float below one: upper bound for sample values in [0,1).
constexpr float OneMinusEpsilon = 0x1.fffffep-1f;

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

// Orthonormal basis around a unit normal n (Duff et al. 2017, "Building an Orthonormal
// Basis, Revisited"). Local coordinates have z along n.
struct Frame {
    Vec3 s, t, n;
    Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
    Frame(const Vec3& s_, const Vec3& t_, const Vec3& n_) : s(s_), t(t_), n(n_) {}
    static Frame fromZ(const Vec3& n) {
        float sign = std::copysign(1.f, n.z);
        float a = -1.f / (sign + n.z);
        float b = n.x * n.y * a;
        return Frame(Vec3(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x),
                     Vec3(b, sign + n.y * n.y * a, -n.y), n);
    }
    Vec3 toLocal(const Vec3& v) const { return Vec3(glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)); }
    Vec3 toWorld(const Vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace rlpbrt
