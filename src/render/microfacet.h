// Microfacet normal distributions (Trowbridge-Reitz/GGX and Beckmann, anisotropic) with Smith
// masking and visible-normal sampling, following pbrt-v3's MicrofacetDistribution semantics.
// Also the shading-frame trigonometry helpers shared by the BxDFs (z = shading normal).
#pragma once

#include <cstdint>

#include "render/math.h"

namespace rlpbrt {

// Trigonometry of unit directions expressed in the local shading frame (z = normal).
namespace shading {
inline float cosTheta(const Vec3& w) { return w.z; }
inline float cos2Theta(const Vec3& w) { return w.z * w.z; }
inline float absCosTheta(const Vec3& w) { return std::abs(w.z); }
inline float sin2Theta(const Vec3& w) { return std::max(0.f, 1.f - cos2Theta(w)); }
inline float sinTheta(const Vec3& w) { return std::sqrt(sin2Theta(w)); }
inline float tanTheta(const Vec3& w) { return sinTheta(w) / cosTheta(w); }
inline float tan2Theta(const Vec3& w) { return sin2Theta(w) / cos2Theta(w); }
inline float cosPhi(const Vec3& w) {
    float s = sinTheta(w);
    return s == 0.f ? 1.f : clamp(w.x / s, -1.f, 1.f);
}
inline float sinPhi(const Vec3& w) {
    float s = sinTheta(w);
    return s == 0.f ? 0.f : clamp(w.y / s, -1.f, 1.f);
}
inline float cos2Phi(const Vec3& w) { return cosPhi(w) * cosPhi(w); }
inline float sin2Phi(const Vec3& w) { return sinPhi(w) * sinPhi(w); }
inline bool sameHemisphere(const Vec3& a, const Vec3& b) { return a.z * b.z > 0.f; }
// Mirror of wo about the unit vector n (both pointing away from the surface).
inline Vec3 reflect(const Vec3& wo, const Vec3& n) { return -wo + 2.f * glm::dot(wo, n) * n; }
// Refraction of wi through the interface with normal n (same side as wi); eta = etaI / etaT.
// Returns false on total internal reflection.
inline bool refract(const Vec3& wi, const Vec3& n, float eta, Vec3* wt) {
    float cosThetaI = glm::dot(n, wi);
    float sin2ThetaI = std::max(0.f, 1.f - cosThetaI * cosThetaI);
    float sin2ThetaT = eta * eta * sin2ThetaI;
    if (sin2ThetaT >= 1.f) return false;
    float cosThetaT = std::sqrt(1.f - sin2ThetaT);
    *wt = eta * -wi + (eta * cosThetaI - cosThetaT) * n;
    return true;
}
// n flipped, if needed, to lie in the hemisphere of v.
inline Vec3 faceForward(const Vec3& n, const Vec3& v) { return glm::dot(n, v) < 0.f ? -n : n; }
}  // namespace shading

enum class MicrofacetType : uint8_t { TrowbridgeReitz, Beckmann };

// Trowbridge-Reitz (GGX) distribution: D(wh) = 1 / (pi ax ay cos^4 (1 + tan^2 (...))^2).
struct TrowbridgeReitzDistribution {
    // pbrt-v3's map from user "roughness" in [0,1] to alpha (used when remaproughness=true).
    static float roughnessToAlpha(float roughness);
    float alphaX, alphaY;
    float D(const Vec3& wh) const;
    float lambda(const Vec3& w) const;
    // Visible normal in the upper hemisphere for wo.z > 0 (Heitz 2018, exact for GGX).
    Vec3 sampleVisible(const Vec3& wo, Vec2 u) const;
};

// Beckmann-Spizzichino distribution: D(wh) = exp(-tan^2 (...)) / (pi ax ay cos^4).
struct BeckmannDistribution {
    // Same polynomial map as TrowbridgeReitzDistribution (pbrt-v3 uses one for both).
    static float roughnessToAlpha(float roughness);
    float alphaX, alphaY;
    float D(const Vec3& wh) const;
    float lambda(const Vec3& w) const;
    // Visible normal in the upper hemisphere for wo.z > 0 (stretch, sample unit slopes, unstretch).
    Vec3 sampleVisible(const Vec3& wo, Vec2 u) const;
};

// A microfacet distribution stored by value (tag + alphas), dispatching to the types above.
class MicrofacetDistribution {
  public:
    // Alphas below this are raised to it so that D, G and sampling stay finite.
    static constexpr float MinAlpha = 1e-4f;

    // Isotropic Trowbridge-Reitz with alpha 1.
    MicrofacetDistribution() = default;
    // alphaX / alphaY: roughness along the shading frame's s / t axes (already remapped).
    MicrofacetDistribution(MicrofacetType type, float alphaX, float alphaY);

    MicrofacetType type() const { return type_; }
    // Alpha along s (after clamping to MinAlpha).
    float alphaX() const { return alphaX_; }
    // Alpha along t (after clamping to MinAlpha).
    float alphaY() const { return alphaY_; }

    // Normal distribution D(wh), a density of microfacet normals w.r.t. projected solid angle.
    float D(const Vec3& wh) const;
    // Smith auxiliary function Lambda(w).
    float lambda(const Vec3& w) const;
    // Smith masking G1(w) = 1 / (1 + Lambda(w)).
    float G1(const Vec3& w) const { return 1.f / (1.f + lambda(w)); }
    // Height-correlated masking-shadowing G(wo, wi) = 1 / (1 + Lambda(wo) + Lambda(wi)).
    float G(const Vec3& wo, const Vec3& wi) const {
        return 1.f / (1.f + lambda(wo) + lambda(wi));
    }
    // Samples a microfacet normal visible from wo, in wo's hemisphere (pbrt-v3 sampleVisibleArea).
    Vec3 sampleWh(const Vec3& wo, Vec2 u) const;
    // Solid-angle density of sampleWh: D(wh) G1(wo) |wo.wh| / |wo.z|.
    float pdf(const Vec3& wo, const Vec3& wh) const;

  private:
    MicrofacetType type_ = MicrofacetType::TrowbridgeReitz;
    float alphaX_ = 1.f, alphaY_ = 1.f;
};

}  // namespace rlpbrt
