#include <functional>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "chi2.h"
#include "render/bsdf.h"
#include "render/bxdfs.h"
#include "render/microfacet.h"

namespace rlpbrt {
namespace {

// Number of spherical chi-square tests in this file, for the Sidak-corrected level.
constexpr int kChi2Family = 180;
constexpr long long kChi2Samples = 200000;

// One of this file's chi-square tests: sample against the quadrature of pdf, seeded by the
// case's name.
template <class Sample, class Pdf>
chi2::SphereResult fileChi2(const std::string& name, Sample&& sample, Pdf&& pdf) {
    chi2::SphereOptions opt;
    opt.sampleCount = kChi2Samples;
    opt.numTests = kChi2Family;
    opt.seed = std::hash<std::string>()(name);
    return chi2::testSphere(sample, pdf, opt);
}

// The same for a BxDF's or BSDF's sampleF and pdf from wo. Specular samples are delta
// distributions: they count as "no sample" for the density.
template <class Scattering>
chi2::SphereResult scatteringChi2(const std::string& name, const Scattering& x, const Vec3& wo) {
    return fileChi2(
        name,
        [&](const Vec3& u) {
            const auto s = x.sampleF(wo, u.x, Vec2(u.y, u.z));
            if (!s.valid() || s.isSpecular()) return chi2::SphereSample();
            return chi2::SphereSample{s.wi, s.pdf};
        },
        [&](const Vec3& wi) { return x.pdf(wo, wi); });
}

Vec3 dirFromCos(float cosTheta, float phi) {
    float s = safeSqrt(1.f - cosTheta * cosTheta);
    return Vec3(s * std::cos(phi), s * std::sin(phi), cosTheta);
}

float uniformFloat(std::mt19937_64& rng) { return float(rng() >> 40) * 0x1p-24f; }

std::string fmtAlpha(float a) {
    std::string s = std::to_string(int(std::lround(a * 100)));
    return "a" + s;
}

struct WoCase {
    const char* name;
    Vec3 wo;
};
const WoCase kWos[] = {{"Normal", dirFromCos(0.95f, 1.1f)},
                       {"Mid", dirFromCos(0.5f, 2.3f)},
                       {"Grazing", dirFromCos(0.08f, 4.0f)},
                       {"Below", dirFromCos(-0.6f, 5.2f)}};

MicrofacetDistribution makeDist(MicrofacetType t, float ax, float ay) {
    return MicrofacetDistribution(t, ax, ay);
}
const char* distName(MicrofacetType t) {
    return t == MicrofacetType::TrowbridgeReitz ? "TR" : "Beckmann";
}

struct LobeCase {
    std::string name;
    BxDF bxdf;
};

// Non-specular lobes, all distributions, isotropic and anisotropic roughness.
std::vector<LobeCase> nonSpecularLobes(TransportMode mode) {
    std::vector<LobeCase> v;
    v.push_back({"Lambertian", LambertianReflection(Spectrum(0.8f))});
    v.push_back({"LambertianTransmission", LambertianTransmission(Spectrum(0.8f))});
    v.push_back({"OrenNayar", OrenNayar(Spectrum(0.8f), 25.f)});
    for (MicrofacetType t : {MicrofacetType::TrowbridgeReitz, MicrofacetType::Beckmann}) {
        for (Vec2 a : {Vec2(0.1f, 0.1f), Vec2(0.5f, 0.5f), Vec2(0.08f, 0.4f)}) {
            v.push_back({std::string("MicrofacetReflection_") + distName(t) + "_" +
                             fmtAlpha(a.x) + "_" + fmtAlpha(a.y),
                         MicrofacetReflection(Spectrum(1.f), makeDist(t, a.x, a.y),
                                              Fresnel::dielectric(1.f, 1.5f))});
        }
        for (Vec2 a : {Vec2(0.15f, 0.15f), Vec2(0.6f, 0.6f), Vec2(0.1f, 0.4f)}) {
            v.push_back({std::string("MicrofacetTransmission_") + distName(t) + "_" +
                             fmtAlpha(a.x) + "_" + fmtAlpha(a.y),
                         MicrofacetTransmission(Spectrum(1.f), makeDist(t, a.x, a.y), 1.f, 1.5f,
                                                mode)});
        }
        for (Vec2 a : {Vec2(0.3f, 0.3f), Vec2(0.1f, 0.4f)}) {
            v.push_back({std::string("FresnelBlend_") + distName(t) + "_" + fmtAlpha(a.x) +
                             "_" + fmtAlpha(a.y),
                         FresnelBlend(Spectrum(0.5f), Spectrum(0.3f), makeDist(t, a.x, a.y))});
        }
    }
    return v;
}

// The Disney BSDF's own lobes (their albedo can exceed 1: Burley's retro-reflection and sheen
// are not energy conserving, so they are not in nonSpecularLobes' energy tests).
std::vector<LobeCase> disneyLobes() {
    using K = DisneyDiffuseLobe::Kind;
    return {{"DisneyDiffuse", DisneyDiffuseLobe(K::Diffuse, Spectrum(0.8f))},
            {"DisneyFakeSS", DisneyDiffuseLobe(K::FakeSS, Spectrum(0.8f), 0.5f)},
            {"DisneyRetro", DisneyDiffuseLobe(K::Retro, Spectrum(0.8f), 0.5f)},
            {"DisneySheen", DisneyDiffuseLobe(K::Sheen, Spectrum(0.8f))},
            {"DisneyClearcoat_g0", DisneyClearcoat(1.f, 0.f)},
            {"DisneyClearcoat_g80", DisneyClearcoat(1.f, 0.8f)}};
}

// ---- chi-square: every non-specular lobe x several wo ------------------------------------

struct BxDFChi2Case {
    std::string name;
    BxDF bxdf;
    Vec3 wo;
};

std::vector<BxDFChi2Case> bxdfChi2Cases() {
    std::vector<BxDFChi2Case> cases;
    for (const LobeCase& l : nonSpecularLobes(TransportMode::Radiance))
        for (const WoCase& w : kWos) cases.push_back({l.name + "_" + w.name, l.bxdf, w.wo});
    for (const LobeCase& l : disneyLobes())
        for (const WoCase& w : kWos) cases.push_back({l.name + "_" + w.name, l.bxdf, w.wo});
    return cases;
}

class BxDFChi2 : public ::testing::TestWithParam<BxDFChi2Case> {};

TEST_P(BxDFChi2, SampleMatchesPdf) {
    const BxDFChi2Case& c = GetParam();
    chi2::SphereResult r = scatteringChi2(c.name, c.bxdf, c.wo);
    EXPECT_TRUE(r.passed) << r.message;
}

INSTANTIATE_TEST_SUITE_P(Lobes, BxDFChi2, ::testing::ValuesIn(bxdfChi2Cases()),
                         [](const auto& info) { return info.param.name; });

// ---- chi-square: visible-normal sampling of the distributions ----------------------------

struct WhChi2Case {
    std::string name;
    MicrofacetDistribution dist;
    Vec3 wo;
};

std::vector<WhChi2Case> whChi2Cases() {
    std::vector<WhChi2Case> cases;
    for (MicrofacetType t : {MicrofacetType::TrowbridgeReitz, MicrofacetType::Beckmann})
        for (Vec2 a : {Vec2(0.2f, 0.2f), Vec2(0.8f, 0.8f), Vec2(0.1f, 0.5f)})
            for (const WoCase& w : kWos)
                cases.push_back({std::string(distName(t)) + "_" + fmtAlpha(a.x) + "_" +
                                     fmtAlpha(a.y) + "_" + w.name,
                                 makeDist(t, a.x, a.y), w.wo});
    return cases;
}

class VisibleNormalChi2 : public ::testing::TestWithParam<WhChi2Case> {};

TEST_P(VisibleNormalChi2, SampleWhMatchesPdf) {
    const WhChi2Case& c = GetParam();
    auto sample = [&](const Vec3& u) {
        Vec3 wh = c.dist.sampleWh(c.wo, Vec2(u.x, u.y));
        return chi2::SphereSample{wh, c.dist.pdf(c.wo, wh)};
    };
    // The visible-normal density is zero for back-facing microfacets.
    auto pdf = [&](const Vec3& wh) {
        if (glm::dot(c.wo, wh) <= 0.f || wh.z * c.wo.z <= 0.f) return 0.f;
        return c.dist.pdf(c.wo, wh);
    };
    chi2::SphereResult r = fileChi2(c.name, sample, pdf);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdfIntegral, 1.0, 2e-3);
}

INSTANTIATE_TEST_SUITE_P(Distributions, VisibleNormalChi2, ::testing::ValuesIn(whChi2Cases()),
                         [](const auto& info) { return info.param.name; });

// ---- chi-square: material builders through the BSDF (rotated world frame) ----------------

struct MaterialCase {
    std::string name;
    std::function<void(BSDF&)> build;
};

std::vector<MaterialCase> materialCases() {
    return {
        {"MatteLambert", [](BSDF& b) { buildMatte(b, Spectrum(0.5f), 0.f); }},
        {"MatteOrenNayar", [](BSDF& b) { buildMatte(b, Spectrum(0.5f), 30.f); }},
        {"Plastic",
         [](BSDF& b) { buildPlastic(b, Spectrum(0.4f), Spectrum(0.5f), 0.1f, true); }},
        {"PlasticSharp",
         [](BSDF& b) { buildPlastic(b, Spectrum(0.4f), Spectrum(0.5f), 0.08f, false); }},
        {"MetalAnisotropic",
         [](BSDF& b) {
             buildMetal(b, Spectrum(0.2f, 0.92f, 1.1f), Spectrum(3.9f, 2.45f, 2.14f), 0.01f,
                        0.2f, true);
         }},
        {"RoughGlass",
         [](BSDF& b) { buildGlass(b, Spectrum(1.f), Spectrum(1.f), 1.5f, 0.2f, 0.2f, false); }},
        {"Uber",
         [](BSDF& b) {
             buildUber(b, Spectrum(0.3f), Spectrum(0.3f), Spectrum(0.2f), Spectrum(0.f), 0.1f,
                       0.1f, Spectrum(1.f), 1.5f, true);
         }},
        {"UberTranslucent",
         [](BSDF& b) {
             buildUber(b, Spectrum(0.3f), Spectrum(0.3f), Spectrum(0.2f), Spectrum(0.2f), 0.05f,
                       0.2f, Spectrum(0.5f), 1.5f, true);
         }},
        {"Substrate",
         [](BSDF& b) {
             buildSubstrate(b, Spectrum(0.5f), Spectrum(0.3f), 0.1f, 0.3f, false);
         }},
        // The three spheres of pbrt-features/disney.small.pbrt (the third without its
        // subsurface), and a thin sheet.
        {"DisneyMetallic",
         [](BSDF& b) {
             DisneyParams p;
             p.color = Spectrum(.9f, .6f, .3f);
             p.metallic = 1.f;
             p.roughness = .3f;
             p.anisotropic = .5f;
             buildDisney(b, p);
         }},
        {"DisneyClearcoatSheen",
         [](BSDF& b) {
             DisneyParams p;
             p.color = Spectrum(.2f, .4f, .8f);
             p.roughness = .6f;
             p.sheen = 1.f;
             p.sheenTint = .5f;
             p.clearcoat = 1.f;
             p.clearcoatGloss = .8f;
             p.specularTint = .3f;
             buildDisney(b, p);
         }},
        {"DisneyTransmissive",
         [](BSDF& b) {
             DisneyParams p;
             p.color = Spectrum(.8f, .9f, .8f);
             p.specTrans = .9f;
             // The scene's .1 (alpha .01) recomputes the refraction half vector in float to
             // 0.1% of the pdf, beyond SampleAgreesWithEvalAndPdf's tolerance.
             p.roughness = .2f;
             p.diffTrans = .3f;
             buildDisney(b, p);
         }},
        {"DisneyThin",
         [](BSDF& b) {
             DisneyParams p;
             p.color = Spectrum(.7f, .5f, .4f);
             p.thin = true;
             p.flatness = .4f;
             p.diffTrans = .8f;
             p.specTrans = .3f;
             p.roughness = .4f;
             buildDisney(b, p);
         }},
        {"Translucent",
         [](BSDF& b) {
             buildTranslucent(b, Spectrum(0.5f), Spectrum(0.5f), Spectrum(0.5f),
                              Spectrum(0.5f), 0.1f, true);
         }},
    };
}

// A BSDF whose frame is rotated away from world axes (ng = ns here).
BSDF makeFramedBSDF() {
    BSDF b;
    Vec3 n = glm::normalize(Vec3(0.3f, -0.2f, 0.93f));
    b.init(n, n, Vec3(1.f, 0.4f, 0.f));
    return b;
}

struct MaterialChi2Case {
    std::string name;
    std::function<void(BSDF&)> build;
    Vec3 woLocal;
};

std::vector<MaterialChi2Case> materialChi2Cases() {
    std::vector<MaterialChi2Case> cases;
    for (const MaterialCase& m : materialCases())
        for (const WoCase& w : kWos) cases.push_back({m.name + "_" + w.name, m.build, w.wo});
    return cases;
}

class MaterialChi2 : public ::testing::TestWithParam<MaterialChi2Case> {};

TEST_P(MaterialChi2, SampleMatchesPdf) {
    const MaterialChi2Case& c = GetParam();
    BSDF bsdf = makeFramedBSDF();
    c.build(bsdf);
    ASSERT_GT(bsdf.numComponents(), 0);
    chi2::SphereResult r = scatteringChi2(c.name, bsdf, bsdf.localToWorld(c.woLocal));
    EXPECT_TRUE(r.passed) << r.message;
}

INSTANTIATE_TEST_SUITE_P(Builders, MaterialChi2, ::testing::ValuesIn(materialChi2Cases()),
                         [](const auto& info) { return info.param.name; });

// Non-specular samples report the same f and pdf as BSDF::f and BSDF::pdf.
TEST(BSDF, SampleAgreesWithEvalAndPdf) {
    for (const MaterialCase& m : materialCases()) {
        SCOPED_TRACE(m.name);
        BSDF bsdf = makeFramedBSDF();
        m.build(bsdf);
        std::mt19937_64 rng(5);
        for (const WoCase& w : kWos) {
            Vec3 wo = bsdf.localToWorld(w.wo);
            for (int i = 0; i < 2000; ++i) {
                float uc = uniformFloat(rng);
                Vec2 u(uniformFloat(rng), uniformFloat(rng));
                BSDFSample s = bsdf.sampleF(wo, uc, u);
                if (!s.valid()) continue;
                ASSERT_NEAR(glm::length(s.wi), 1.f, 1e-4f);
                ASSERT_TRUE(isFinite(s.f));
                if (s.isSpecular()) continue;
                Spectrum f = bsdf.f(wo, s.wi);
                float pdf = bsdf.pdf(wo, s.wi);
                ASSERT_NEAR(s.pdf, pdf, 1e-3f * pdf + 1e-6f);
                for (int k = 0; k < 3; ++k) ASSERT_NEAR(s.f[k], f[k], 1e-3f * f[k] + 1e-6f);
            }
        }
    }
}

// ---- energy ----------------------------------------------------------------------------

struct Albedo {
    double mean;
    double stdError;
};

// Monte Carlo estimate of the directional albedo (max over channels of f |cos| / pdf).
Albedo estimateAlbedo(const BxDF& b, const Vec3& wo, int n, uint64_t seed) {
    std::mt19937_64 rng(seed);
    double sum = 0.0, sum2 = 0.0;
    for (int i = 0; i < n; ++i) {
        BxDFSample s = b.sampleF(wo, uniformFloat(rng), Vec2(uniformFloat(rng), uniformFloat(rng)));
        double w = 0.0;
        if (s.valid()) w = maxComponent(s.f) * std::abs(s.wi.z) / s.pdf;
        sum += w;
        sum2 += w * w;
    }
    double mean = sum / n;
    double var = std::max(0.0, sum2 / n - mean * mean);
    return {mean, std::sqrt(var / n)};
}

TEST(BxDFEnergy, AlbedoAtMostOne) {
    // Importance mode: no eta^2 radiance scaling, so transmission conserves energy both ways.
    std::vector<LobeCase> lobes = nonSpecularLobes(TransportMode::Importance);
    lobes.push_back({"SpecularReflection",
                     SpecularReflection(Spectrum(1.f), Fresnel::dielectric(1.f, 1.5f))});
    lobes.push_back({"SpecularTransmission",
                     SpecularTransmission(Spectrum(1.f), 1.f, 1.5f, TransportMode::Importance)});
    lobes.push_back({"FresnelSpecular", FresnelSpecular(Spectrum(1.f), Spectrum(1.f), 1.f, 1.5f,
                                                        TransportMode::Importance)});
    lobes.push_back({"MicrofacetConductor",
                     MicrofacetReflection(Spectrum(1.f),
                                          makeDist(MicrofacetType::TrowbridgeReitz, 0.3f, 0.3f),
                                          Fresnel::conductor(Spectrum(1.f), Spectrum(0.2f),
                                                             Spectrum(3.9f)))});
    for (const LobeCase& l : lobes) {
        for (const WoCase& w : kWos) {
            Albedo a = estimateAlbedo(l.bxdf, w.wo, 10000, 17);
            // The mean of n weights is within 5 standard errors of its expectation.
            EXPECT_LE(a.mean, 1.0 + 5.0 * a.stdError + 1e-4) << l.name << " " << w.name;
            EXPECT_GE(a.mean, 0.0);
        }
    }
}

TEST(BxDFEnergy, RadianceTransmissionFromOutsideAtMostOne) {
    for (const LobeCase& l : nonSpecularLobes(TransportMode::Radiance)) {
        for (const WoCase& w : kWos) {
            if (w.wo.z < 0.f) continue;
            Albedo a = estimateAlbedo(l.bxdf, w.wo, 10000, 19);
            EXPECT_LE(a.mean, 1.0 + 5.0 * a.stdError + 1e-4) << l.name << " " << w.name;
        }
    }
}

// White furnace for the Disney BSDF where the model conserves energy: a white metal (Schlick
// Fresnel of R0 = 1 is 1) and a white dielectric of spectrans 1 (reflection F plus transmission
// 1 - F, importance transport: no eta^2 scaling). The albedo is at most 1 and, for smooth
// surfaces seen from above, close to 1 (what is lost is microfacet masking only).
TEST(BxDFEnergy, DisneyWhiteFurnace) {
    for (bool metal : {true, false}) {
        for (float rough : {0.15f, 0.5f}) {
            DisneyParams p;
            p.color = Spectrum(1.f);
            p.roughness = rough;
            if (metal) p.metallic = 1.f;
            else p.specTrans = 1.f;
            BSDF bsdf;
            buildDisney(bsdf, p, TransportMode::Importance);
            ASSERT_EQ(bsdf.numComponents(), metal ? 1 : 2);
            for (const WoCase& w : kWos) {
                if (metal && w.wo.z < 0.f) continue;  // a metal has no inside
                std::mt19937_64 rng(31);
                double sum = 0.0, sum2 = 0.0;
                const int n = 40000;
                for (int i = 0; i < n; ++i) {
                    BSDFSample s = bsdf.sampleF(w.wo, uniformFloat(rng),
                                                Vec2(uniformFloat(rng), uniformFloat(rng)));
                    double v = s.valid() ? maxComponent(s.f) * std::abs(s.wi.z) / s.pdf : 0.0;
                    sum += v;
                    sum2 += v * v;
                }
                double mean = sum / n, se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
                SCOPED_TRACE(std::string(metal ? "metal " : "dielectric ") + w.name + " rough " +
                             std::to_string(rough));
                EXPECT_LE(mean, 1.0 + 5.0 * se + 1e-4);
                if (rough < 0.2f && std::abs(w.wo.z) > 0.4f) {
                    EXPECT_GE(mean, 0.97);
                }
            }
        }
    }
}

TEST(BxDFEnergy, WhiteLambertianAlbedoIsOne) {
    BxDF b = LambertianReflection(Spectrum(1.f));
    for (const WoCase& w : kWos) {
        Albedo a = estimateAlbedo(b, w.wo, 20000, 23);
        EXPECT_NEAR(a.mean, 1.0, 1e-4) << w.name;  // every weight is exactly 1
    }
}

TEST(BxDFEnergy, SmoothGlassAlbedoIsOne) {
    BxDF b = FresnelSpecular(Spectrum(1.f), Spectrum(1.f), 1.f, 1.5f, TransportMode::Importance);
    for (const WoCase& w : kWos) {
        Albedo a = estimateAlbedo(b, w.wo, 20000, 29);
        EXPECT_NEAR(a.mean, 1.0, 1e-4) << w.name;  // weights are F/F or (1-F)/(1-F)
    }
}

TEST(BxDFEnergy, RoughMirrorMatchesIndependentQuadrature) {
    // Single-scattering GGX with alpha = 0.3 and F = 1 loses energy to the missing multiple
    // scattering. Reference albedos from an independent 2000 x 4000 midpoint quadrature of
    // D G / (4 cos_o cos_i) cos_i written from the textbook formulas: 0.8675 at cos_o = 0.9
    // and 0.8217 at cos_o = 0.5 (quadrature error < 1e-3).
    BxDF mirror = MicrofacetReflection(
        Spectrum(1.f), makeDist(MicrofacetType::TrowbridgeReitz, 0.3f, 0.3f), Fresnel::noOp());
    const std::pair<float, double> refs[] = {{0.9f, 0.8675}, {0.5f, 0.8217}};
    for (const auto& [cosTheta, ref] : refs) {
        Albedo a = estimateAlbedo(mirror, dirFromCos(cosTheta, 0.4f), 40000, 37);
        // 5 standard errors of the mean plus the quadrature error.
        EXPECT_NEAR(a.mean, ref, 5.0 * a.stdError + 1e-3) << "cos " << cosTheta;
    }
}

TEST(BxDFEnergy, RoughDielectricIsCloseToMirror) {
    // Reflection + transmission of a rough dielectric (importance mode, so no eta^2 scaling)
    // loses energy like the rough mirror but does not create any: albedo in [0.7, 1].
    for (MicrofacetType t : {MicrofacetType::TrowbridgeReitz, MicrofacetType::Beckmann}) {
        MicrofacetDistribution d = makeDist(t, 0.3f, 0.3f);
        BSDF glass;
        glass.add(MicrofacetReflection(Spectrum(1.f), d, Fresnel::dielectric(1.f, 1.5f)));
        glass.add(MicrofacetTransmission(Spectrum(1.f), d, 1.f, 1.5f, TransportMode::Importance));
        std::mt19937_64 rng(31);
        for (float cosTheta : {0.9f, 0.5f, -0.7f}) {
            Vec3 wo = dirFromCos(cosTheta, 0.4f);
            const int n = 40000;
            double sum = 0.0, sum2 = 0.0;
            for (int i = 0; i < n; ++i) {
                BSDFSample s = glass.sampleF(wo, uniformFloat(rng),
                                             Vec2(uniformFloat(rng), uniformFloat(rng)));
                double w = s.valid() ? s.f.x * std::abs(s.wi.z) / s.pdf : 0.0;
                sum += w;
                sum2 += w * w;
            }
            double mean = sum / n, se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
            EXPECT_GE(mean, 0.7) << distName(t) << " cos " << cosTheta;
            EXPECT_LE(mean, 1.0 + 5.0 * se) << distName(t) << " cos " << cosTheta;
        }
    }
}

// ---- reciprocity -------------------------------------------------------------------------

TEST(BxDF, ReflectionLobesAreReciprocal) {
    std::vector<LobeCase> lobes = nonSpecularLobes(TransportMode::Radiance);
    std::mt19937_64 rng(41);
    for (const LobeCase& l : lobes) {
        if (!hasAny(l.bxdf.flags(), BxDFFlags::Reflection)) continue;
        for (int i = 0; i < 500; ++i) {
            Vec3 wo = dirFromCos(0.02f + 0.98f * uniformFloat(rng), 2 * Pi * uniformFloat(rng));
            Vec3 wi = dirFromCos(0.02f + 0.98f * uniformFloat(rng), 2 * Pi * uniformFloat(rng));
            Spectrum a = l.bxdf.f(wo, wi), b = l.bxdf.f(wi, wo);
            for (int k = 0; k < 3; ++k)
                ASSERT_NEAR(a[k], b[k], 1e-3f * std::max(a[k], b[k]) + 1e-6f) << l.name;
        }
    }
}

// Transmission obeys the generalised reciprocity f(wo, wi) / eta_i^2 = f(wi, wo) / eta_o^2
// in importance mode (the radiance-mode scaling makes the radiance BTDF symmetric).
TEST(BxDF, MicrofacetTransmissionRadianceIsSymmetric) {
    BxDF b = MicrofacetTransmission(Spectrum(1.f),
                                    makeDist(MicrofacetType::TrowbridgeReitz, 0.3f, 0.2f), 1.f,
                                    1.5f, TransportMode::Radiance);
    BxDF bi = MicrofacetTransmission(Spectrum(1.f),
                                     makeDist(MicrofacetType::TrowbridgeReitz, 0.3f, 0.2f), 1.f,
                                     1.5f, TransportMode::Importance);
    std::mt19937_64 rng(43);
    int nonZero = 0;
    for (int i = 0; i < 500; ++i) {
        Vec3 wo = dirFromCos(0.05f + 0.95f * uniformFloat(rng), 2 * Pi * uniformFloat(rng));
        Vec3 wi = dirFromCos(-(0.05f + 0.95f * uniformFloat(rng)), 2 * Pi * uniformFloat(rng));
        Spectrum ioImportance = bi.f(wo, wi), oiImportance = bi.f(wi, wo);
        // wo outside (eta 1), wi inside (eta 1.5).
        ASSERT_NEAR(ioImportance.x / (1.5f * 1.5f), oiImportance.x,
                    1e-3f * oiImportance.x + 1e-6f);
        Spectrum io = b.f(wo, wi);
        ASSERT_NEAR(io.x, oiImportance.x, 1e-3f * io.x + 1e-6f);
        if (io.x > 0.f) ++nonZero;
    }
    EXPECT_GT(nonZero, 100);
}

// ---- Fresnel -----------------------------------------------------------------------------

TEST(Fresnel, DielectricKnownValues) {
    EXPECT_NEAR(frDielectric(1.f, 1.f, 1.5f), 0.04f, 1e-6f);  // ((1.5-1)/(1.5+1))^2
    EXPECT_NEAR(frDielectric(-1.f, 1.f, 1.5f), 0.04f, 1e-6f);
    EXPECT_NEAR(frDielectric(0.f, 1.f, 1.5f), 1.f, 1e-6f);
    // Brewster angle: Rp = 0, so R = Rs / 2 with Rs = ((n^2-1)/(n^2+1))^2 = (1.25/3.25)^2.
    float cosB = std::cos(std::atan(1.5f));
    float rs = (1.25f / 3.25f) * (1.25f / 3.25f);
    EXPECT_NEAR(frDielectric(cosB, 1.f, 1.5f), 0.5f * rs, 1e-5f);
    // 45 degrees from air into n = 1.5: Rs = 0.0920, Rp = 0.00846 (textbook values).
    EXPECT_NEAR(frDielectric(std::sqrt(0.5f), 1.f, 1.5f), 0.5f * (0.09202f + 0.008466f), 2e-4f);
    // Total internal reflection from inside beyond the critical angle asin(1/1.5) = 41.8 deg.
    EXPECT_EQ(frDielectric(-std::cos(radians(45.f)), 1.f, 1.5f), 1.f);
    EXPECT_LT(frDielectric(-std::cos(radians(40.f)), 1.f, 1.5f), 1.f);
    EXPECT_EQ(Fresnel::noOp().evaluate(0.3f), Spectrum(1.f));
}

TEST(Fresnel, ConductorKnownValues) {
    // Normal incidence: ((n-1)^2 + k^2) / ((n+1)^2 + k^2).
    Spectrum eta(0.2f, 0.92f, 1.1f), k(3.9f, 2.45f, 2.14f);
    Spectrum r = frConductor(1.f, Spectrum(1.f), eta, k);
    for (int c = 0; c < 3; ++c) {
        float expect = ((eta[c] - 1) * (eta[c] - 1) + k[c] * k[c]) /
                       ((eta[c] + 1) * (eta[c] + 1) + k[c] * k[c]);
        EXPECT_NEAR(r[c], expect, 1e-5f);
    }
    Spectrum grazing = frConductor(0.f, Spectrum(1.f), eta, k);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(grazing[c], 1.f, 1e-5f);
    // With k = 0 the conductor formula reduces to the dielectric one.
    for (float c : {0.1f, 0.4f, 0.8f, 1.f}) {
        EXPECT_NEAR(frConductor(c, Spectrum(1.f), Spectrum(1.5f), Spectrum(0.f)).x,
                    frDielectric(c, 1.f, 1.5f), 1e-5f);
    }
    // pbrt-v3's FresnelConductor uses |cos|.
    Fresnel fc = Fresnel::conductor(Spectrum(1.f), eta, k);
    EXPECT_NEAR(fc.evaluate(-0.5f).x, fc.evaluate(0.5f).x, 1e-7f);
}

// ---- specular lobes ----------------------------------------------------------------------

TEST(SpecularLobes, ReflectionIsExactMirror) {
    BxDF b = SpecularReflection(Spectrum(0.7f), Fresnel::dielectric(1.f, 1.5f));
    for (const WoCase& w : kWos) {
        BxDFSample s = b.sampleF(w.wo, 0.3f, Vec2(0.6f, 0.2f));
        ASSERT_TRUE(s.valid());
        EXPECT_EQ(s.wi, Vec3(-w.wo.x, -w.wo.y, w.wo.z));
        EXPECT_EQ(s.pdf, 1.f);
        EXPECT_TRUE(s.isSpecular() && s.isReflection());
        float fr = frDielectric(w.wo.z, 1.f, 1.5f);
        EXPECT_NEAR(s.f.x, 0.7f * fr / std::abs(w.wo.z), 1e-5f);
        EXPECT_EQ(b.f(w.wo, s.wi), Spectrum(0.f));
        EXPECT_EQ(b.pdf(w.wo, s.wi), 0.f);
    }
}

// Checks Snell's law and the plane of incidence for a refracted pair.
void expectRefraction(const Vec3& wo, const Vec3& wi, float etaO, float etaI) {
    EXPECT_LT(wo.z * wi.z, 0.f);
    float sinO = safeSqrt(1 - wo.z * wo.z), sinI = safeSqrt(1 - wi.z * wi.z);
    EXPECT_NEAR(etaO * sinO, etaI * sinI, 1e-5f);
    // Opposite azimuth: wi's tangential part is -etaO/etaI times wo's.
    EXPECT_NEAR(wi.x, -etaO / etaI * wo.x, 1e-5f);
    EXPECT_NEAR(wi.y, -etaO / etaI * wo.y, 1e-5f);
    EXPECT_NEAR(glm::length(wi), 1.f, 1e-5f);
}

TEST(SpecularLobes, TransmissionRefractsAndScales) {
    BxDF rad = SpecularTransmission(Spectrum(0.9f), 1.f, 1.5f, TransportMode::Radiance);
    BxDF imp = SpecularTransmission(Spectrum(0.9f), 1.f, 1.5f, TransportMode::Importance);
    for (const WoCase& w : kWos) {
        BxDFSample s = rad.sampleF(w.wo, 0.5f, Vec2(0.5f));
        BxDFSample si = imp.sampleF(w.wo, 0.5f, Vec2(0.5f));
        bool entering = w.wo.z > 0.f;
        float etaO = entering ? 1.f : 1.5f, etaI = entering ? 1.5f : 1.f;
        float sinI = etaO / etaI * safeSqrt(1 - w.wo.z * w.wo.z);
        if (sinI >= 1.f) {
            EXPECT_FALSE(s.valid()) << w.name;  // total internal reflection
            continue;
        }
        ASSERT_TRUE(s.valid()) << w.name;
        expectRefraction(w.wo, s.wi, etaO, etaI);
        EXPECT_TRUE(s.isTransmission() && s.isSpecular());
        float ft = 0.9f * (1.f - frDielectric(s.wi.z, 1.f, 1.5f)) / std::abs(s.wi.z);
        EXPECT_NEAR(si.f.x, ft, 1e-4f * ft);
        // Radiance scaling by (eta_o / eta_i)^2 (pbrt-v3: etaI^2 / etaT^2).
        EXPECT_NEAR(s.f.x, ft * (etaO * etaO) / (etaI * etaI), 1e-4f * ft);
        EXPECT_EQ(rad.f(w.wo, s.wi), Spectrum(0.f));
        EXPECT_EQ(rad.pdf(w.wo, s.wi), 0.f);
    }
}

TEST(SpecularLobes, FresnelSpecularChoosesByFresnel) {
    BxDF b = FresnelSpecular(Spectrum(1.f), Spectrum(1.f), 1.f, 1.5f, TransportMode::Radiance);
    Vec3 wo = dirFromCos(0.3f, 0.7f);
    float fr = frDielectric(0.3f, 1.f, 1.5f);
    BxDFSample r = b.sampleF(wo, 0.5f * fr, Vec2(0.5f));
    ASSERT_TRUE(r.valid());
    EXPECT_TRUE(r.isReflection() && r.isSpecular());
    EXPECT_EQ(r.wi, Vec3(-wo.x, -wo.y, wo.z));
    EXPECT_NEAR(r.pdf, fr, 1e-6f);
    EXPECT_NEAR(r.f.x, fr / 0.3f, 1e-5f);
    BxDFSample t = b.sampleF(wo, 0.5f + 0.5f * fr, Vec2(0.5f));
    ASSERT_TRUE(t.valid());
    EXPECT_TRUE(t.isTransmission() && t.isSpecular());
    expectRefraction(wo, t.wi, 1.f, 1.5f);
    EXPECT_NEAR(t.pdf, 1.f - fr, 1e-6f);
    EXPECT_NEAR(t.f.x, (1.f - fr) / (1.5f * 1.5f) / std::abs(t.wi.z), 1e-5f);
    // Fraction of reflection samples over uniform uc is F (binomial; 5 sigma tolerance).
    std::mt19937_64 rng(47);
    const int n = 20000;
    int reflections = 0;
    for (int i = 0; i < n; ++i)
        if (b.sampleF(wo, uniformFloat(rng), Vec2(0.5f)).isReflection()) ++reflections;
    EXPECT_NEAR(double(reflections) / n, fr, 5.0 * std::sqrt(fr * (1 - fr) / n));
    // From inside beyond the critical angle everything reflects.
    BxDFSample tir = b.sampleF(dirFromCos(-0.5f, 0.1f), 0.99f, Vec2(0.5f));
    EXPECT_TRUE(tir.isReflection());
    EXPECT_NEAR(tir.pdf, 1.f, 1e-6f);
}

// ---- microfacet --------------------------------------------------------------------------

TEST(Microfacet, RoughnessToAlphaMatchesPbrtPolynomial) {
    EXPECT_NEAR(TrowbridgeReitzDistribution::roughnessToAlpha(1.f), 1.62142f, 1e-5f);
    EXPECT_NEAR(TrowbridgeReitzDistribution::roughnessToAlpha(0.1f), 0.46176f, 1e-4f);
    EXPECT_NEAR(TrowbridgeReitzDistribution::roughnessToAlpha(0.01f), 0.138924f, 1e-4f);
    // Clamped below 1e-3.
    EXPECT_NEAR(TrowbridgeReitzDistribution::roughnessToAlpha(0.f), 0.0472695f, 1e-4f);
    EXPECT_EQ(BeckmannDistribution::roughnessToAlpha(0.3f),
              TrowbridgeReitzDistribution::roughnessToAlpha(0.3f));
}

// Integrates g(w) over the upper hemisphere (solid angle).
template <typename F>
double integrateHemisphere(const F& g) {
    auto inner = [&](double theta) {
        double st = std::sin(theta), ct = std::cos(theta);
        auto h = [&](double phi) {
            return g(Vec3(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct))) * st;
        };
        return chi2::adaptiveSimpson(h, 0.0, 2.0 * Pi, 1e-7, 10);
    };
    return chi2::adaptiveSimpson(inner, 0.0, 0.5 * Pi, 1e-7, 10);
}

