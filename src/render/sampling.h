// Warping of uniform samples to common distributions, with their pdfs.
// Piecewise-constant 1D/2D distributions are in distribution.h.
#pragma once

#include "render/math.h"

namespace rlpbrt {

// Shirley-Chiu concentric map of [0,1)^2 onto the unit disk.
inline Vec2 sampleUniformDiskConcentric(Vec2 u) {
    Vec2 o = 2.f * u - Vec2(1.f);
    if (o.x == 0 && o.y == 0) return Vec2(0.f);
    float r, theta;
    if (std::abs(o.x) > std::abs(o.y)) {
        r = o.x;
        theta = PiOver4 * (o.y / o.x);
    } else {
        r = o.y;
        theta = PiOver2 - PiOver4 * (o.x / o.y);
    }
    return r * Vec2(std::cos(theta), std::sin(theta));
}

// Cosine-weighted direction on the hemisphere around +z; pdf = cos(theta)/pi per steradian.
inline Vec3 sampleCosineHemisphere(Vec2 u) {
    Vec2 d = sampleUniformDiskConcentric(u);
    float z = safeSqrt(1.f - d.x * d.x - d.y * d.y);
    return Vec3(d.x, d.y, z);
}
inline float cosineHemispherePdf(float cosTheta) { return cosTheta * InvPi; }

inline Vec3 sampleUniformSphere(Vec2 u) {
    float z = 1.f - 2.f * u.x;
    float r = safeSqrt(1.f - z * z);
    float phi = 2.f * Pi * u.y;
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}
inline float uniformSpherePdf() { return Inv4Pi; }

inline Vec3 sampleUniformHemisphere(Vec2 u) {
    float z = u.x;
    float r = safeSqrt(1.f - z * z);
    float phi = 2.f * Pi * u.y;
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}
inline float uniformHemispherePdf() { return Inv2Pi; }

// Uniform direction in the cone around +z with cos(half-angle) = cosThetaMax.
inline Vec3 sampleUniformCone(Vec2 u, float cosThetaMax) {
    float cosTheta = (1.f - u.x) + u.x * cosThetaMax;
    float sinTheta = safeSqrt(1.f - cosTheta * cosTheta);
    float phi = u.y * 2.f * Pi;
    return Vec3(std::cos(phi) * sinTheta, std::sin(phi) * sinTheta, cosTheta);
}
inline float uniformConePdf(float cosThetaMax) { return 1.f / (2.f * Pi * (1.f - cosThetaMax)); }

// Uniform barycentrics (b0, b1) on a triangle; b2 = 1 - b0 - b1.
inline Vec2 sampleUniformTriangle(Vec2 u) {
    float su0 = std::sqrt(u.x);
    return Vec2(1.f - su0, u.y * su0);
}

inline float powerHeuristic(int nf, float fPdf, int ng, float gPdf) {
    float f = nf * fPdf, g = ng * gPdf;
    if (std::isinf(f * f)) return 1.f;
    if (f == 0.f && g == 0.f) return 0.f;
    return (f * f) / (f * f + g * g);
}

inline Vec3 sphericalDirection(float sinTheta, float cosTheta, float phi) {
    return Vec3(clamp(sinTheta, -1.f, 1.f) * std::cos(phi),
                clamp(sinTheta, -1.f, 1.f) * std::sin(phi), clamp(cosTheta, -1.f, 1.f));
}
inline float sphericalTheta(const Vec3& v) { return safeAcos(v.z); }
inline float sphericalPhi(const Vec3& v) {
    float p = std::atan2(v.y, v.x);
    return (p < 0) ? (p + 2 * Pi) : p;
}

}  // namespace rlpbrt
