#include "render/metrics.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/image_io.h"
#include "shared_data.h"

namespace rlpbrt {
namespace {

Image constantImage(int w, int h, float r, float g, float b, int channels = 3) {
    Image img;
    img.width = w;
    img.height = h;
    img.channels = channels;
    img.pixels.resize(size_t(w) * h * channels);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            img.at(x, y, 0) = r;
            img.at(x, y, 1) = g;
            img.at(x, y, 2) = b;
            if (channels == 4) img.at(x, y, 3) = 1.f;
        }
    }
    return img;
}

// Survival function of the chi-square distribution with 3 and 5 degrees of freedom.
double chi2Sf3(double q) {
    const double pi = 3.14159265358979323846;
    return std::erfc(std::sqrt(q / 2)) + std::sqrt(2 * q / pi) * std::exp(-q / 2);
}
double chi2Sf5(double q) {
    return chi2Sf3(q) + std::pow(q / 2, 1.5) * std::exp(-q / 2) / std::tgamma(2.5);
}

TEST(RelMse, ZeroAgainstItself) {
    Image a = constantImage(37, 29, 0.3f, 2.f, 0.f);
    a.at(5, 7, 1) = 100.f;
    EXPECT_EQ(relMseTrimmed(a, a), 0.0);
}

TEST(RelMse, HandComputedPerPixelValue) {
    // Per channel (x-r)^2/(r^2+0.01): (0.1^2/0.02, 0.1^2/0.01, 0) = (0.5, 1, 0); mean 0.5.
    Image ref = constantImage(10, 10, 0.1f, 0.f, 1.f);
    Image test = constantImage(10, 10, 0.2f, 0.1f, 1.f);
    EXPECT_NEAR(relMseTrimmed(test, ref), 0.5, 1e-6);
}

TEST(RelMse, DropsTheWorstTenthOfAPercent) {
    // 1000 pixels: floor(1000/1000) = 1 pixel dropped, the outlier; the rest all have
    // e = 0.1^2 / (1 + 0.01).
    Image ref = constantImage(40, 25, 1.f, 1.f, 1.f);
    Image test = constantImage(40, 25, 1.1f, 1.1f, 1.1f);
    test.at(13, 17, 0) = 100.f;
    const double e = std::pow(double(1.1f) - 1.0, 2) / 1.01;
    EXPECT_NEAR(relMseTrimmed(test, ref), e, 1e-9);
    // 999 pixels: none dropped, so the outlier counts.
    Image ref2 = constantImage(37, 27, 1.f, 1.f, 1.f);
    Image test2 = constantImage(37, 27, 1.1f, 1.1f, 1.1f);
    test2.at(3, 3, 0) = 100.f;
    const double outlier = (std::pow(100.0 - 1.0, 2) / 1.01 + 2 * e * 1.01 / 1.01) / 3;
    EXPECT_NEAR(relMseTrimmed(test2, ref2), (998 * e + outlier) / 999, 1e-9);
    // 2000 pixels, two outliers: both dropped.
    Image ref3 = constantImage(50, 40, 1.f, 1.f, 1.f);
    Image test3 = constantImage(50, 40, 1.1f, 1.1f, 1.1f);
    test3.at(0, 0, 2) = 50.f;
    test3.at(49, 39, 1) = -50.f;
    EXPECT_NEAR(relMseTrimmed(test3, ref3), e, 1e-9);
}