TEST(Microfacet, DistributionsAreNormalised) {
    for (MicrofacetType t : {MicrofacetType::TrowbridgeReitz, MicrofacetType::Beckmann}) {
        for (Vec2 a : {Vec2(0.2f, 0.2f), Vec2(0.7f, 0.7f), Vec2(0.15f, 0.6f)}) {
            MicrofacetDistribution d = makeDist(t, a.x, a.y);
            // Projected microfacet area equals the macro-surface area: int D cos = 1.
            double projected = integrateHemisphere([&](const Vec3& wh) { return d.D(wh) * wh.z; });
            EXPECT_NEAR(projected, 1.0, 2e-3) << distName(t) << " " << a.x << " " << a.y;
            // Visible normals: int D G1(wo) max(0, wo.wh) / wo.z = 1 (checks Lambda against D).
            for (float c : {0.9f, 0.4f, 0.1f}) {
                Vec3 wo = dirFromCos(c, 0.8f);
                double visible = integrateHemisphere([&](const Vec3& wh) {
                    return d.D(wh) * d.G1(wo) * std::max(0.f, glm::dot(wo, wh)) / wo.z;
                });
                EXPECT_NEAR(visible, 1.0, 3e-3) << distName(t) << " cos " << c;
            }
        }
    }
}

