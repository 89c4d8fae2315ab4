// The "hair" material: HairBxDF's sampling against its pdf (chi-square), energy conservation
// without absorption (a white furnace, pbrt-v3's own test idea), importance sampling's
// estimate of the same integral, the absorption helpers, and the material's parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "chi2.h"
#include "parser/diagnostics.h"
#include "parser/parser.h"
#include "render/bsdf.h"
#include "render/hair.h"
#include "render/sampling.h"
#include "render/scene.h"
#include "render/scene_builder.h"
#include "scene_text.h"

namespace rlpbrt {
namespace {

Vec3 sphereDir(float theta, float phi) {
    // theta from the hair's axis-normal plane: x is along the hair.
    return Vec3(std::sin(theta), std::cos(theta) * std::cos(phi), std::cos(theta) * std::sin(phi));
}

struct HairChi2Case {
    std::string name;
    float h, betaM, betaN;
    Spectrum sigmaA;
    Vec3 wo;
};

std::vector<HairChi2Case> hairChi2Cases() {
    std::vector<HairChi2Case> cases;
    struct Lobe { const char* name; float h, bm, bn; Spectrum sa; };
    const Lobe lobes[] = {{"brown", 0.3f, 0.3f, 0.3f, Spectrum(0.84f, 1.39f, 2.74f)},
                          {"blond_edge", -0.8f, 0.25f, 0.3f, Spectrum(0.15f, 0.25f, 0.5f)},
                          {"white_rough", 0.f, 0.6f, 0.7f, Spectrum(0.f)}};
    const struct { const char* name; Vec3 wo; } wos[] = {
        {"across", glm::normalize(sphereDir(0.1f, 0.4f))},
        {"along", glm::normalize(sphereDir(1.1f, -2.f))}};
    for (const Lobe& l : lobes)
        for (const auto& w : wos)
            cases.push_back({std::string(l.name) + "_" + w.name, l.h, l.bm, l.bn, l.sa, w.wo});
    return cases;
}

// The integral of the lobe's pdf over the sphere (midpoint rule, 256 x 256 equal areas).
double pdfIntegral(const HairBxDF& hair, const Vec3& wo) {
    const int n = 256;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            sum += hair.pdf(wo, sampleUniformSphere(Vec2((i + 0.5f) / n, (j + 0.5f) / n)));
    return sum * 4.0 * Pi / (double(n) * n);
}

// Without the scales' tilt (alpha = 0) the sampling procedure draws exactly the density the
// pdf describes, up to the normalisation of pbrt-v3's I0 series (within 1% here): the test
// compares the sampled directions with the pdf divided by its integral. (With a tilt,
// pbrt-v3's pdf evaluates the tilted M_p without the cosine's change of measure, so it is
// not the sampled density; f / pdf follow pbrt-v3 there, as the reference test checks.)
class HairChi2 : public ::testing::TestWithParam<HairChi2Case> {};

TEST_P(HairChi2, SampleMatchesPdf) {
    const HairChi2Case& c = GetParam();
    HairBxDF hair(c.h, 1.55f, c.sigmaA, c.betaM, c.betaN, 0.f);
    double norm = pdfIntegral(hair, c.wo);
    EXPECT_NEAR(norm, 1.0, 0.01);
    auto sample = [&](const Vec3& u) {
        BxDFSample s = hair.sampleF(c.wo, u.x, Vec2(u.y, u.z));
        if (!s.valid()) return chi2::SphereSample();
        return chi2::SphereSample{s.wi, float(s.pdf / norm)};
    };
    auto pdf = [&](const Vec3& wi) { return float(hair.pdf(c.wo, wi) / norm); };
    chi2::SphereOptions opt;
    opt.sampleCount = 200000;
    opt.numTests = int(hairChi2Cases().size());
    opt.seed = std::hash<std::string>()(c.name);
    chi2::SphereResult r = chi2::testSphere(sample, pdf, opt);
    EXPECT_TRUE(r.passed) << r.message;
}

INSTANTIATE_TEST_SUITE_P(Lobes, HairChi2, ::testing::ValuesIn(hairChi2Cases()),
                         [](const auto& info) { return info.param.name; });

// Without absorption, the fibre scatters all light: the integral of f |cos| over the sphere
// is 1 for every wo and h (the lobes' attenuations then sum to exactly 1, and M_p and N_p are
// normalised up to pbrt-v3's approximation of I0 by ten terms of its series, which is up to
// 2% low near x = 12, where the asymptotic form takes over). As pbrt-v3's own furnace test,
// without the scales' tilt (alpha = 0): the tilt shifts the lobes against the cosine, by up
// to 20% at grazing angles, in pbrt-v3 as here. The integral by the midpoint rule on a
// 128 x 128 equal-area grid; and, with and without tilt, the sampled weights f |cos| / pdf,
// which are then exactly 1 (the lobe probabilities are the attenuations themselves).
TEST(Hair, WhiteFurnace) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    for (float alpha : {0.f, 2.f})
        for (float betaM : {0.2f, 0.5f, 0.8f})
            for (float betaN : {0.2f, 0.5f, 0.8f})
                for (int trial = 0; trial < 2; ++trial) {
                    float h = -1.f + 2.f * uni(rng);
                    Vec3 wo = sampleUniformSphere(Vec2(uni(rng), uni(rng)));
                    HairBxDF hair(h, 1.55f, Spectrum(0.f), betaM, betaN, alpha);
                    const int n = 128;
                    double sum = 0.0;
                    int badWeights = 0;
                    for (int i = 0; i < n; ++i)
                        for (int j = 0; j < n; ++j) {
                            Vec2 u((float(i) + 0.5f) / n, (float(j) + 0.5f) / n);
                            Vec3 wi = sampleUniformSphere(u);
                            sum += double(hair.f(wo, wi).y) * std::abs(wi.z);
                            BxDFSample s = hair.sampleF(wo, uni(rng), u);
                            if (!s.valid() ||
                                std::abs(s.f.y * std::abs(s.wi.z) / s.pdf - 1.f) > 1e-3f)
                                ++badWeights;
                        }
                    double integral = sum * 4.0 * Pi / (double(n) * n);
                    SCOPED_TRACE("alpha " + std::to_string(alpha) + " beta_m " +
                                 std::to_string(betaM) + " beta_n " + std::to_string(betaN) +
                                 " h " + std::to_string(h));
                    if (alpha == 0.f) {
                        EXPECT_NEAR(integral, 1.0, 0.02);
                    }
                    EXPECT_EQ(badWeights, 0);
                }
}

TEST(Hair, AbsorptionFromPigmentsAndColour) {
    // pbrt-v3's default (eumelanin 1.3) and its pigment spectra.
    Spectrum d = hairSigmaAFromConcentration(1.3f, 0.f);
    EXPECT_NEAR(d.x, 1.3f * 0.419f, 1e-6f);
    EXPECT_NEAR(d.z, 1.3f * 1.37f, 1e-6f);
    Spectrum p = hairSigmaAFromConcentration(0.f, 1.f);
    EXPECT_NEAR(p.y, 0.4f, 1e-6f);
    // Colour: white hair has no absorption; darker colours absorb more.
    Spectrum w = hairSigmaAFromReflectance(Spectrum(1.f), 0.3f);
    EXPECT_EQ(w, Spectrum(0.f));
    Spectrum c = hairSigmaAFromReflectance(Spectrum(0.8f, 0.5f, 0.2f), 0.3f);
    EXPECT_LT(c.x, c.y);
    EXPECT_LT(c.y, c.z);
}

TEST(Hair, MaterialOnACurve) {
    Diagnostics diag;
    auto scene = test::sceneFromText(
        "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n"
        "LightSource \"infinite\"\n"
        "Material \"hair\" \"float eumelanin\" 0.3 \"rgb sigma_a\" [0.1 0.2 0.3]\n"
        "Shape \"curve\" \"string type\" \"cylinder\" \"point P\" [-1 0 0 -0.3333 0 0 "
        "0.3333 0 0 1 0 0] \"float width\" 0.2\nWorldEnd\n",
        "hair.pbrt", diag);
    ASSERT_NE(scene, nullptr);
    EXPECT_EQ(diag.warningCount(), 1);  // eumelanin is ignored: sigma_a is given
    SurfaceInteraction si;
    ASSERT_TRUE(scene->intersect(Ray(Vec3(0.2f, 0.05f, 5.f), Vec3(0, 0, -1)), &si));
    BSDF bsdf;
    scene->materials[size_t(si.material)]->computeBSDF(si, 0.5f, &bsdf);
    ASSERT_EQ(bsdf.numComponents(), 1);
    // Glossy (the integrator leaves it to the BSDF's own sampling), both sides.
    BSDF::LobeCounts lc = bsdf.lobeCounts();
    EXPECT_EQ(lc.smooth, 1);
    EXPECT_EQ(lc.diffuse, 0);
    const HairBxDF* hair = bsdf.component(0).get<HairBxDF>();
    ASSERT_NE(hair, nullptr);
    EXPECT_NEAR(hair->h, -1.f + 2.f * si.uv.y, 1e-6f);
    EXPECT_EQ(hair->sigmaA, Spectrum(0.1f, 0.2f, 0.3f));
    EXPECT_NEAR(glm::dot(bsdf.frame().s, glm::normalize(si.dpdu)), 1.f, 1e-5f);
}

}  // namespace
}  // namespace rlpbrt
