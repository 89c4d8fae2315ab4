// Subsurface scattering (render/bssrdf.h): the photon beam diffusion table, the profiles'
// normalisation, radius sampling against its pdf (chi-square), the probe sampling's density
// (Monte Carlo over a plane), the reflectance inversion and the exit lobe's normalisation.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "chi2.h"
#include "parser/diagnostics.h"
#include "parser/parser.h"
#include "render/bsdf.h"
#include "render/bssrdf.h"
#include "render/bxdfs.h"
#include "render/scene.h"
#include "render/scene_builder.h"
#include "scene_text.h"

namespace rlpbrt {
namespace {

const BSSRDFTable& table() {
    static const BSSRDFTable t = [] {
        BSSRDFTable t;
        computeBeamDiffusionTable(0.f, 1.33f, &t);
        return t;
    }();
    return t;
}

// Integral of f(r) 2 pi r dr over [0, rMax] (midpoint rule on a log-spaced grid plus the
// first interval).
template <typename F>
double radialIntegral(F f, double rMin, double rMax, int n = 20000) {
    double sum = 0.0;
    // [0, rMin]: uniform
    for (int i = 0; i < 200; ++i) {
        double r = (i + 0.5) * rMin / 200;
        sum += f(float(r)) * 2 * Pi * r * rMin / 200;
    }
    const double l0 = std::log(rMin), l1 = std::log(rMax);
    for (int i = 0; i < n; ++i) {
        double a = std::exp(l0 + (l1 - l0) * i / n), b = std::exp(l0 + (l1 - l0) * (i + 1) / n);
        double r = 0.5 * (a + b);
        sum += f(float(r)) * 2 * Pi * r * (b - a);
    }
    return sum;
}

// (Photon beam diffusion is an approximation: at albedo 1 it returns slightly more than 1.)
TEST(BSSRDFTable, EffectiveAlbedoGrowsWithAlbedoAndStaysNearOrBelowOne) {
    const BSSRDFTable& t = table();
    ASSERT_EQ(t.nRho, 100);
    ASSERT_EQ(t.nRadius, 64);
    EXPECT_NEAR(t.rhoEff.front(), 0.f, 1e-6f);
    for (int i = 1; i < t.nRho; ++i) {
        EXPECT_GT(t.rhoEff[size_t(i)], t.rhoEff[size_t(i - 1)]) << i;
        EXPECT_LT(t.rhoEff[size_t(i)], i < 90 ? 1.f : 1.05f) << i;
    }
    // A white medium returns (nearly) all of the light.
    EXPECT_GT(t.rhoEff.back(), 0.95f);
}

// The tabulated profile integrates to the effective albedo of its medium and its sampling
// density to 1, in any units (sigma_t scales the radius); Disney's profile integrates to R.
TEST(BSSRDFProfile, IntegralsAreTheAlbedoAndOne) {
    const BSSRDFTable& t = table();
    const Spectrum sa(0.01f, 0.2f, 1.f), ss(3.f, 2.f, 1.f);
    SeparableBSSRDF b = SeparableBSSRDF::tabulated(&t, sa, ss, 1.33f);
    for (int ch = 0; ch < 3; ++ch) {
        SCOPED_TRACE(ch);
        const float st = sa[ch] + ss[ch], rho = ss[ch] / st;
        const double rMax = t.radius.back() / st;
        double profile = radialIntegral([&](float r) { return b.sr(r)[ch]; }, 1e-4 / st, rMax);
        double pdf = radialIntegral([&](float r) { return b.pdfSr(ch, r); }, 1e-4 / st, rMax);
        // rhoEff of this albedo from the table's nodes (linear between the two around rho).
        int i = 0;
        while (t.rho[size_t(i + 1)] < rho) ++i;
        float w = (rho - t.rho[size_t(i)]) / (t.rho[size_t(i + 1)] - t.rho[size_t(i)]);
        double eff = (1 - w) * t.rhoEff[size_t(i)] + w * t.rhoEff[size_t(i + 1)];
        EXPECT_NEAR(profile, eff, 0.01 * eff + 1e-4);
        EXPECT_NEAR(pdf, 1.0, 0.01);
    }
    SeparableBSSRDF d = SeparableBSSRDF::disney(Spectrum(0.8f, 0.5f, 0.2f),
                                                Spectrum(0.2f, 0.5f, 1.f), 1.5f);
    for (int ch = 0; ch < 3; ++ch) {
        SCOPED_TRACE(ch);
        const double rMax = 60.0 * 0.2 * (ch == 0 ? 0.2 : ch == 1 ? 0.5 : 1.0);
        double profile = radialIntegral([&](float r) { return d.sr(r)[ch]; }, 1e-5, rMax);
        double pdf = radialIntegral([&](float r) { return d.pdfSr(ch, r); }, 1e-5, rMax);
        EXPECT_NEAR(profile, ch == 0 ? 0.8 : ch == 1 ? 0.5 : 0.2, 0.005);
        EXPECT_NEAR(pdf, 1.0, 0.005);
    }
}

// Radii drawn by sampleSr follow pdfSr 2 pi r (chi-square over log-spaced bins).
TEST(BSSRDFProfile, SampledRadiiFollowThePdf) {
    const BSSRDFTable& t = table();
    const Spectrum sa(0.05f, 0.5f, 0.001f), ss(2.f, 1.f, 0.5f);
    SeparableBSSRDF tab = SeparableBSSRDF::tabulated(&t, sa, ss, 1.33f);
    SeparableBSSRDF dis = SeparableBSSRDF::disney(Spectrum(0.7f), Spectrum(0.3f, 1.f, 2.f), 1.4f);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    const int kBins = 40, kSamples = 200000;
    int tests = 0;
    for (const SeparableBSSRDF* b : {&tab, &dis}) {
        for (int ch = 0; ch < 3; ++ch) {
            SCOPED_TRACE(std::string(b == &tab ? "tabulated" : "disney") + " ch " +
                         std::to_string(ch));
            const double rLo = b->sampleSr(ch, 0.001f), rHi = b->sampleSr(ch, 0.9995f);
            ASSERT_GT(rLo, 0.0);
            ASSERT_GT(rHi, rLo);
            // Bins: [0, rLo), log-spaced in [rLo, rHi), [rHi, inf).
            std::vector<double> edges = {0.0};
            for (int i = 0; i <= kBins; ++i)
                edges.push_back(rLo * std::pow(rHi / rLo, double(i) / kBins));
            std::vector<double> observed(edges.size(), 0.0), expected(edges.size(), 0.0);
            for (int s = 0; s < kSamples; ++s) {
                float r = b->sampleSr(ch, uni(rng));
                size_t k = size_t(std::upper_bound(edges.begin(), edges.end(), double(r)) -
                                  edges.begin()) - 1;
                observed[k] += 1;
            }
            double total = 0.0;
            for (size_t k = 0; k + 1 < edges.size(); ++k) {
                double a = edges[k], c = edges[k + 1], sum = 0.0;
                const int n = 200;
                for (int i = 0; i < n; ++i) {
                    double r = a + (c - a) * (i + 0.5) / n;
                    sum += b->pdfSr(ch, float(r)) * 2 * Pi * r * (c - a) / n;
                }
                expected[k] = sum * kSamples;
                total += sum;
            }
            expected.back() = std::max(0.0, 1.0 - total) * kSamples;
            chi2::Result r = chi2::testCounts(observed, expected, 0.01, 6);
            ++tests;
            EXPECT_TRUE(r.passed) << r.message;
        }
    }
    EXPECT_EQ(tests, 6);
}

// Probe sampling over the plane z = 0 around po = 0 (frame: the plane's): each probe along the
// normal crosses the plane once; Sp / (pdfSp / hits) then estimates the profile's integral
// over the plane (up to rMax), per channel.
TEST(BSSRDFProbe, PlaneEstimateMatchesTheProfileIntegral) {
    const BSSRDFTable& t = table();
    const Spectrum sa(0.02f, 0.1f, 0.4f), ss(1.5f, 1.f, 0.8f);
    SeparableBSSRDF b = SeparableBSSRDF::tabulated(&t, sa, ss, 1.33f);
    const Frame f;  // s = x, t = y, n = z
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    const int kSamples = 400000;
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
    for (int s = 0; s < kSamples; ++s) {
        BSSRDFProbe p;
        Spectrum est(0.f);
        if (sampleProbe(b, f, Vec3(0.f), uni(rng), Vec2(uni(rng), uni(rng)), &p) &&
            p.start.z * p.end.z < 0.f) {
            const float a = p.start.z / (p.start.z - p.end.z);
            const Vec3 pi = p.start + a * (p.end - p.start);
            const float pdf = pdfSp(b, f, Vec3(0.f), pi, Vec3(0, 0, 1));
            if (pdf > 0.f) est = b.sr(glm::length(pi)) / pdf;
        }
        for (int c = 0; c < 3; ++c) {
            sum[c] += est[c];
            sum2[c] += double(est[c]) * est[c];
        }
    }
    for (int c = 0; c < 3; ++c) {
        SCOPED_TRACE(c);
        const double mean = sum[c] / kSamples;
        const double se = std::sqrt((sum2[c] / kSamples - mean * mean) / kSamples);
        const float st = sa[c] + ss[c];
        // The integral up to the largest rMax of the channels (samples beyond a channel's
        // own rMax are rejected by sampleProbe, a part of the profile below 0.1%).
        float rMax = 0.f;
        for (int ch = 0; ch < 3; ++ch) rMax = std::max(rMax, b.rMax(ch));
        const double truth = radialIntegral([&](float r) { return b.sr(r)[c]; }, 1e-4 / st, rMax);
        EXPECT_NEAR(mean, truth, 4.0 * se + 0.01 * truth) << "se " << se;
    }
}

TEST(BSSRDF, ReflectanceInversionRoundTrips) {
    const BSSRDFTable& t = table();
    const Spectrum kd(0.8f, 0.5f, 0.3f), mfp(0.5f, 1.f, 2.f);
    Spectrum sa, ss;
    subsurfaceFromDiffuse(t, kd, mfp, &sa, &ss);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(sa[c] + ss[c], 1.f / mfp[c], 1e-4f);
        SeparableBSSRDF b = SeparableBSSRDF::tabulated(&t, sa, ss, 1.33f);
        const float st = sa[c] + ss[c];
        double eff =
            radialIntegral([&](float r) { return b.sr(r)[c]; }, 1e-4 / st, t.radius.back() / st);
        EXPECT_NEAR(eff, kd[c], 0.01);
    }
}

TEST(BSSRDF, MeasuredMediaAreKnownByName) {
    Spectrum sa, ss;
    ASSERT_TRUE(measuredSubsurface("Ketchup", &sa, &ss));
    EXPECT_FLOAT_EQ(sa.z, 1.45f);
    EXPECT_FLOAT_EQ(ss.x, 0.18f);
    EXPECT_TRUE(measuredSubsurface("Regular Milk", &sa, &ss));
    EXPECT_FALSE(measuredSubsurface("ketchup", &sa, &ss));
}

// The exit lobe Sw cos integrates to 1 over the hemisphere (its constant c normalises it);
// radiance transport scales it by eta^2.
TEST(BSSRDFExitLobe, IsNormalised) {
    for (float eta : {1.33f, 1.5f}) {
        BSSRDFExitLobe imp(eta, TransportMode::Importance), rad(eta, TransportMode::Radiance);
        const Vec3 wo(0, 0, 1);
        double sum = 0.0;
        const int n = 4000;
        for (int i = 0; i < n; ++i) {
            float cosT = (i + 0.5f) / n;
            Vec3 wi(std::sqrt(1 - cosT * cosT), 0.f, cosT);
            sum += imp.f(wo, wi).x * cosT * 2 * Pi / n;
            EXPECT_FLOAT_EQ(rad.f(wo, wi).x, imp.f(wo, wi).x * eta * eta);
        }
        EXPECT_NEAR(sum, 1.0, 0.01) << eta;
        EXPECT_EQ(imp.f(wo, Vec3(0, 0, -1)).x, 0.f);
    }
}

// The materials: the BSDF at a sphere's hit carries the BSSRDF, with pbrt-v3's parameters.
struct MaterialHit {
    std::unique_ptr<Scene> scene;  // owns the material, whose table the BSSRDF points to
    BSDF bsdf;
    int warnings = 0;
    bool ok = false;
};
MaterialHit materialHit(const std::string& material) {
    MaterialHit out;
    Diagnostics diag;
    out.scene = test::sceneFromText("LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n"
                                    "LightSource \"infinite\"\n" +
                                        material + "\nShape \"sphere\" \"float radius\" 1\nWorldEnd\n",
                                    "sss.pbrt", diag);
    if (!out.scene) return out;
    SurfaceInteraction si;
    if (!out.scene->intersect(Ray(Vec3(0.1f, 0.2f, 5.f), Vec3(0, 0, -1)), &si)) return out;
    out.scene->materials[size_t(si.material)]->computeBSDF(si, 0.5f, &out.bsdf);
    out.warnings = diag.warningCount();
    out.ok = true;
    return out;
}

TEST(SubsurfaceMaterial, NamedMediumAndCoefficients) {
    MaterialHit named = materialHit("Material \"subsurface\" \"string name\" \"Ketchup\"");
    ASSERT_TRUE(named.ok);
    EXPECT_EQ(named.warnings, 0);
    const SeparableBSSRDF* b = named.bsdf.subsurface();
    ASSERT_NE(b, nullptr);
    EXPECT_FLOAT_EQ(b->eta(), 1.33f);
    // Smooth boundary by default: one FresnelSpecular lobe (a delta BSDF: no guiding).
    EXPECT_TRUE(named.bsdf.isDelta());
    MaterialHit given = materialHit(
        "Material \"subsurface\" \"rgb sigma_a\" [0.061 0.97 1.45] \"rgb sigma_s\" "
        "[0.18 0.07 0.03] \"float uroughness\" 0.1 \"float vroughness\" 0.1");
    ASSERT_TRUE(given.ok);
    ASSERT_NE(given.bsdf.subsurface(), nullptr);
    EXPECT_FALSE(given.bsdf.isDelta());
    for (float r : {0.f, 0.3f, 2.f})
        EXPECT_EQ(given.bsdf.subsurface()->sr(r), b->sr(r)) << r;
    // scale multiplies the coefficients: the profile's radii shrink by it.
    MaterialHit scaled = materialHit(
        "Material \"subsurface\" \"string name\" \"Ketchup\" \"float scale\" 2");
    ASSERT_TRUE(scaled.ok);
    EXPECT_NEAR(scaled.bsdf.subsurface()->rMax(1), 0.5f * b->rMax(1), 1e-5f);
    // An unknown name: pbrt-v3's defaults, with a warning.
    MaterialHit unknown = materialHit("Material \"subsurface\" \"string name\" \"Ketchupp\"");
    ASSERT_TRUE(unknown.ok);
    EXPECT_EQ(unknown.warnings, 1);
}

TEST(SubsurfaceMaterial, KdSubsurfaceMfpDefaultsToOneAndIgnoresAFloat) {
    MaterialHit def = materialHit("Material \"kdsubsurface\" \"rgb Kd\" [0.8 0.5 0.3]");
    MaterialHit one = materialHit(
        "Material \"kdsubsurface\" \"rgb Kd\" [0.8 0.5 0.3] \"rgb mfp\" [1 1 1]");
    // pbrt-v3 reads mfp as a spectrum only: a float is ignored with a warning (mfp 1).
    MaterialHit flt =
        materialHit("Material \"kdsubsurface\" \"rgb Kd\" [0.8 0.5 0.3] \"float mfp\" 0.5");
    ASSERT_TRUE(def.ok && one.ok && flt.ok);
    EXPECT_EQ(def.warnings, 0);
    EXPECT_EQ(flt.warnings, 1);
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_EQ(def.bsdf.subsurface()->rMax(ch), one.bsdf.subsurface()->rMax(ch));
        EXPECT_EQ(flt.bsdf.subsurface()->rMax(ch), one.bsdf.subsurface()->rMax(ch));
    }
    MaterialHit half = materialHit(
        "Material \"kdsubsurface\" \"rgb Kd\" [0.8 0.5 0.3] \"rgb mfp\" [0.5 0.5 0.5]");
    ASSERT_TRUE(half.ok);
    EXPECT_NEAR(half.bsdf.subsurface()->rMax(0), 0.5f * one.bsdf.subsurface()->rMax(0), 1e-5f);
}

