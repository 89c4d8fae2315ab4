// BSDF: a shading frame plus up to MaxBxDFs lobes held by value (no heap allocation), with
// pbrt-v3's BSDF semantics; and material-level builders that create pbrt-v3's lobes from
// already-evaluated (texture-looked-up) parameter values.
#pragma once

#include "render/bssrdf.h"
#include "render/bxdfs.h"
#include "render/math.h"

namespace rlpbrt {

// Result of BSDF::sampleF in world space; see BxDFSample for the meaning of f and pdf.
struct BSDFSample {
    Spectrum f{0.f};
    Vec3 wi{0.f};  // world space, unit length
    float pdf = 0.f;
    BxDFFlags flags = BxDFFlags::None;
    bool valid() const { return pdf > 0.f; }
    bool isSpecular() const { return hasAny(flags, BxDFFlags::Specular); }
    bool isReflection() const { return hasAny(flags, BxDFFlags::Reflection); }
    bool isTransmission() const { return hasAny(flags, BxDFFlags::Transmission); }
};

class BSDF {
  public:
    static constexpr int MaxBxDFs = 8;

    // Identity frame (shading normal +z), no lobes, eta 1.
    BSDF() = default;
    // Sets the frame: geometric normal ng, shading normal ns, and a shading tangent (e.g. dpdu
    // of the shading geometry) that is Gram-Schmidt-orthogonalised against ns (an arbitrary
    // tangent is used if it is degenerate). Removes all lobes; sets the relative IOR eta.
    void init(const Vec3& ng, const Vec3& ns, const Vec3& tangent, float eta = 1.f);
    // Removes all lobes and the BSSRDF (frame and eta are kept).
    void clear() {
        n_ = 0;
        hasSubsurface_ = false;
    }
    // The material's BSSRDF (pbrt-v3's si->bssrdf: subsurface, kdsubsurface, disney with a
    // scatter distance), or null. The integrator follows it after sampling a transmission.
    const SeparableBSSRDF* subsurface() const { return hasSubsurface_ ? &bssrdf_ : nullptr; }
    void setSubsurface(const SeparableBSSRDF& b) {
        bssrdf_ = b;
        hasSubsurface_ = true;
    }
    // Appends a lobe; returns false (and ignores it) if MaxBxDFs lobes are already present.
    bool add(const BxDF& bxdf);

    // Relative index of refraction inside/outside (pbrt BSDF::eta), for Russian roulette.
    float eta() const { return eta_; }
    // Sets the relative IOR reported by eta().
    void setEta(float eta) { eta_ = eta; }
    // Geometric normal (world space, unit).
    const Vec3& ng() const { return ng_; }
    // Shading normal (world space, unit).
    const Vec3& ns() const { return frame_.n; }
    // Shading frame (s, t, n) in world space.
    const Frame& frame() const { return frame_; }
    // The i-th lobe, 0 <= i < numComponents().
    const BxDF& component(int i) const { return bxdfs_[i]; }

    // Number of lobes whose flags are contained in `flags`.
    // (Inline: the integrator asks several times per vertex.)
    int numComponents(BxDFFlags flags = BxDFFlags::All) const {
        int count = 0;
        for (int i = 0; i < n_; ++i) count += matchesFlags(flags_[i], flags) ? 1 : 0;
        return count;
    }
    // One pass over the lobes for the counts the integrator asks at every vertex: all lobes
    // (numComponents()), the non-specular ones (numComponents(All & ~Specular)) and the diffuse
    // ones (numComponents(Reflection | Transmission | Diffuse)).
    struct LobeCounts {
        int all = 0, smooth = 0, diffuse = 0;
    };
    LobeCounts lobeCounts() const {
        constexpr BxDFFlags kSmooth = BxDFFlags::All & ~BxDFFlags::Specular;
        LobeCounts c;
        c.all = n_;
        for (int i = 0; i < n_; ++i) {
            c.smooth += matchesFlags(flags_[i], kSmooth) ? 1 : 0;
            c.diffuse += matchesFlags(flags_[i], kDiffuseLobes) ? 1 : 0;
        }
        return c;
    }
    // True if there is at least one lobe and all lobes are specular (delta distributions).
    bool isDelta() const;
    // Union of the flags of all lobes.
    BxDFFlags flags() const;

    // World direction to the local shading frame (z = shading normal).
    Vec3 worldToLocal(const Vec3& v) const { return frame_.toLocal(v); }
    // Local shading-frame direction to world space.
    Vec3 localToWorld(const Vec3& v) const { return frame_.toWorld(v); }

    // BSDF value (1/sr) for world directions; the geometric normal decides whether reflection
    // or transmission lobes are evaluated (pbrt-v3). Specular lobes contribute 0.
    Spectrum f(const Vec3& woWorld, const Vec3& wiWorld,
               BxDFFlags flags = BxDFFlags::All) const;
    // Samples an incident direction: picks one of the matching lobes uniformly with u.x
    // (whose remainder, rescaled to [0,1), the lobe then samples with u.y), passes uc on to
    // the lobe for its own choice; for non-specular lobes pdf averages all matching lobes'
    // pdfs (solid angle) and f sums all matching lobes.
    BSDFSample sampleF(const Vec3& woWorld, float uc, Vec2 u,
                       BxDFFlags flags = BxDFFlags::All) const;
    // Solid-angle density of sampleF for non-specular lobes (average over matching lobes).
    float pdf(const Vec3& woWorld, const Vec3& wiWorld, BxDFFlags flags = BxDFFlags::All) const;

