// MixedLightChoice (render/light_sampler.h): a learned light choice mixed into a light
// sampler. Its pmf sums to 1 over the lights, trained and untrained; sample() draws lights
// with that pmf (chi-square); a light the learned CDF leaves out keeps its base share.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "chi2.h"
#include "render/light_sampler.h"

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
    int sample(const Vec3& p, float u, float* pmf) const override {
        float acc = 0.f;
        for (int i = 0; i < n_; ++i) {
            acc += this->pmf(p, i);
            if (u < acc || i == n_ - 1) {
                *pmf = this->pmf(p, i);
                return i;
            }
        }
        return -1;
    }

private:
    int n_;
};

TEST(MixedLightChoice, PmfSumsToOneAndSamplesMatchIt) {
    constexpr int n = 4;
    const TiltedSampler base(n);
    // A learned CDF that leaves light 1 out (hidden from the region).
    const float cdf[n + 1] = {0.f, 0.6f, 0.6f, 0.7f, 1.f};
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> u01(0.f, 1.f);
    for (const float* c : {static_cast<const float*>(nullptr), cdf}) {
        for (float share : {0.f, 0.3f, 0.8f}) {
            for (const Vec3 p : {Vec3(-1.f, 0.f, 0.f), Vec3(1.f, 0.f, 0.f)}) {
                const MixedLightChoice mix{base, c, n, share};
                double total = 0.0;
                std::vector<double> expected(n), observed(n, 0.0);
                for (int l = 0; l < n; ++l) {
                    const float q = mix.pmf(p, l);
                    EXPECT_GT(q, 0.f) << l;  // every light keeps a chance
                    total += q;
                }
                EXPECT_NEAR(total, 1.0, 1e-6);
                constexpr int kSamples = 200000;
                for (int i = 0; i < kSamples; ++i) {
                    float pmf = 0.f;
                    const int l = mix.sample(p, u01(rng), &pmf);
                    ASSERT_GE(l, 0);
                    ASSERT_LT(l, n);
                    EXPECT_EQ(pmf, mix.pmf(p, l));
                    observed[size_t(l)] += 1.0;
                }
                for (int l = 0; l < n; ++l) expected[size_t(l)] = kSamples * mix.pmf(p, l);
                const chi2::Result r = chi2::testCounts(observed, expected, 0.01, 12);
                EXPECT_TRUE(r.passed) << "share " << share << " p-value " << r.pValue;
            }
        }
    }
    // Without a CDF or with share 0 the mixture is the base sampler.
    const MixedLightChoice none{base, nullptr, n, 0.8f};
    EXPECT_EQ(none.pmf(Vec3(1.f, 0.f, 0.f), 2), base.pmf(Vec3(1.f, 0.f, 0.f), 2));
    const MixedLightChoice zero{base, cdf, n, 0.f};
    EXPECT_EQ(zero.pmf(Vec3(1.f, 0.f, 0.f), 1), base.pmf(Vec3(1.f, 0.f, 0.f), 1));
    // The learned share: light 1 has only the base part.
    const MixedLightChoice mix{base, cdf, n, 0.8f};
    EXPECT_FLOAT_EQ(mix.pmf(Vec3(1.f, 0.f, 0.f), 1), 0.2f * base.pmf(Vec3(1.f, 0.f, 0.f), 1));
}

}  // namespace
}  // namespace rlpbrt