TEST(RelMse, GaussianNoiseMatchesTheory) {
    // x = r + N(0, s^2) per channel: e_p = s^2/(r^2+0.01) * Q/3 with Q ~ chi2(3). Dropping
    // the top 0.1% keeps Q < q (q = 0.999 quantile), so E[mean] = s^2/(r^2+0.01) *
    // (3 - 3 P(chi2(5) > q)) / (3 * 0.999)   [E[Q; Q > q] = 3 P(chi2(5) > q)].
    const int w = 500, h = 500;
    const float r = 0.5f, s = 0.05f;
    Image ref = constantImage(w, h, r, r, r);
    Image test = ref;
    std::mt19937_64 rng(12345);
    std::normal_distribution<double> noise(0.0, s);
    for (float& v : test.pixels) v = float(r + noise(rng));

    double lo = 0, hi = 100;  // bisection for the 0.999 quantile of chi2(3)
    for (int i = 0; i < 200; ++i) {
        double mid = 0.5 * (lo + hi);
        (chi2Sf3(mid) > 0.001 ? lo : hi) = mid;
    }
    const double q = lo;
    EXPECT_NEAR(q, 16.266, 1e-3);
    const double base = double(s) * s / (double(r) * r + 0.01);
    const double expected = base * (3 - 3 * chi2Sf5(q)) / (3 * 0.999);
    // Std of the mean of Q/3 over N pixels is sqrt(2/3)/sqrt(N) (slightly less after
    // trimming); allow 5 sigma.
    const double tol = 5 * base * std::sqrt(2.0 / 3.0) / std::sqrt(double(w) * h);
    EXPECT_NEAR(relMseTrimmed(test, ref), expected, tol);
}

TEST(RelMse, NonFiniteGivesNaN) {
    Image ref = constantImage(8, 8, 1.f, 1.f, 1.f);
    Image test = ref;
    test.at(2, 2, 2) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(std::isnan(relMseTrimmed(test, ref)));
}

TEST(RelMse, UsesRgbOfRgbaReference) {
    Image ref = constantImage(10, 10, 0.1f, 0.f, 1.f, 4);
    Image test = constantImage(10, 10, 0.2f, 0.1f, 1.f);
    EXPECT_NEAR(relMseTrimmed(test, ref), 0.5, 1e-6);
}

TEST(Metrics, MismatchedImagesThrow) {
    Image a = constantImage(10, 10, 1, 1, 1), b = constantImage(10, 11, 1, 1, 1);
    EXPECT_THROW(relMseTrimmed(a, b), std::invalid_argument);
    EXPECT_THROW(blockBias(a, b), std::invalid_argument);
    EXPECT_THROW(relMseTrimmed(a, Image{}), std::invalid_argument);
}

TEST(PairRelMse, ZeroForIdenticalRenders) {
    Image ref = constantImage(20, 20, 0.5f, 1.f, 2.f);
    Image a = constantImage(20, 20, 0.7f, 0.2f, 3.f);
    EXPECT_EQ(pairRelMse(a, a, ref), 0.0);
}

TEST(PairRelMse, HalfTheSquaredDifferenceWeightedByTheReference) {
    // Channel 0: (0.3 - 0.1)^2 / (0.1^2 + 0.01) = 2; channels 1, 2 equal: mean 2/3, half 1/3.
    // The reference's value enters only the weight (a and b are both away from it).
    Image ref = constantImage(10, 10, 0.1f, 5.f, 5.f);
    Image a = constantImage(10, 10, 0.3f, 1.f, 1.f);
    Image b = constantImage(10, 10, 0.1f, 1.f, 1.f);
    EXPECT_NEAR(pairRelMse(a, b, ref), 1.0 / 3.0, 1e-6);
    EXPECT_NEAR(pairRelMse(b, a, ref), 1.0 / 3.0, 1e-6);
}

TEST(PairRelMse, DropsTwoRendersWorthOfOutliers) {
    // 1000 pixels: relMseTrimmed drops 1, the pair 2. Two outliers (one per render) and
    // otherwise equal images: the pair's error is 0, one render's against the other is not.
    Image ref = constantImage(40, 25, 1.f, 1.f, 1.f);
    Image a = ref, b = ref;
    a.at(3, 4, 0) = 50.f;
    b.at(30, 20, 1) = 50.f;
    EXPECT_EQ(pairRelMse(a, b, ref), 0.0);
    EXPECT_GT(relMseTrimmed(a, b), 0.0);
    b.at(10, 10, 2) = 2.f;  // a third difference stays: (1^2 / 1.01) / 3 / 1000 / 2 per pixel
    EXPECT_NEAR(pairRelMse(a, b, ref), 1.0 / 1.01 / 3.0 / 998.0 / 2.0, 1e-9);
}

