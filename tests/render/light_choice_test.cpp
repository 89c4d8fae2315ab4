// MixedLightChoice (render/light_sampler.h): a learned light choice mixed into a light
// sampler. Its pmf sums to 1 over the lights, trained and untrained; sample() draws lights
// with that pmf (chi-square); a light the learned CDF leaves out keeps its base share.
// LightGroups: one group per emitter, lights within it by power.
#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

#include "chi2.h"
#include "parser/diagnostics.h"
#include "parser/parser.h"
#include "render/light_sampler.h"
#include "render/scene.h"
#include "render/scene_builder.h"
#include "scene_text.h"

namespace rlpbrt {
namespace {

// A base sampler whose pmf depends on the point (as "spatial" does).
class TiltedSampler : public LightSampler {
public:
    explicit TiltedSampler(int n) : n_(n) {}
    float pmf(const Vec3& p, int light) const override {
        const float t = p.x > 0.f ? 2.f : 1.f;
        float total = 0.f;
        for (int i = 0; i < n_; ++i) total += 1.f + t * float(i);
        return (1.f + t * float(light)) / total;
    }
    int sample(const Vec3& p, float u, float* pmf, float* uRemapped = nullptr) const override {
        float acc = 0.f;
        for (int i = 0; i < n_; ++i) {
            const float lo = acc;
            acc += this->pmf(p, i);
            if (u < acc || i == n_ - 1) {
                *pmf = this->pmf(p, i);
                if (uRemapped) *uRemapped = remapInInterval(u, lo, acc);
                return i;
            }
        }
        return -1;
    }

private:
    int n_;
};

// A light of a given power (only power() is used by LightGroups).
class PowerLight : public Light {
public:
    explicit PowerLight(float w) : w_(w) {}
    LightKind kind() const override { return LightKind::DeltaPosition; }
    bool sampleLi(const LightSampleContext&, Vec2, LightSample*) const override { return false; }
    float pdfLi(const LightSampleContext&, const Vec3&, const Vec3&, const Vec3&) const override {
        return 0.f;
    }
    Spectrum power() const override { return Spectrum(w_); }

private:
    float w_;
};

std::vector<std::unique_ptr<Light>> lightsOfPower(const std::vector<float>& w) {
    std::vector<std::unique_ptr<Light>> lights;
    for (float x : w) lights.push_back(std::make_unique<PowerLight>(x));
    return lights;
}

// The mixture's pmf sums to 1 with every light above 0, and sample() follows it (chi-square),
// for no CDF and a learned CDF over the groups, shares 0..0.8, and two points; its remapped
// u is uniform in [0,1) for each light (chi-square over quarters).
void expectMixtureSamplesItsPmf(const LightSampler& base, const LightGroups& groups,
                                const float* cdf, int n) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> u01(0.f, 1.f);
    for (const float* c : {static_cast<const float*>(nullptr), cdf}) {
        for (float share : {0.f, 0.3f, 0.8f}) {
            for (const Vec3 p : {Vec3(-1.f, 0.f, 0.f), Vec3(1.f, 0.f, 0.f)}) {
                const MixedLightChoice mix{base, c, groups, share};
                double total = 0.0;
                std::vector<double> expected(static_cast<size_t>(n));
                std::vector<double> observed(expected.size(), 0.0);
                std::vector<double> quarters(4 * expected.size(), 0.0), eq(quarters.size());
                for (int l = 0; l < n; ++l) {
                    const float q = mix.pmf(p, l);
                    EXPECT_GT(q, 0.f) << l;  // every light keeps a chance
                    total += q;
                }
                EXPECT_NEAR(total, 1.0, 1e-6);
                constexpr int kSamples = 200000;
                for (int i = 0; i < kSamples; ++i) {
                    float pmf = 0.f, ur = -1.f;
                    const int l = mix.sample(p, u01(rng), &pmf, &ur);
                    ASSERT_GE(l, 0);
                    ASSERT_LT(l, n);
                    EXPECT_EQ(pmf, mix.pmf(p, l));
                    ASSERT_TRUE(ur >= 0.f && ur < 1.f) << ur;
                    observed[size_t(l)] += 1.0;
                    quarters[size_t(4 * l + int(ur * 4.f))] += 1.0;
                }
                for (int l = 0; l < n; ++l) {
                    expected[size_t(l)] = kSamples * mix.pmf(p, l);
                    for (int k = 0; k < 4; ++k) eq[size_t(4 * l + k)] = expected[size_t(l)] / 4.0;
                }
                const chi2::Result r = chi2::testCounts(observed, expected, 0.01, 24);
                EXPECT_TRUE(r.passed) << "share " << share << " p-value " << r.pValue;
                const chi2::Result rq = chi2::testCounts(quarters, eq, 0.01, 24);
                EXPECT_TRUE(rq.passed) << "remapped u, share " << share << " p-value " << rq.pValue;
            }
        }
    }
}

TEST(MixedLightChoice, PmfSumsToOneAndSamplesMatchIt) {
    constexpr int n = 4;
    const TiltedSampler base(n);
    // Four lights of four LightSources: four groups of one.
    const auto lights = lightsOfPower({1.f, 1.f, 1.f, 1.f});
    const LightGroups groups(lights, {-1, -1, -1, -1});
    ASSERT_EQ(groups.count(), n);
    // A learned CDF that leaves light 1 out (hidden from the region).
    const float cdf[n + 1] = {0.f, 0.6f, 0.6f, 0.7f, 1.f};
    expectMixtureSamplesItsPmf(base, groups, cdf, n);
    // Without a CDF or with share 0 the mixture is the base sampler.
    const MixedLightChoice none{base, nullptr, groups, 0.8f};
    EXPECT_EQ(none.pmf(Vec3(1.f, 0.f, 0.f), 2), base.pmf(Vec3(1.f, 0.f, 0.f), 2));
    const MixedLightChoice zero{base, cdf, groups, 0.f};
    EXPECT_EQ(zero.pmf(Vec3(1.f, 0.f, 0.f), 1), base.pmf(Vec3(1.f, 0.f, 0.f), 1));
    // The learned share: light 1 has only the base part.
    const MixedLightChoice mix{base, cdf, groups, 0.8f};
    EXPECT_FLOAT_EQ(mix.pmf(Vec3(1.f, 0.f, 0.f), 1), 0.2f * base.pmf(Vec3(1.f, 0.f, 0.f), 1));
}

// Emitters 7, 7, (a LightSource), 3, 3 with powers 1, 3, 2, 1, 1: three groups numbered by
// their first light, powers shared within; the learned CDF picks a group, power a light in it.
TEST(MixedLightChoice, GroupsAreEmittersAndLightsWithinGoByPower) {
    constexpr int n = 5;
    const auto lights = lightsOfPower({1.f, 3.f, 2.f, 1.f, 1.f});
    const LightGroups groups(lights, {7, 7, -1, 3, 3});
    ASSERT_EQ(groups.count(), 3);
    const int expectGroup[n] = {0, 0, 1, 2, 2};
    const float expectWithin[n] = {0.25f, 0.75f, 1.f, 0.5f, 0.5f};
    for (int l = 0; l < n; ++l) {
        EXPECT_EQ(groups.group(l), expectGroup[l]) << l;
        EXPECT_FLOAT_EQ(groups.within(l), expectWithin[l]) << l;
    }
    EXPECT_EQ(groups.sample(0, 0.2f), 0);
    EXPECT_EQ(groups.sample(0, 0.3f), 1);
    EXPECT_EQ(groups.sample(1, 0.99f), 2);
    EXPECT_EQ(groups.sample(2, 0.7f), 4);
    // Two LightSources (-1) are two groups; a dark emitter's lights share it evenly.
    const auto dark = lightsOfPower({0.f, 0.f, 1.f, 1.f});
    const LightGroups twoSources(dark, {5, 5, -1, -1});
    EXPECT_EQ(twoSources.count(), 3);
    EXPECT_FLOAT_EQ(twoSources.within(1), 0.5f);
    EXPECT_FLOAT_EQ(twoSources.within(3), 1.f);

    const TiltedSampler base(n);
    // The middle group hidden from the region.
    const float cdf[4] = {0.f, 0.7f, 0.7f, 1.f};
    expectMixtureSamplesItsPmf(base, groups, cdf, n);
    const MixedLightChoice mix{base, cdf, groups, 0.8f};
    const Vec3 p(1.f, 0.f, 0.f);
    EXPECT_FLOAT_EQ(mix.pmf(p, 1), 0.8f * 0.7f * 0.75f + 0.2f * base.pmf(p, 1));
    EXPECT_FLOAT_EQ(mix.pmf(p, 2), 0.2f * base.pmf(p, 2));
}

// The scene builder groups lights by emitter: a quad's two triangles are one group (nothing
// for a region to choose between, as in cornell-box), a second quad and a point light one each.
TEST(MixedLightChoice, SceneGroupsTheTrianglesOfOneEmitter) {
    const std::string quad = "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] "
                             "\"point P\" [0 0 0  1 0 0  1 1 0  0 1 0]\n";
    auto build = [](const std::string& world) {
        return test::sceneFromText(
            "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\"\nWorldBegin\n" + world + "WorldEnd\n",
            "groups.pbrt");
    };
    const std::string lit = "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n";
    auto one = build("AttributeBegin\n" + lit + quad + "AttributeEnd\n");
    ASSERT_TRUE(one);
    EXPECT_EQ(one->lights.size(), 2u);
    EXPECT_EQ(one->lightGroups.count(), 1);
    auto three = build("AttributeBegin\n" + lit + quad + "AttributeEnd\nAttributeBegin\n" + lit +
                       "Translate 0 0 1\n" + quad + "AttributeEnd\nLightSource \"point\"\n");
    ASSERT_TRUE(three);
    ASSERT_EQ(three->lights.size(), 5u);
    EXPECT_EQ(three->lightGroups.count(), 3);
    EXPECT_EQ(three->lightGroups.group(0), three->lightGroups.group(1));
    EXPECT_EQ(three->lightGroups.group(2), three->lightGroups.group(3));
    EXPECT_NE(three->lightGroups.group(1), three->lightGroups.group(2));
    EXPECT_FLOAT_EQ(three->lightGroups.within(2), 0.5f);
    EXPECT_FLOAT_EQ(three->lightGroups.within(4), 1.f);
}

}  // namespace
}  // namespace rlpbrt