  private:
    // Sum of the matching lobes' f for local directions: reflection lobes if `reflect` (the
    // geometric normal's verdict on the world directions), else transmission lobes.
    Spectrum sumF(const Vec3& wo, const Vec3& wi, bool reflect, BxDFFlags flags) const;

    Frame frame_;
    Vec3 ng_{0.f, 0.f, 1.f};
    float eta_ = 1.f;
    int n_ = 0;
    bool hasSubsurface_ = false;
    SeparableBSSRDF bssrdf_;
    BxDFFlags flags_[MaxBxDFs];  // each lobe's flags, taken at add() (queried per vertex)
    BxDF bxdfs_[MaxBxDFs];
};

// ---- Material builders (pbrt-v3 src/materials/*.cpp lobes) ------------------------------
// Each replaces the lobes of an already init()-ed BSDF (keeping its frame), sets eta, clamps
// colours to be non-negative and skips lobes whose colour is black. Roughness values are
// pbrt "roughness" parameters, mapped with TrowbridgeReitzDistribution::roughnessToAlpha when
// remap is true. All microfacet lobes use Trowbridge-Reitz with visible-normal sampling.

// matte: Lambertian(kd) if sigma == 0, else OrenNayar(kd, sigma); sigma in degrees [0, 90].
void buildMatte(BSDF& bsdf, Spectrum kd, float sigmaDeg);
// plastic: Lambertian(kd) + MicrofacetReflection(ks, TR(rough), FresnelDielectric(1.5, 1)).
void buildPlastic(BSDF& bsdf, Spectrum kd, Spectrum ks, float roughness, bool remap);
// metal: MicrofacetReflection(1, TR(u, v), FresnelConductor(1, eta, k)).
void buildMetal(BSDF& bsdf, Spectrum eta, Spectrum k, float uRough, float vRough, bool remap);
// glass: FresnelSpecular(kr, kt, 1, eta) if both roughnesses are 0, else
// MicrofacetReflection(kr, TR, Dielectric(1, eta)) + MicrofacetTransmission(kt, TR, 1, eta).
void buildGlass(BSDF& bsdf, Spectrum kr, Spectrum kt, float eta, float uRough, float vRough,
                bool remap, TransportMode mode = TransportMode::Radiance);
// mirror: SpecularReflection(kr, FresnelNoOp).
void buildMirror(BSDF& bsdf, Spectrum kr);
// uber: SpecularTransmission(1 - opacity, 1, 1) + Lambertian(op kd) +
// MicrofacetReflection(op ks, TR(u, v), Dielectric(1, eta)) + SpecularReflection(op kr,
// Dielectric(1, eta)) + SpecularTransmission(op kt, 1, eta). eta of the BSDF is 1 when
// partially transparent, else eta.
void buildUber(BSDF& bsdf, Spectrum kd, Spectrum ks, Spectrum kr, Spectrum kt, float uRough,
               float vRough, Spectrum opacity, float eta, bool remap,
               TransportMode mode = TransportMode::Radiance);
// substrate: FresnelBlend(kd, ks, TR(u, v)) unless both colours are black.
void buildSubstrate(BSDF& bsdf, Spectrum kd, Spectrum ks, float uRough, float vRough,
                    bool remap);
// translucent (eta 1.5): Lambertian(reflect kd) + LambertianTransmission(transmit kd) +
// MicrofacetReflection(reflect ks, Dielectric(1, 1.5)) + MicrofacetTransmission(transmit ks).
void buildTranslucent(BSDF& bsdf, Spectrum kd, Spectrum ks, Spectrum reflect,
                      Spectrum transmit, float roughness, bool remap,
                      TransportMode mode = TransportMode::Radiance);

// subsurface / kdsubsurface (pbrt-v3): the boundary is buildGlass(kr, kt, eta, u, v, remap);
// the BSSRDF is set by the material.

// disney (pbrt-v3's DisneyMaterial, Burley 2012/2015), from evaluated parameters; names and
// defaults are pbrt-v3's. With diffuse weight dw = (1 - metallic)(1 - spectrans) > 0:
// DisneyDiffuse(dw c) (thin: DisneyDiffuse(dw (1 - flatness)(1 - difftrans / 2) c) +
// FakeSS(dw flatness (1 - difftrans / 2) c)) + Retro(dw c) + Sheen(dw sheen lerp(sheentint, 1,
// tint)) if sheen > 0; then MicrofacetReflection(1, TR, DisneyFresnel) +
// DisneyClearcoat if clearcoat > 0 + MicrofacetTransmission(spectrans sqrt(c)) if spectrans > 0
// (thin: with roughness scaled by 0.65 eta - 0.35) + thin: LambertianTransmission(difftrans / 2
// c). Not thin with a non-black scatterdistance: SpecularTransmission(1, 1, eta) and Disney's
// BSSRDF (dw c, scatterdistance) replace DisneyDiffuse (pbrt-v3). BSDF eta 1, as pbrt-v3's.
struct DisneyParams {
    Spectrum color{0.5f};
    float metallic = 0.f, eta = 1.5f, roughness = 0.5f, specularTint = 0.f, anisotropic = 0.f;
    float sheen = 0.f, sheenTint = 0.5f, clearcoat = 0.f, clearcoatGloss = 1.f;
    float specTrans = 0.f, flatness = 0.f, diffTrans = 1.f;
    Spectrum scatterDistance{0.f};
    bool thin = false;
};
void buildDisney(BSDF& bsdf, const DisneyParams& p, TransportMode mode = TransportMode::Radiance);

}  // namespace rlpbrt
