// Subsurface scattering with pbrt-v3's separable BSSRDF semantics (pbrt-v3 bssrdf.h/.cpp,
// disney.cpp): S(po, wo, pi, wi) = (1 - Fr(cos wo)) Sp(|po - pi|) Sw(wi). The entry's Fresnel
// transmission is the dielectric boundary's BSDF (the material's lobes); the radial profile Sr
// is either the photon beam diffusion table (TabulatedBSSRDF: single + multiple scattering,
// tabulated over albedo and optical radius) or Disney's two-exponential profile (Burley 2015);
// Sw is the exit lobe (BSSRDFExitLobe in bxdfs.h). Exit points are sampled by probe segments
// (sampleProbe), which the integrator intersects with the surfaces of the entry's material.
// Units: the coefficients are per scene unit (pbrt-v3's named media are in mm^-1 and used as
// given, as pbrt-v3 does).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/math.h"

namespace rlpbrt {

// pbrt-v3's Fresnel moments of a dielectric of relative index eta (polynomial fits).
float fresnelMoment1(float eta);
float fresnelMoment2(float eta);

// Photon beam diffusion (Habel et al. 2013) of a medium with coefficients sigma_s, sigma_a
// (per unit length), phase asymmetry g and relative index eta: the multiple-scattering
// (dipole, integrated over real-source depths) and single-scattering radial exitance at r.
float beamDiffusionMS(float sigmaS, float sigmaA, float g, float eta, float r);
float beamDiffusionSS(float sigmaS, float sigmaA, float g, float eta, float r);

// The profile 2 pi r (SS + MS) of a unit-extinction medium tabulated over albedo rho (100
// nodes, denser near 1) and optical radius (64 nodes, 0 then 2.5e-3 x 1.2^k); per albedo its
// integral rhoEff (the effective albedo) and running integral (for sampling).
struct BSSRDFTable {
    int nRho = 0, nRadius = 0;
    std::vector<float> rho, radius, profile, rhoEff, cdf;
    float at(int iRho, int iRadius) const { return profile[size_t(iRho * nRadius + iRadius)]; }
};
void computeBeamDiffusionTable(float g, float eta, BSSRDFTable* t);
// The table for (g, eta), computed once per process and shared (thread-safe): the materials
// of a scene often share their parameters (0.07 s per table).
std::shared_ptr<const BSSRDFTable> beamDiffusionTable(float g, float eta);

// pbrt-v3's SubsurfaceFromDiffuse: per channel the albedo whose effective albedo is rhoEff
// (inverting the table's rhoEff spline), with sigma_t = 1 / mfp.
void subsurfaceFromDiffuse(const BSSRDFTable& t, const Spectrum& rhoEff, const Spectrum& mfp,
                           Spectrum* sigmaA, Spectrum* sigmaS);

// pbrt-v3's table of measured media (Jensen et al. 2001, Narasimhan et al. 2006): sigma_a and
// the reduced scattering coefficient sigma'_s (mm^-1, RGB) of `name`; false if unknown.
bool measuredSubsurface(const std::string& name, Spectrum* sigmaA, Spectrum* sigmaPrimeS);

// A separable BSSRDF's radial part and Sw constant, by value.
class SeparableBSSRDF {
  public:
    SeparableBSSRDF() = default;
    // pbrt-v3's TabulatedBSSRDF (table outlives this).
    static SeparableBSSRDF tabulated(const BSSRDFTable* table, const Spectrum& sigmaA,
                                     const Spectrum& sigmaS, float eta);
    // pbrt-v3's DisneyBSSRDF: reflectance R and scatter distance sd (d = 0.2 sd).
    static SeparableBSSRDF disney(const Spectrum& R, const Spectrum& sd, float eta);

    float eta() const { return eta_; }
    // The radial profile (per unit area) at distance r.
    Spectrum sr(float r) const;
    // A radius for channel ch sampled with density pdfSr(ch, r) 2 pi r; negative: none.
    float sampleSr(int ch, float u) const;
    // The area density (per unit area of the tangent plane) of sampleSr's points at radius r.
    float pdfSr(int ch, float r) const;
    // pbrt-v3's probe radius bound: sampleSr(ch, 0.999).
    float rMax(int ch) const { return sampleSr(ch, 0.999f); }

  private:
    enum class Kind : uint8_t { Tabulated, Disney };
    Kind kind_ = Kind::Tabulated;
    const BSSRDFTable* table_ = nullptr;
    Spectrum sigmaT_{0.f}, rho_{0.f};  // tabulated
    Spectrum r_{0.f}, d_{0.f};         // disney
    float eta_ = 1.f;
};

// A probe segment for BSSRDF sampling (pbrt-v3's Sample_Sp): an axis of the frame at po (its
// normal with probability 1/2, each tangent with 1/4), a channel, a radius from the profile
// and an angle; the segment of length 2 sqrt(rMax^2 - r^2) through the sampled point along
// the axis. uPick is the remainder of u1 for choosing among the segment's hits. False if the
// profile gives no radius.
struct BSSRDFProbe {
    Vec3 start{0.f}, end{0.f};
    float uPick = 0.f;
};
bool sampleProbe(const SeparableBSSRDF& b, const Frame& frame, const Vec3& po, float u1,
                 Vec2 u2, BSSRDFProbe* probe);
// The density (per unit area at pi, before dividing by the number of hits found) with which
// sampleProbe's strategies reach pi with geometric normal ni: pbrt-v3's Pdf_Sp.
float pdfSp(const SeparableBSSRDF& b, const Frame& frame, const Vec3& po, const Vec3& pi,
            const Vec3& ni);

}  // namespace rlpbrt