TEST(PairRelMse, RejectsMismatchedImages) {
    Image a = constantImage(10, 10, 1.f, 1.f, 1.f);
    Image small = constantImage(9, 10, 1.f, 1.f, 1.f);
    EXPECT_THROW(pairRelMse(a, small, a), std::invalid_argument);
    EXPECT_THROW(pairRelMse(a, a, small), std::invalid_argument);
}

// Two renders a, b = truth + independent uniform noise, and a reference = truth + its own
// noise: pairRelMse estimates the renders' error against the truth, and relMseTrimmed(a, ref)
// minus it the reference's own error, each within 5 standard errors of the per-pixel terms
// (plus what trimming the largest 0.1% / 0.2% of pixels can remove).
TEST(PairRelMse, SeparatesTheRendersNoiseFromTheReferences) {
    const int w = 200, h = 200;
    const float truth[3] = {1.f, 0.5f, 2.f};
    const float hr = 0.05f, hx = 0.3f;  // noise half-widths: reference, renders
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.f, 1.f);
    Image t = constantImage(w, h, truth[0], truth[1], truth[2]);
    Image ref = t, a = t, b = t;
    for (size_t i = 0; i < ref.pixels.size(); ++i) {
        ref.pixels[i] += hr * u(rng);
        a.pixels[i] += hx * u(rng);
        b.pixels[i] += hx * u(rng);
    }
    // Expectations given the reference: E[(a - b)^2] / 2 = hx^2 / 3 per channel, and
    // E[(a - r)^2] = hx^2 / 3 + (t - r)^2, so their difference is the reference's own error.
    const size_t n = size_t(w) * h;
    double expPair = 0, expRef = 0, sdPair = 0, sdA = 0, maxTerm = 0;
    std::vector<double> pairTerms(n), aTerms(n);
    for (size_t p = 0; p < n; ++p) {
        double ep = 0, er = 0, tp = 0, ta = 0;
        for (int c = 0; c < 3; ++c) {
            const double r = ref.pixels[p * 3 + c], wgt = 1.0 / (r * r + 0.01);
            ep += hx * hx / 3.0 * wgt;
            er += (truth[c] - r) * (truth[c] - r) * wgt;
            tp += 0.5 * (a.pixels[p * 3 + c] - b.pixels[p * 3 + c]) *
                  (a.pixels[p * 3 + c] - b.pixels[p * 3 + c]) * wgt;
            ta += (a.pixels[p * 3 + c] - r) * (a.pixels[p * 3 + c] - r) * wgt;
        }
        expPair += ep / 3;
        expRef += er / 3;
        pairTerms[p] = tp / 3;
        aTerms[p] = ta / 3;
        maxTerm = std::max({maxTerm, pairTerms[p], aTerms[p]});
    }
    expPair /= double(n);
    expRef /= double(n);
    auto sd = [&](const std::vector<double>& v) {
        double m = 0, q = 0;
        for (double x : v) m += x;
        m /= double(v.size());
        for (double x : v) q += (x - m) * (x - m);
        return std::sqrt(q / double(v.size() - 1));
    };
    sdPair = sd(pairTerms);
    sdA = sd(aTerms);
    const double trim = double(2 * (n / 1000)) / double(n - 2 * (n / 1000)) * maxTerm;
    const double pair = pairRelMse(a, b, ref);
    EXPECT_NEAR(pair, expPair, 5 * sdPair / std::sqrt(double(n)) + trim);
    // The reference's own error is a tenth of the renders': the estimate must find it, not 0
    // and not the renders' error.
    ASSERT_LT(expRef, 0.2 * expPair);
    const double refError = relMseTrimmed(a, ref) - pair;
    EXPECT_NEAR(refError, expRef, 5 * (sdPair + sdA) / std::sqrt(double(n)) + 2 * trim);
    EXPECT_GT(refError, 0.5 * expRef);
}

