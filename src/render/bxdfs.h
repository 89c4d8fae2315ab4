// Reflection models with pbrt-v3 semantics: Fresnel terms and the BxDF lobes. All directions
// are unit vectors in the local shading frame (z = shading normal), both pointing away from the
// surface; wo is the outgoing (towards the camera for radiance) and wi the sampled direction.
// BxDFs are small value types; `BxDF` is a std::variant over them, so a BSDF can hold them by
// value without heap allocation.
#pragma once

#include <cstdint>
#include <type_traits>
#include <utility>
#include <variant>

#include "render/math.h"
#include "render/microfacet.h"

namespace rlpbrt {

// Lobe classification bits (pbrt-v3 BxDFType).
enum class BxDFFlags : uint8_t {
    None = 0,
    Reflection = 1 << 0,
    Transmission = 1 << 1,
    Diffuse = 1 << 2,
    Glossy = 1 << 3,
    Specular = 1 << 4,
    All = 0x1f,
};
inline constexpr BxDFFlags operator|(BxDFFlags a, BxDFFlags b) {
    return BxDFFlags(uint8_t(a) | uint8_t(b));
}
inline constexpr BxDFFlags operator&(BxDFFlags a, BxDFFlags b) {
    return BxDFFlags(uint8_t(a) & uint8_t(b));
}
inline constexpr BxDFFlags operator~(BxDFFlags a) { return BxDFFlags(~uint8_t(a) & 0x1f); }
// True if any bit of b is set in a.
inline constexpr bool hasAny(BxDFFlags a, BxDFFlags b) { return uint8_t(a & b) != 0; }
// True if flags of a lobe (lobe) are all contained in the requested set (pbrt MatchesFlags).
inline constexpr bool matchesFlags(BxDFFlags lobe, BxDFFlags requested) {
    return (lobe & requested) == lobe;
}
// The diffuse lobes, reflecting or transmitting (a request for matchesFlags / BSDF::f).
inline constexpr BxDFFlags kDiffuseLobes =
    BxDFFlags::Reflection | BxDFFlags::Transmission | BxDFFlags::Diffuse;

// Which quantity is being transported; affects the eta^2 scaling of transmission (pbrt-v3).
enum class TransportMode : uint8_t { Radiance, Importance };

// Unpolarised Fresnel reflectance of a dielectric interface. cosThetaI is the cosine of the
// incident direction with the normal on the etaI side; negative values mean the direction is
// on the etaT side (the indices are swapped). Returns 1 on total internal reflection.
float frDielectric(float cosThetaI, float etaI, float etaT);
// Fresnel reflectance of a conductor with complex index etaT + i k, seen from a medium etaI.
Spectrum frConductor(float cosThetaI, const Spectrum& etaI, const Spectrum& etaT,
                     const Spectrum& k);

// Schlick's weight (1 - cos)^5, cos clamped to [0, 1].
inline float schlickWeight(float cosTheta) {
    float m = clamp(1.f - cosTheta, 0.f, 1.f);
    return (m * m) * (m * m) * m;
}

// A Fresnel term stored by value: no-op (always 1), dielectric, conductor, or the Disney
// BSDF's blend of a dielectric and Schlick's approximation.
class Fresnel {
  public:
    enum class Kind : uint8_t { NoOp, Dielectric, Conductor, Disney };
    Fresnel() = default;
    // Always returns 1 (pbrt FresnelNoOp, used by the mirror material).
    static Fresnel noOp() { return Fresnel(); }
    // Dielectric with etaI on the side of the normal (+z) and etaT below it.
    static Fresnel dielectric(float etaI, float etaT);
    // Conductor; pbrt-v3's evaluate uses |cosThetaI|.
    static Fresnel conductor(const Spectrum& etaI, const Spectrum& etaT, const Spectrum& k);
    // pbrt-v3's DisneyFresnel: (1 - metallic) FrDielectric(cos, 1, eta) + metallic
    // Schlick(r0, cos).
    static Fresnel disney(const Spectrum& r0, float metallic, float eta);

    Kind kind() const { return kind_; }
    // Reflectance for the cosine of the incident direction with the normal.
    Spectrum evaluate(float cosThetaI) const;

