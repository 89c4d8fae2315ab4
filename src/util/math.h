// Basics that every layer may use (src/util: the standard library and GLM only): constants,
// the remapping of a one-sample choice's u, an orthonormal frame. The render layer adds its
// types in render/math.h; the guiding layer uses these directly.
#pragma once

#include <cmath>
#include <limits>

#include <glm/glm.hpp>

namespace rlpbrt {

constexpr float Pi = 3.14159265358979323846f;
constexpr double PiDouble = 3.14159265358979323846;
constexpr float TwoPi = 6.28318530717958647692f;
constexpr float InvPi = 0.31830988618379067154f;
constexpr float Inv2Pi = 0.15915494309189533577f;
constexpr float Inv4Pi = 0.07957747154594766788f;
constexpr float PiOver2 = 1.57079632679489661923f;
constexpr float PiOver4 = 0.78539816339744830961f;
constexpr float Infinity = std::numeric_limits<float>::infinity();
// Largest float below one: upper bound for sample values in [0,1).
constexpr float OneMinusEpsilon = 0x1.fffffep-1f;

// u's place in [lo, hi), rescaled to [0,1) (0 for an empty interval): the fresh uniform value
// left over after u chose the piece [lo, hi) of a CDF (pbrt-v3's remapping of a one-sample
// choice, which keeps a stratified u stratified for what it samples next).
inline float remapInInterval(float u, float lo, float hi) {
    const float w = hi - lo;
    if (!(w > 0.f)) return 0.f;
    const float t = (u - lo) / w;
    return t < 0.f ? 0.f : (t < OneMinusEpsilon ? t : OneMinusEpsilon);
}

// Orthonormal basis around a unit normal n (Duff et al. 2017, "Building an Orthonormal
// Basis, Revisited"). Local coordinates have z along n.
struct Frame {
    glm::vec3 s, t, n;
    Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
    Frame(const glm::vec3& s_, const glm::vec3& t_, const glm::vec3& n_) : s(s_), t(t_), n(n_) {}
    // The frame around the unit vector n (local +z = n).
    static Frame fromZ(const glm::vec3& n) {
        float sign = std::copysign(1.f, n.z);
        float a = -1.f / (sign + n.z);
        float b = n.x * n.y * a;
        return Frame(glm::vec3(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x),
                     glm::vec3(b, sign + n.y * n.y * a, -n.y), n);
    }
    // World vector -> local coordinates (z along n).
    glm::vec3 toLocal(const glm::vec3& v) const {
        return glm::vec3(glm::dot(v, s), glm::dot(v, t), glm::dot(v, n));
    }
    // Local coordinates -> world vector.
    glm::vec3 toWorld(const glm::vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace rlpbrt