TEST(Microfacet, SmithGIsSymmetricAndBounded) {
    MicrofacetDistribution d = makeDist(MicrofacetType::Beckmann, 0.3f, 0.5f);
    Vec3 a = dirFromCos(0.3f, 1.f), b = dirFromCos(0.8f, 2.f);
    EXPECT_NEAR(d.G(a, b), d.G(b, a), 1e-7f);
    EXPECT_LE(d.G(a, b), std::min(d.G1(a), d.G1(b)));
    EXPECT_NEAR(d.G1(Vec3(0, 0, 1)), 1.f, 1e-6f);
}

// ---- BSDF and builders ---------------------------------------------------------------------

TEST(BSDF, GeometricNormalSelectsReflectionOrTransmission) {
    BSDF bsdf;
    // Shading normal tilted 30 degrees away from the geometric normal.
    Vec3 ng(0.f, 0.f, 1.f), ns = glm::normalize(Vec3(std::tan(radians(30.f)), 0.f, 1.f));
    bsdf.init(ng, ns, Vec3(1.f, 0.f, 0.f));
    buildMatte(bsdf, Spectrum(0.6f), 0.f);
    Vec3 wo = Vec3(0.f, 0.f, 1.f);
    Vec3 wiAbove = glm::normalize(Vec3(0.3f, 0.2f, 0.9f));
    Vec3 wiBetween = glm::normalize(Vec3(1.f, 0.f, -0.1f));  // above ns, below ng
    ASSERT_GT(glm::dot(wiBetween, ns), 0.f);
    EXPECT_NEAR(bsdf.f(wo, wiAbove).x, 0.6f * InvPi, 1e-6f);
    EXPECT_EQ(bsdf.f(wo, wiBetween), Spectrum(0.f));
    // A transmission lobe is evaluated there instead.
    bsdf.add(LambertianTransmission(Spectrum(0.2f)));
    EXPECT_NEAR(bsdf.f(wo, wiBetween).x, 0.2f * InvPi, 1e-6f);
}

