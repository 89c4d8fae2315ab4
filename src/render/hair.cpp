#include "render/hair.h"

#include <array>

namespace rlpbrt {

namespace {

constexpr int kPMax = 3;  // R, TT, TRT explicitly; the rest in one isotropic term

// Modified Bessel function of the first kind, order 0 (its power series, 10 terms).
float besselI0(float x) {
    float sum = 0.f, term = 1.f, q = 0.25f * x * x;
    for (int i = 1; i <= 10; ++i) {
        sum += term;
        term *= q / float(i * i);
    }
    return sum;
}

float logBesselI0(float x) {
    if (x > 12.f) return x + 0.5f * (-std::log(2.f * Pi) + std::log(1.f / x) + 1.f / (8.f * x));
    return std::log(besselI0(x));
}

// The longitudinal scattering function M_p (d'Eon et al.), variance v; the log form for small
// v, where the Bessel function and sinh overflow.
float longitudinal(float cosThetaI, float cosThetaO, float sinThetaI, float sinThetaO,
                   float v) {
    float a = cosThetaI * cosThetaO / v, b = sinThetaI * sinThetaO / v;
    if (v <= 0.1f) return std::exp(logBesselI0(a) - b - 1.f / v - std::log(v));
    return std::exp(-b) * besselI0(a) / (2.f * v * std::sinh(1.f / v));
}

float logistic(float x, float s) {
    x = std::abs(x);
    float e = std::exp(-x / s);
    return e / (s * (1.f + e) * (1.f + e));
}
float logisticCdf(float x, float s) { return 1.f / (1.f + std::exp(-x / s)); }

// The logistic density restricted to [-pi, pi] and renormalised.
float trimmedLogistic(float x, float s) {
    return logistic(x, s) / (logisticCdf(Pi, s) - logisticCdf(-Pi, s));
}
float sampleTrimmedLogistic(float u, float s) {
    float lo = logisticCdf(-Pi, s), k = logisticCdf(Pi, s) - lo;
    float x = -s * std::log(1.f / (u * k + lo) - 1.f);
    return clamp(x, -Pi, Pi);
}

// The azimuth change of the p-th lobe's perfect-cylinder path.
float lobePhi(int p, float gammaO, float gammaT) {
    return 2.f * float(p) * gammaT - 2.f * gammaO + float(p) * Pi;
}

// The azimuthal scattering function N_p.
float azimuthal(float phi, int p, float s, float gammaO, float gammaT) {
    float d = phi - lobePhi(p, gammaO, gammaT);
    d = std::remainder(d, 2.f * Pi);  // into [-pi, pi]
    return trimmedLogistic(d, s);
}

// The lobes' attenuations A_p: Fresnel at the first interface, absorption T per passage.
std::array<Spectrum, kPMax + 1> attenuations(float cosThetaO, float eta, float h,
                                             const Spectrum& T) {
    std::array<Spectrum, kPMax + 1> a;
    float cosGammaO = safeSqrt(1.f - h * h);
    float f = frDielectric(cosThetaO * cosGammaO, 1.f, eta);
    a[0] = Spectrum(f);
    a[1] = (1.f - f) * (1.f - f) * T;
    for (int p = 2; p < kPMax; ++p) a[p] = a[p - 1] * T * f;
    a[kPMax] = a[kPMax - 1] * f * T / (Spectrum(1.f) - T * f);
    return a;
}

// Rotates the angle theta (as its sine and cosine) by delta.
void rotate(float sinT, float cosT, float sinD, float cosD, float* sinOut, float* cosOut) {
    *sinOut = sinT * cosD + cosT * sinD;
    *cosOut = cosT * cosD - sinT * sinD;
}

// What the hair's geometry gives for wo: the refracted ray's gamma_t and the absorption of
// one passage through the fibre.
struct HairGeometry {
    float sinThetaO, cosThetaO, phiO, gammaT;
    Spectrum T;
    HairGeometry(const HairBxDF& b, const Vec3& wo) {
        sinThetaO = wo.x;
        cosThetaO = safeSqrt(1.f - sinThetaO * sinThetaO);
        phiO = std::atan2(wo.z, wo.y);
        float sinThetaT = sinThetaO / b.eta;
        float cosThetaT = safeSqrt(1.f - sinThetaT * sinThetaT);
        float etaP = std::sqrt(b.eta * b.eta - sinThetaO * sinThetaO) / cosThetaO;
        float sinGammaT = b.h / etaP;
        float cosGammaT = safeSqrt(1.f - sinGammaT * sinGammaT);
        gammaT = safeAsin(sinGammaT);
        T = glm::exp(-b.sigmaA * (2.f * cosGammaT / cosThetaT));
    }
};

// The tilt of lobe p's incident angle by the scales: +2 alpha (R), -alpha (TT), -4 alpha
// (TRT), none for the remainder; as (sin, cos) of the tilt.
void lobeTilt(const HairBxDF& b, int p, float* sinD, float* cosD) {
    float s1 = b.sinAlpha, c1 = b.cosAlpha;
    float s2 = 2.f * c1 * s1, c2 = c1 * c1 - s1 * s1;  // 2 alpha
    float s4 = 2.f * c2 * s2, c4 = c2 * c2 - s2 * s2;  // 4 alpha
    switch (p) {
    case 0: *sinD = s2, *cosD = c2; break;
    case 1: *sinD = -s1, *cosD = c1; break;
    case 2: *sinD = -s4, *cosD = c4; break;
    default: *sinD = 0.f, *cosD = 1.f; break;
    }
}

float lobeVariance(const HairBxDF& b, int p) {
    return p == 0 ? b.v0 : (p == 1 ? 0.25f * b.v0 : 4.f * b.v0);
}

// Probabilities of choosing each lobe in sampling: the attenuations' luminances.
std::array<float, kPMax + 1> lobePdf(const HairBxDF& b, const HairGeometry& g) {
    std::array<Spectrum, kPMax + 1> a = attenuations(g.cosThetaO, b.eta, b.h, g.T);
    std::array<float, kPMax + 1> pdf;
    float sum = 0.f;
    for (int p = 0; p <= kPMax; ++p) sum += (pdf[p] = std::max(0.f, luminance(a[p])));
    for (int p = 0; p <= kPMax; ++p) pdf[p] = sum > 0.f ? pdf[p] / sum : (p == 0 ? 1.f : 0.f);
    return pdf;
}

// Sum over the lobes of M_p * weight_p * N_p (weights: attenuations for f, lobe
// probabilities for the pdf).
template <typename W, typename Weights>
W lobeSum(const HairBxDF& b, const HairGeometry& g, const Vec3& wi, const Weights& w) {
    float sinThetaI = wi.x, cosThetaI = safeSqrt(1.f - sinThetaI * sinThetaI);
    float phi = std::atan2(wi.z, wi.y) - g.phiO;
    float gammaO = b.gammaO;
    W sum(0.f);
    for (int p = 0; p < kPMax; ++p) {
        float sinD, cosD, sinI, cosI;
        lobeTilt(b, p, &sinD, &cosD);
        rotate(sinThetaI, cosThetaI, sinD, cosD, &sinI, &cosI);
        sum += longitudinal(std::abs(cosI), g.cosThetaO, sinI, g.sinThetaO, lobeVariance(b, p)) *
               w[p] * azimuthal(phi, p, b.s, gammaO, g.gammaT);
    }
    sum += longitudinal(cosThetaI, g.cosThetaO, sinThetaI, g.sinThetaO,
                        lobeVariance(b, kPMax)) *
           w[kPMax] * Inv2Pi;
    return sum;
}

}  // namespace

HairBxDF::HairBxDF(float h_, float eta_, const Spectrum& sigmaA_, float betaM, float betaN,
                   float alphaDegrees)
    : h(clamp(h_, -1.f, 1.f)), gammaO(safeAsin(h)), eta(eta_), sigmaA(sigmaA_) {
    float m = betaM;
    float sm = 0.726f * m + 0.812f * m * m + 3.7f * std::pow(m, 20.f);
    v0 = sm * sm;
    float n = betaN;
    s = 0.626657069f * (0.265f * n + 1.194f * n * n + 5.372f * std::pow(n, 22.f));  // sqrt(pi/8)
    sinAlpha = std::sin(radians(alphaDegrees));
    cosAlpha = safeSqrt(1.f - sinAlpha * sinAlpha);
}

Spectrum HairBxDF::f(const Vec3& wo, const Vec3& wi) const {
    HairGeometry g(*this, wo);
    std::array<Spectrum, kPMax + 1> a = attenuations(g.cosThetaO, eta, h, g.T);
    Spectrum sum = lobeSum<Spectrum>(*this, g, wi, a);
    float c = std::abs(wi.z);
    return c > 0.f ? sum / c : sum;
}

float HairBxDF::pdf(const Vec3& wo, const Vec3& wi) const {
    HairGeometry g(*this, wo);
    return lobeSum<float>(*this, g, wi, lobePdf(*this, g));
}

BxDFSample HairBxDF::sampleF(const Vec3& wo, float uc, Vec2 u) const {
    HairGeometry g(*this, wo);
    std::array<float, kPMax + 1> lp = lobePdf(*this, g);
    // The lobe from uc, and uc's remainder (uniform again) for the azimuth.
    int p = 0;
    while (p < kPMax && uc >= lp[p]) uc -= lp[p++];
    float ur = lp[p] > 0.f ? std::min(uc / lp[p], OneMinusEpsilon) : 0.5f;
    // Longitudinal: M_p sampled about the mirror direction -theta_o, then untilted.
    float v = lobeVariance(*this, p);
    float u1 = std::max(u.x, 1e-5f);
    float cosTheta = 1.f + v * std::log(u1 + (1.f - u1) * std::exp(-2.f / v));
    float sinTheta = safeSqrt(1.f - cosTheta * cosTheta);
    float cosPhi = std::cos(2.f * Pi * u.y);
    float sinThetaI = -cosTheta * g.sinThetaO + sinTheta * cosPhi * g.cosThetaO;
    float cosThetaI = safeSqrt(1.f - sinThetaI * sinThetaI);
    float sinD, cosD;
    lobeTilt(*this, p, &sinD, &cosD);
    rotate(sinThetaI, cosThetaI, -sinD, cosD, &sinThetaI, &cosThetaI);
    // Azimuthal: N_p about the lobe's perfect-cylinder azimuth; uniform for the remainder.
    float dphi = p < kPMax ? lobePhi(p, gammaO, g.gammaT) + sampleTrimmedLogistic(ur, s)
                           : 2.f * Pi * ur;
    float phiI = g.phiO + dphi;
    BxDFSample out;
    out.wi = Vec3(sinThetaI, cosThetaI * std::cos(phiI), cosThetaI * std::sin(phiI));
    out.pdf = pdf(wo, out.wi);
    out.f = f(wo, out.wi);
    out.flags = BxDFFlags::Glossy | (out.wi.z * wo.z > 0.f ? BxDFFlags::Reflection
                                                             : BxDFFlags::Transmission);
    if (!(out.pdf > 0.f) || !isFinite(out.f)) out = BxDFSample();
    return out;
}

Spectrum hairSigmaAFromConcentration(float eumelanin, float pheomelanin) {
    const Spectrum eu(0.419f, 0.697f, 1.37f), pheo(0.187f, 0.4f, 1.05f);
    return eumelanin * eu + pheomelanin * pheo;
}

Spectrum hairSigmaAFromReflectance(const Spectrum& c, float betaN) {
    float n = betaN;
    float d = 5.969f - 0.215f * n + 2.532f * n * n - 10.73f * n * n * n +
              5.574f * n * n * n * n + 0.245f * n * n * n * n * n;
    Spectrum out;
    for (int i = 0; i < 3; ++i) {
        float l = std::log(c[i]) / d;
        out[i] = l * l;
    }
    return out;
}

// ------------------------------------------------------------------------------------------
// The material.

namespace {

using FTex = std::shared_ptr<FloatTexture>;
using STex = std::shared_ptr<SpectrumTexture>;

class HairMaterial : public Material {
public:
    // Exactly one way to give the absorption: sigmaA, color, or the pigments.
    HairMaterial(STex sigmaA, STex color, FTex eumelanin, FTex pheomelanin, FTex eta,
                 FTex betaM, FTex betaN, FTex alpha)
        : sigmaA_(std::move(sigmaA)), color_(std::move(color)),
          eumelanin_(std::move(eumelanin)), pheomelanin_(std::move(pheomelanin)),
          eta_(std::move(eta)), betaM_(std::move(betaM)), betaN_(std::move(betaN)),
          alpha_(std::move(alpha)) {}