  private:
    Kind kind_ = Kind::NoOp;
    Spectrum etaI_{1.f}, etaT_{1.f}, k_{0.f};
};

// Result of sampling a lobe: value f (1/sr; for specular lobes f includes 1/|cos wi| and the
// delta is implied), direction wi, pdf (solid angle, or the discrete probability for specular
// lobes) and the sampled lobe's flags. pdf == 0 means no sample.
struct BxDFSample {
    Spectrum f{0.f};
    Vec3 wi{0.f};
    float pdf = 0.f;
    BxDFFlags flags = BxDFFlags::None;
    bool valid() const { return pdf > 0.f; }
    bool isSpecular() const { return hasAny(flags, BxDFFlags::Specular); }
    bool isReflection() const { return hasAny(flags, BxDFFlags::Reflection); }
    bool isTransmission() const { return hasAny(flags, BxDFFlags::Transmission); }
};

// Every lobe type below offers (uc: extra uniform float in [0,1), u: uniform point in [0,1)^2):
//   Spectrum f(wo, wi)                  BSDF value, 1/sr (0 for specular lobes)
//   BxDFSample sampleF(wo, uc, u)        importance sample
//   float pdf(wo, wi)                   solid-angle density of sampleF (0 for specular lobes)
//   BxDFFlags flags()

// Lambertian reflection: f = R / pi, cosine-weighted sampling.
struct LambertianReflection {
    Spectrum r;
    explicit LambertianReflection(const Spectrum& r = Spectrum(0.f)) : r(r) {}
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const { return BxDFFlags::Reflection | BxDFFlags::Diffuse; }
};

// Lambertian transmission: f = T / pi into the opposite hemisphere.
struct LambertianTransmission {
    Spectrum t;
    explicit LambertianTransmission(const Spectrum& t) : t(t) {}
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const { return BxDFFlags::Transmission | BxDFFlags::Diffuse; }
};

// Oren-Nayar rough diffuse reflection (qualitative model), sigma = slope deviation in degrees.
struct OrenNayar {
    Spectrum r;
    float a, b;
    OrenNayar(const Spectrum& r, float sigmaDeg);
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const { return BxDFFlags::Reflection | BxDFFlags::Diffuse; }
};

// Perfect mirror reflection scaled by R and a Fresnel term.
struct SpecularReflection {
    Spectrum r;
    Fresnel fresnel;
    SpecularReflection(const Spectrum& r, const Fresnel& fresnel) : r(r), fresnel(fresnel) {}
    Spectrum f(const Vec3&, const Vec3&) const { return Spectrum(0.f); }
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3&, const Vec3&) const { return 0.f; }
    BxDFFlags flags() const { return BxDFFlags::Reflection | BxDFFlags::Specular; }
};

// Perfect refraction between etaA (above, +z) and etaB (below) scaled by T (1 - Fresnel).
// For TransportMode::Radiance the value is scaled by (etaI / etaT)^2.
struct SpecularTransmission {
    Spectrum t;
    float etaA, etaB;
    TransportMode mode;
    SpecularTransmission(const Spectrum& t, float etaA, float etaB, TransportMode mode)
        : t(t), etaA(etaA), etaB(etaB), mode(mode) {}
    Spectrum f(const Vec3&, const Vec3&) const { return Spectrum(0.f); }
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3&, const Vec3&) const { return 0.f; }
    BxDFFlags flags() const { return BxDFFlags::Transmission | BxDFFlags::Specular; }
};

// Smooth dielectric: chooses reflection with probability F and refraction with 1 - F (using
// uc), so sampleF's pdf is F or 1 - F.
struct FresnelSpecular {
    Spectrum r, t;
    float etaA, etaB;
    TransportMode mode;
    FresnelSpecular(const Spectrum& r, const Spectrum& t, float etaA, float etaB,
                    TransportMode mode)
        : r(r), t(t), etaA(etaA), etaB(etaB), mode(mode) {}
    Spectrum f(const Vec3&, const Vec3&) const { return Spectrum(0.f); }
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3&, const Vec3&) const { return 0.f; }
    BxDFFlags flags() const {
        return BxDFFlags::Reflection | BxDFFlags::Transmission | BxDFFlags::Specular;
    }
};