TEST(BlockBias, HandComputedMedian) {
    // 40x40: 2x2 full 16x16 blocks; the 8-pixel strips at the right and bottom are ignored.
    Image ref = constantImage(40, 40, 1.f, 2.f, 3.f);
    Image test = ref;
    const float factor[2][2] = {{1.1f, 1.2f}, {1.3f, 0.6f}};  // deviations .1 .2 .3 .4
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 40; ++x)
            for (int c = 0; c < 3; ++c) {
                if (x < 32 && y < 32)
                    test.at(x, y, c) *= factor[y / 16][x / 16];
                else
                    test.at(x, y, c) = 1e6f;  // edge pixels: must not matter
            }
    // Even count: mean of the middle two, (0.2 + 0.3) / 2.
    EXPECT_NEAR(blockBias(test, ref), 0.25, 1e-6);
    EXPECT_EQ(blockBias(ref, ref), 0.0);
}

TEST(BlockBias, DarkBlocksAreExcluded) {
    // 32x48: 2x3 blocks. Image mean M ~ 0.83; the top-left block's ref mean 0.01 < 0.05 M,
    // so its huge deviation is excluded.
    Image ref = constantImage(32, 48, 1.f, 1.f, 1.f);
    Image test = ref;
    const float factor[3][2] = {{1.f, 1.1f}, {0.8f, 1.3f}, {1.f, 1.f}};
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 32; ++x)
            for (int c = 0; c < 3; ++c) {
                if (x < 16 && y < 16) {
                    ref.at(x, y, c) = 0.01f;
                    test.at(x, y, c) = 5.f;
                } else {
                    test.at(x, y, c) *= factor[y / 16][x / 16];
                }
            }
    // Blocks: (0,0) excluded; .1, .2, .3, 0, 0 -> sorted 0 0 .1 .2 .3 -> median .1
    EXPECT_NEAR(blockBias(test, ref), 0.1, 1e-6);
    EXPECT_TRUE(std::isnan(blockBias(constantImage(8, 8, 1, 1, 1), constantImage(8, 8, 1, 1, 1))));
}

TEST(BlockBias, GaussianNoise) {
    // Block mean of 768 N(0, s^2) values has sigma_b = s / sqrt(768); |dev| = |N|/r has
    // median 0.6745 sigma_b / r. The sample median over 961 blocks has relative standard
    // error 1 / (2 * 0.6356 * sqrt(961) * 0.6745) ~ 3.8%; allow 5 sigma (19%).
    const float r = 0.5f, s = 0.05f;
    Image ref = constantImage(500, 500, r, r, r);
    Image test = ref;
    std::mt19937_64 rng(99);
    std::normal_distribution<double> noise(0.0, s);
    for (float& v : test.pixels) v = float(r + noise(rng));
    const double expected = 0.6745 * s / std::sqrt(768.0) / r;
    EXPECT_NEAR(blockBias(test, ref), expected, 0.19 * expected);
}

TEST(Metrics, HasNonFinite) {
    Image a = constantImage(4, 4, 1, 1, 1);
    EXPECT_FALSE(hasNonFinite(a));
    a.at(3, 3, 1) = std::numeric_limits<float>::infinity();
    EXPECT_TRUE(hasNonFinite(a));
    a.at(3, 3, 1) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(hasNonFinite(a));
    EXPECT_FALSE(hasNonFinite(Image{}));
}

TEST(Metrics, ManifestReferencesAgainstThemselves) {
    RLPBRT_REQUIRE_SHARED();
    const std::string dir = rlpbrt::test::sharedDir() + "/references/";
    std::ifstream manifest(dir + "manifest.tsv");
    ASSERT_TRUE(manifest) << "cannot read " << dir << "manifest.tsv";
    std::string line;
    std::getline(manifest, line);  // header
    int checked = 0;
    while (std::getline(manifest, line) && checked < 2) {
        std::istringstream row(line);
        std::string id, scene;
        int width, height;
        row >> id >> scene >> width >> height;
        Image ref;
        std::string err;
        ASSERT_TRUE(readImage(dir + id + ".exr", &ref, &err)) << err;
        EXPECT_EQ(ref.width, width) << id;
        EXPECT_EQ(ref.height, height) << id;
        EXPECT_FALSE(hasNonFinite(ref)) << id;
        EXPECT_EQ(relMseTrimmed(ref, ref), 0.0) << id;
        EXPECT_EQ(blockBias(ref, ref), 0.0) << id;
        ++checked;
    }
    EXPECT_EQ(checked, 2);
}

}  // namespace
}  // namespace rlpbrt