TEST(SubsurfaceMaterial, DisneyScatterDistance) {
    MaterialHit sss = materialHit(
        "Material \"disney\" \"color color\" [0.8 0.6 0.4] \"color scatterdistance\" "
        "[0.2 0.3 0.4]");
    ASSERT_TRUE(sss.ok);
    EXPECT_EQ(sss.warnings, 0);
    ASSERT_NE(sss.bsdf.subsurface(), nullptr);
    EXPECT_FLOAT_EQ(sss.bsdf.subsurface()->eta(), 1.5f);
    bool specularTransmission = false;
    for (int i = 0; i < sss.bsdf.numComponents(); ++i)
        specularTransmission |= sss.bsdf.component(i).get<SpecularTransmission>() != nullptr;
    EXPECT_TRUE(specularTransmission);
    // thin: no BSSRDF.
    MaterialHit thin = materialHit(
        "Material \"disney\" \"color scatterdistance\" [0.2 0.3 0.4] \"bool thin\" true");
    ASSERT_TRUE(thin.ok);
    EXPECT_EQ(thin.bsdf.subsurface(), nullptr);
    MaterialHit plain = materialHit("Material \"disney\"");
    ASSERT_TRUE(plain.ok);
    EXPECT_EQ(plain.bsdf.subsurface(), nullptr);
}

}  // namespace
}  // namespace rlpbrt