// Torrance-Sparrow microfacet reflection: R D G F / (4 |cos o| |cos i|).
struct MicrofacetReflection {
    Spectrum r;
    MicrofacetDistribution distribution;
    Fresnel fresnel;
    MicrofacetReflection(const Spectrum& r, const MicrofacetDistribution& d, const Fresnel& fr)
        : r(r), distribution(d), fresnel(fr) {}
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const { return BxDFFlags::Reflection | BxDFFlags::Glossy; }
};

// Walter et al. microfacet transmission between etaA (above) and etaB (below).
struct MicrofacetTransmission {
    Spectrum t;
    MicrofacetDistribution distribution;
    float etaA, etaB;
    TransportMode mode;
    MicrofacetTransmission(const Spectrum& t, const MicrofacetDistribution& d, float etaA,
                           float etaB, TransportMode mode)
        : t(t), distribution(d), etaA(etaA), etaB(etaB), mode(mode) {}
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const { return BxDFFlags::Transmission | BxDFFlags::Glossy; }
};

// Ashikhmin-Shirley diffuse substrate under a glossy coating (pbrt FresnelBlend).
struct FresnelBlend {
    Spectrum rd, rs;
    MicrofacetDistribution distribution;
    FresnelBlend(const Spectrum& rd, const Spectrum& rs, const MicrofacetDistribution& d)
        : rd(rd), rs(rs), distribution(d) {}
    // Schlick's approximation with normal-incidence reflectance rs.
    Spectrum schlickFresnel(float cosTheta) const;
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const { return BxDFFlags::Reflection | BxDFFlags::Glossy; }
};

// The Disney BSDF's diffuse-like reflection lobes (pbrt-v3's DisneyDiffuse, DisneyFakeSS,
// DisneyRetro, DisneySheen; Burley 2012 and 2015), with Fo, Fi = schlickWeight(|cos|) of wo, wi
// and cos d = wi . normalize(wo + wi):
//   Diffuse: R / pi (1 - Fo / 2) (1 - Fi / 2)
//   FakeSS:  R / pi 1.25 (Fss (1 / (|cos o| + |cos i|) - 0.5) + 0.5), Fss = lerp(Fo, 1, F90)
//            lerp(Fi, 1, F90), F90 = cos^2 d roughness (Hanrahan-Krueger-like flattening)
//   Retro:   R / pi Rr (Fo + Fi + Fo Fi (Rr - 1)), Rr = 2 roughness cos^2 d
//   Sheen:   R schlickWeight(cos d)
// All reflection | diffuse, sampled cosine-weighted on wo's side (pbrt-v3's default BxDF
// sampling).
struct DisneyDiffuseLobe {
    enum class Kind : uint8_t { Diffuse, FakeSS, Retro, Sheen };
    Spectrum r;
    float roughness;
    Kind kind;
    DisneyDiffuseLobe(Kind kind, const Spectrum& r, float roughness = 0.f)
        : r(r), roughness(roughness), kind(kind) {}
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const { return BxDFFlags::Reflection | BxDFFlags::Diffuse; }
};

// The Disney clearcoat (pbrt-v3's DisneyClearcoat): 0.25 weight D G F with the GTR1
// distribution of alpha lerp(gloss, 0.1, 0.001), Schlick's Fresnel with R0 = 0.04 and the
// separable Smith GGX masking of alpha 0.25. Sampled exactly from GTR1's D(wh) cos(wh), so
// the pdf is D cos(wh) / (4 wo.wh) (pbrt-v3 samples alpha 0.25 but reports the pdf of the gloss
// alpha without the cosine: a density mismatch this implementation does not copy).
struct DisneyClearcoat {
    float weight, gloss;
    DisneyClearcoat(float weight, float gloss) : weight(weight), gloss(gloss) {}
    float alpha() const { return 0.1f + gloss * (0.001f - 0.1f); }
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const { return BxDFFlags::Reflection | BxDFFlags::Glossy; }
};

struct FourierTable;