TEST(BSDF, FrameIsOrthonormalAndRoundTrips) {
    BSDF b;
    b.init(Vec3(0, 0, 1), glm::normalize(Vec3(0.2f, 0.1f, 1.f)), Vec3(1.f, 0.3f, 0.4f));
    const Frame& f = b.frame();
    EXPECT_NEAR(glm::dot(f.s, f.t), 0.f, 1e-6f);
    EXPECT_NEAR(glm::dot(f.s, f.n), 0.f, 1e-6f);
    EXPECT_NEAR(glm::length(f.s), 1.f, 1e-6f);
    EXPECT_NEAR(glm::dot(glm::cross(f.s, f.t), f.n), 1.f, 1e-6f);
    Vec3 v = glm::normalize(Vec3(0.3f, -0.5f, 0.2f));
    Vec3 back = b.localToWorld(b.worldToLocal(v));
    EXPECT_NEAR(glm::length(back - v), 0.f, 1e-6f);
    // Degenerate tangent falls back to an arbitrary frame.
    b.init(Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 2));
    EXPECT_NEAR(glm::dot(b.frame().s, b.frame().n), 0.f, 1e-6f);
    EXPECT_NEAR(glm::length(b.frame().s), 1.f, 1e-6f);
}

TEST(BSDF, ComponentsFlagsAndDelta) {
    BSDF b;
    EXPECT_EQ(b.numComponents(), 0);
    EXPECT_FALSE(b.isDelta());
    EXPECT_FALSE(b.sampleF(Vec3(0, 0, 1), 0.5f, Vec2(0.5f)).valid());
    EXPECT_EQ(b.pdf(Vec3(0, 0, 1), Vec3(0, 0, 1)), 0.f);

    buildMirror(b, Spectrum(0.9f));
    EXPECT_EQ(b.numComponents(), 1);
    EXPECT_TRUE(b.isDelta());
    BSDFSample s = b.sampleF(glm::normalize(Vec3(0.3f, 0.f, 1.f)), 0.2f, Vec2(0.4f));
    ASSERT_TRUE(s.valid());
    EXPECT_TRUE(s.isSpecular());
    EXPECT_NEAR(s.wi.x, -glm::normalize(Vec3(0.3f, 0.f, 1.f)).x, 1e-6f);

    buildPlastic(b, Spectrum(0.5f), Spectrum(0.3f), 0.1f, true);
    EXPECT_EQ(b.numComponents(), 2);
    EXPECT_FALSE(b.isDelta());
    EXPECT_EQ(b.numComponents(BxDFFlags::Reflection | BxDFFlags::Diffuse), 1);
    EXPECT_EQ(b.numComponents(BxDFFlags::Reflection | BxDFFlags::Glossy), 1);
    EXPECT_EQ(b.numComponents(BxDFFlags::Transmission | BxDFFlags::Diffuse), 0);
    ASSERT_NE(b.component(1).get<MicrofacetReflection>(), nullptr);
    EXPECT_NEAR(b.component(1).get<MicrofacetReflection>()->distribution.alphaX(), 0.46176f,
                1e-4f);
    EXPECT_EQ(b.component(1).get<MicrofacetReflection>()->fresnel.kind(),
              Fresnel::Kind::Dielectric);
    // Sampling restricted to the diffuse lobe only produces diffuse samples.
    s = b.sampleF(Vec3(0, 0, 1), 0.9f, Vec2(0.3f, 0.6f), BxDFFlags::Reflection | BxDFFlags::Diffuse);
    ASSERT_TRUE(s.valid());
    EXPECT_EQ(s.flags, BxDFFlags::Reflection | BxDFFlags::Diffuse);

    BSDF full;
    for (int i = 0; i < BSDF::MaxBxDFs; ++i) EXPECT_TRUE(full.add(LambertianReflection()));
    EXPECT_FALSE(full.add(LambertianReflection()));
}