    void computeBSDF(const SurfaceInteraction& si, float, BSDF* bsdf) const override {
        TextureContext tc = textureContext(si);
        float bm = clamp(betaM_->evaluate(tc), 0.f, 1.f);
        float bn = clamp(betaN_->evaluate(tc), 0.f, 1.f);
        float e = eta_->evaluate(tc);
        Spectrum sa;
        if (sigmaA_) {
            sa = glm::max(sigmaA_->evaluate(tc), Spectrum(0.f));
        } else if (color_) {
            sa = hairSigmaAFromReflectance(glm::max(color_->evaluate(tc), Spectrum(0.f)), bn);
        } else {
            sa = hairSigmaAFromConcentration(
                eumelanin_ ? std::max(0.f, eumelanin_->evaluate(tc)) : 0.f,
                pheomelanin_ ? std::max(0.f, pheomelanin_->evaluate(tc)) : 0.f);
        }
        // The frame: x along the hair (dpdu), z the shading normal.
        bsdf->init(si.ng, si.ns, si.dpdu, e);
        float h = -1.f + 2.f * si.uv.y;  // the offset across the curve
        bsdf->add(HairBxDF(h, e, sa, bm, bn, alpha_->evaluate(tc)));
    }

private:
    STex sigmaA_, color_;
    FTex eumelanin_, pheomelanin_, eta_, betaM_, betaN_, alpha_;
};

}  // namespace

std::unique_ptr<Material> createHairMaterial(const MaterialEntity& e, TextureResolver& tex,
                                             Diagnostics& diag) {
    const ParamList& p = e.params;
    STex sigmaA, color;
    FTex eu, pheo;
    auto ignore = [&](const char* name, const char* because) {
        if (!p.has(name)) return;
        if (const Param* q = p.find(name)) q->used = true;
        diag.warning(e.loc, std::string("material \"hair\": \"") + name + "\" is ignored "
                            "because \"" + because + "\" is given (as in pbrt-v3)");
    };
    if (p.has("sigma_a")) {
        sigmaA = tex.spectrumTex(p, "sigma_a", Spectrum(0.f));
        ignore("color", "sigma_a");
        ignore("eumelanin", "sigma_a");
        ignore("pheomelanin", "sigma_a");
    } else if (p.has("color")) {
        color = tex.spectrumTex(p, "color", Spectrum(0.f));
        ignore("eumelanin", "color");
        ignore("pheomelanin", "color");
    } else if (p.has("eumelanin") || p.has("pheomelanin")) {
        if (p.has("eumelanin")) eu = tex.floatTex(p, "eumelanin", 0.f);
        if (p.has("pheomelanin")) pheo = tex.floatTex(p, "pheomelanin", 0.f);
    } else {
        // pbrt-v3's default: brown hair.
        sigmaA = std::make_shared<ConstantSpectrumTexture>(hairSigmaAFromConcentration(1.3f, 0.f));
    }
    return std::make_unique<HairMaterial>(
        sigmaA, color, eu, pheo, tex.floatTex(p, "eta", 1.55f), tex.floatTex(p, "beta_m", 0.3f),
        tex.floatTex(p, "beta_n", 0.3f), tex.floatTex(p, "alpha", 2.f));
}

}  // namespace rlpbrt