// pbrt-v3's FourierBSDF: a tabulated BSDF (fourier_bsdf.h) that outlives the lobe. f from the
// table's Catmull-Rom interpolation in mu_i, mu_o and its Fourier series in phi (radiance
// transmission scaled by 1/eta^2 as pbrt-v3); samples mu_i from the interpolated a0 spline and
// phi from the luminance series, pdf = Y / (2 pi integral of a0).
struct FourierBSDF {
    const FourierTable* table;
    TransportMode mode;
    FourierBSDF(const FourierTable* table, TransportMode mode) : table(table), mode(mode) {}
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const {
        return BxDFFlags::Reflection | BxDFFlags::Transmission | BxDFFlags::Glossy;
    }
};

// pbrt-v3's HairBSDF (d'Eon et al. 2011, Chiang et al. 2016; hair.cpp): R, TT, TRT and a
// remainder lobe of a rough dielectric cylinder with absorbing interior and tilted scales.
// Local frame: x along the hair (the curve's dpdu), z the shading normal; h in [-1, 1] is the
// offset across the hair (-1 + 2 v on a curve). Flags: glossy, reflection and transmission
// (a sample reports the side it went to).
struct HairBxDF {
    float h, gammaO, eta;
    Spectrum sigmaA;
    float v0;                  // longitudinal variance of R; TT: v0 / 4; TRT and beyond: 4 v0
    float s;                   // azimuthal logistic scale
    float sinAlpha, cosAlpha;  // the scales' tilt
    HairBxDF(float h, float eta, const Spectrum& sigmaA, float betaM, float betaN,
             float alphaDegrees);
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const {
        return BxDFFlags::Reflection | BxDFFlags::Transmission | BxDFFlags::Glossy;
    }
};

// The exit lobe of a separable BSSRDF (pbrt-v3's SeparableBSSRDFAdapter, bssrdf.h): Sw(wi) =
// (1 - Fr(cos wi; 1, eta)) / (c pi), c = 1 - 2 FresnelMoment1(1 / eta), times eta^2 for
// radiance transport. Reflection | diffuse, sampled cosine-weighted on wo's side (the path
// leaves the exit point with wo = the shading normal).
struct BSSRDFExitLobe {
    float eta, c;
    TransportMode mode;
    BSSRDFExitLobe(float eta, TransportMode mode);
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    float pdf(const Vec3& wo, const Vec3& wi) const;
    BxDFFlags flags() const { return BxDFFlags::Reflection | BxDFFlags::Diffuse; }
};

// Any one lobe, stored by value.
class BxDF {
  public:
    using Variant =
        std::variant<LambertianReflection, LambertianTransmission, OrenNayar,
                     SpecularReflection, SpecularTransmission, FresnelSpecular,
                     MicrofacetReflection, MicrofacetTransmission, FresnelBlend,
                     DisneyDiffuseLobe, DisneyClearcoat, FourierBSDF, HairBxDF,
                     BSSRDFExitLobe>;

    // A black Lambertian reflection lobe.
    BxDF() = default;
    // Wraps any of the lobe types above.
    template <typename T, typename = std::enable_if_t<!std::is_same_v<std::decay_t<T>, BxDF>>>
    BxDF(T&& lobe) : v_(std::forward<T>(lobe)) {}

    // BSDF value in 1/sr (0 for specular lobes).
    Spectrum f(const Vec3& wo, const Vec3& wi) const;
    // Importance sample of wi; see BxDFSample.
    BxDFSample sampleF(const Vec3& wo, float uc, Vec2 u) const;
    // Solid-angle density of sampleF at wi (0 for specular lobes).
    float pdf(const Vec3& wo, const Vec3& wi) const;
    // Lobe classification of the held lobe.
    BxDFFlags flags() const;
    // True if this lobe's flags are all contained in `requested`.
    bool matchesFlags(BxDFFlags requested) const {
        return rlpbrt::matchesFlags(flags(), requested);
    }
    // The concrete lobe if it has type T, else nullptr.
    template <typename T>
    const T* get() const { return std::get_if<T>(&v_); }

  private:
    Variant v_;
};

}  // namespace rlpbrt