// lobeCounts() is the integrator's one-pass form of three numComponents queries.
TEST(BSDF, LobeCountsMatchNumComponents) {
    auto expectCounts = [](const BSDF& b, const char* what) {
        SCOPED_TRACE(what);
        const BSDF::LobeCounts c = b.lobeCounts();
        EXPECT_EQ(c.all, b.numComponents());
        EXPECT_EQ(c.smooth, b.numComponents(BxDFFlags::All & ~BxDFFlags::Specular));
        EXPECT_EQ(c.diffuse, b.numComponents(BxDFFlags::Reflection | BxDFFlags::Transmission |
                                             BxDFFlags::Diffuse));
    };
    BSDF b;
    expectCounts(b, "empty");
    EXPECT_EQ(b.lobeCounts().all, 0);
    buildMirror(b, Spectrum(0.9f));
    expectCounts(b, "mirror");
    EXPECT_EQ(b.lobeCounts().smooth, 0);
    b.clear();
    buildPlastic(b, Spectrum(0.5f), Spectrum(0.3f), 0.1f, true);
    expectCounts(b, "plastic");
    EXPECT_EQ(b.lobeCounts().diffuse, 1);
    EXPECT_EQ(b.lobeCounts().smooth, 2);
    b.clear();
    buildMatte(b, Spectrum(0.5f), 0.f);
    expectCounts(b, "matte");
    EXPECT_EQ(b.lobeCounts().diffuse, 1);
    b.clear();
    buildGlass(b, Spectrum(1.f), Spectrum(1.f), 1.5f, 0.f, 0.f, false);
    expectCounts(b, "glass");
    b.clear();
    buildTranslucent(b, Spectrum(0.4f), Spectrum(0.3f), Spectrum(0.5f), Spectrum(0.5f), 0.1f,
                     true);
    expectCounts(b, "translucent");
    EXPECT_EQ(b.lobeCounts().diffuse, 2);
}

TEST(Builders, LobesFollowPbrtMaterials) {
    BSDF b;
    buildMatte(b, Spectrum(0.5f), 0.f);
    ASSERT_EQ(b.numComponents(), 1);
    EXPECT_NE(b.component(0).get<LambertianReflection>(), nullptr);
    buildMatte(b, Spectrum(0.5f), 20.f);
    ASSERT_EQ(b.numComponents(), 1);
    EXPECT_NE(b.component(0).get<OrenNayar>(), nullptr);
    buildMatte(b, Spectrum(0.f), 20.f);
    EXPECT_EQ(b.numComponents(), 0);

    buildPlastic(b, Spectrum(0.f), Spectrum(0.3f), 0.1f, false);
    ASSERT_EQ(b.numComponents(), 1);
    EXPECT_NEAR(b.component(0).get<MicrofacetReflection>()->distribution.alphaX(), 0.1f, 1e-7f);
    buildPlastic(b, Spectrum(0.3f), Spectrum(-1.f), 0.1f, false);  // negative ks clamps to black
    EXPECT_EQ(b.numComponents(), 1);

    buildMetal(b, Spectrum(0.2f), Spectrum(3.9f), 0.01f, 0.2f, true);
    ASSERT_EQ(b.numComponents(), 1);
    const auto* metal = b.component(0).get<MicrofacetReflection>();
    ASSERT_NE(metal, nullptr);
    EXPECT_EQ(metal->fresnel.kind(), Fresnel::Kind::Conductor);
    EXPECT_NEAR(metal->distribution.alphaX(), 0.138924f, 1e-4f);
    EXPECT_NEAR(metal->distribution.alphaY(), 0.683836f, 1e-4f);

    buildGlass(b, Spectrum(1.f), Spectrum(1.f), 1.5f, 0.f, 0.f, true);
    ASSERT_EQ(b.numComponents(), 1);
    EXPECT_NE(b.component(0).get<FresnelSpecular>(), nullptr);
    EXPECT_TRUE(b.isDelta());
    EXPECT_EQ(b.eta(), 1.5f);
    buildGlass(b, Spectrum(1.f), Spectrum(1.f), 1.33f, 0.1f, 0.f, true);
    ASSERT_EQ(b.numComponents(), 2);
    EXPECT_NE(b.component(0).get<MicrofacetReflection>(), nullptr);
    EXPECT_NE(b.component(1).get<MicrofacetTransmission>(), nullptr);
    EXPECT_EQ(b.eta(), 1.33f);
    buildGlass(b, Spectrum(0.f), Spectrum(1.f), 1.5f, 0.1f, 0.1f, true);
    ASSERT_EQ(b.numComponents(), 1);
    EXPECT_NE(b.component(0).get<MicrofacetTransmission>(), nullptr);
    buildGlass(b, Spectrum(0.f), Spectrum(0.f), 1.5f, 0.f, 0.f, true);
    EXPECT_EQ(b.numComponents(), 0);

    buildMirror(b, Spectrum(0.f));
    EXPECT_EQ(b.numComponents(), 0);

    buildUber(b, Spectrum(0.25f), Spectrum(0.25f), Spectrum(0.f), Spectrum(0.f), 0.1f, 0.1f,
              Spectrum(1.f), 1.5f, true);
    ASSERT_EQ(b.numComponents(), 2);
    EXPECT_EQ(b.eta(), 1.5f);
    EXPECT_NE(b.component(0).get<LambertianReflection>(), nullptr);
    EXPECT_NE(b.component(1).get<MicrofacetReflection>(), nullptr);
    buildUber(b, Spectrum(0.4f), Spectrum(0.2f), Spectrum(0.3f), Spectrum(0.1f), 0.1f, 0.1f,
              Spectrum(0.25f), 1.5f, true);
    ASSERT_EQ(b.numComponents(), 5);
    EXPECT_EQ(b.eta(), 1.f);
    const auto* pass = b.component(0).get<SpecularTransmission>();
    ASSERT_NE(pass, nullptr);
    EXPECT_NEAR(pass->t.x, 0.75f, 1e-6f);
    EXPECT_EQ(pass->etaB, 1.f);
    EXPECT_NEAR(b.component(1).get<LambertianReflection>()->r.x, 0.1f, 1e-6f);
    EXPECT_NE(b.component(3).get<SpecularReflection>(), nullptr);
    EXPECT_EQ(b.component(4).get<SpecularTransmission>()->etaB, 1.5f);

    buildSubstrate(b, Spectrum(0.5f), Spectrum(0.5f), 0.1f, 0.1f, true);
    ASSERT_EQ(b.numComponents(), 1);
    EXPECT_NE(b.component(0).get<FresnelBlend>(), nullptr);

    buildTranslucent(b, Spectrum(0.25f), Spectrum(0.25f), Spectrum(0.5f), Spectrum(0.5f), 0.1f,
                     true);
    ASSERT_EQ(b.numComponents(), 4);
    EXPECT_EQ(b.eta(), 1.5f);
    EXPECT_NEAR(b.component(0).get<LambertianReflection>()->r.x, 0.125f, 1e-6f);
    EXPECT_NE(b.component(1).get<LambertianTransmission>(), nullptr);
    EXPECT_NE(b.component(2).get<MicrofacetReflection>(), nullptr);
    EXPECT_NE(b.component(3).get<MicrofacetTransmission>(), nullptr);
    buildTranslucent(b, Spectrum(0.25f), Spectrum(0.25f), Spectrum(0.f), Spectrum(0.f), 0.1f,
                     true);
    EXPECT_EQ(b.numComponents(), 0);
}

}  // namespace
}  // namespace rlpbrt
