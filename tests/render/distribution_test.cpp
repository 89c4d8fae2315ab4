#include "render/distribution.h"

#include <random>

#include <gtest/gtest.h>

#include "chi2.h"

namespace rlpbrt {
namespace {

constexpr int kChi2Family = 8;  // chi-square tests in this file (Sidak correction)

float uniformFloat(std::mt19937_64& rng) { return float(rng() >> 40) * 0x1p-24f; }

TEST(Distribution1D, IntegralCountAndPmf) {
    std::vector<float> f = {0.f, 1.f, 3.f, 0.f, 0.5f, 2.f, 0.f};
    Distribution1D d(f);
    EXPECT_EQ(d.count(), 7);
    EXPECT_NEAR(d.integral(), 6.5f / 7.f, 1e-6f);
    float sum = 0.f;
    for (int i = 0; i < d.count(); ++i) {
        EXPECT_NEAR(d.discretePmf(i), f[i] / 6.5f, 1e-6f);
        sum += d.discretePmf(i);
    }
    EXPECT_NEAR(sum, 1.f, 1e-6f);
}

TEST(Distribution1D, NegativeAndNonFiniteValuesAreZero) {
    std::vector<float> f = {-1.f, 2.f, std::numeric_limits<float>::quiet_NaN(), Infinity, 2.f};
    Distribution1D d(f);
    EXPECT_NEAR(d.integral(), 4.f / 5.f, 1e-6f);
    EXPECT_EQ(d.discretePmf(0), 0.f);
    EXPECT_EQ(d.discretePmf(2), 0.f);
    EXPECT_EQ(d.discretePmf(3), 0.f);
    EXPECT_NEAR(d.discretePmf(1), 0.5f, 1e-6f);
}

TEST(Distribution1D, ContinuousSamplesMatchFunction) {
    std::vector<float> f = {0.f, 1.f, 3.f, 0.f, 0.5f, 2.f, 0.f};
    Distribution1D d(f);
    // Histogram with 4 sub-bins per piece: the density must be constant inside each piece.
    const int sub = 4, nBins = 7 * sub;
    const long long n = 200000;
    std::vector<double> observed(nBins, 0.0), expected(nBins, 0.0);
    std::mt19937_64 rng(7);
    for (long long i = 0; i < n; ++i) {
        float pdf = -1.f;
        int offset = -1;
        float x = d.sampleContinuous(uniformFloat(rng), &pdf, &offset);
        ASSERT_GE(x, 0.f);
        ASSERT_LT(x, 1.f);
        ASSERT_EQ(offset, std::min(int(x * 7), 6));
        ASSERT_GT(f[offset], 0.f) << "sampled a zero piece";
        ASSERT_NEAR(pdf, d.pdf(x), 1e-5f);
        observed[std::min(int(x * nBins), nBins - 1)] += 1.0;
    }
    for (int b = 0; b < nBins; ++b) expected[b] = n * f[b / sub] / 6.5 / sub;
    chi2::Result r = chi2::testCounts(observed, expected, 0.01, kChi2Family);
    EXPECT_TRUE(r.passed) << r.message;
}

TEST(Distribution1D, DiscreteSamplesMatchFunction) {
    std::vector<float> f = {5.f, 0.f, 1.f, 1.f, 0.25f};
    Distribution1D d(f);
    const long long n = 100000;
    std::vector<double> observed(f.size(), 0.0), expected(f.size(), 0.0);
    // The remapped u must stay uniform: histogram it in 10 bins.
    std::vector<double> remapObs(10, 0.0), remapExp(10, n / 10.0);
    std::mt19937_64 rng(11);
    for (long long i = 0; i < n; ++i) {
        float pmf = 0.f, ur = -1.f;
        int k = d.sampleDiscrete(uniformFloat(rng), &pmf, &ur);
        ASSERT_GT(f[k], 0.f);
        ASSERT_NEAR(pmf, d.discretePmf(k), 1e-7f);
        ASSERT_GE(ur, 0.f);
        ASSERT_LT(ur, 1.f);
        observed[k] += 1.0;
        remapObs[std::min(int(ur * 10), 9)] += 1.0;
    }
    for (size_t k = 0; k < f.size(); ++k) expected[k] = n * f[k] / 7.25;
    chi2::Result r = chi2::testCounts(observed, expected, 0.01, kChi2Family);
    EXPECT_TRUE(r.passed) << r.message;
    chi2::Result r2 = chi2::testCounts(remapObs, remapExp, 0.01, kChi2Family);
    EXPECT_TRUE(r2.passed) << r2.message;
}

TEST(Distribution1D, PdfIntegratesToOne) {
    std::vector<float> f = {0.f, 1.f, 3.f, 0.f, 0.5f, 2.f, 0.f};
    Distribution1D d(f);
    // Midpoint rule on a grid aligned with the pieces is exact for a piecewise constant pdf.
    const int m = 7 * 100;
    double sum = 0.0;
    for (int i = 0; i < m; ++i) sum += d.pdf((i + 0.5f) / m) / m;
    EXPECT_NEAR(sum, 1.0, 1e-5);
    EXPECT_EQ(d.pdf(-0.1f), 0.f);
    EXPECT_EQ(d.pdf(1.1f), 0.f);
}

TEST(Distribution1D, EdgeSampleValuesSkipZeroPieces) {
    std::vector<float> f = {0.f, 0.f, 2.f, 1.f, 0.f, 0.f};
    Distribution1D d(f);
    float pdf;
    int offset;
    float x = d.sampleContinuous(0.f, &pdf, &offset);
    EXPECT_EQ(offset, 2);
    EXPECT_GT(pdf, 0.f);
    EXPECT_GE(x, 2.f / 6.f);
    x = d.sampleContinuous(OneMinusEpsilon, &pdf, &offset);
    EXPECT_EQ(offset, 3);
    EXPECT_GT(pdf, 0.f);
    EXPECT_LT(x, 1.f);
    EXPECT_LE(x, 4.f / 6.f);
    EXPECT_EQ(d.sampleDiscrete(OneMinusEpsilon), 3);
    EXPECT_EQ(d.sampleDiscrete(0.f), 2);
}

TEST(Distribution1D, AllZeroFallsBackToUniform) {
    std::vector<float> f(5, 0.f);
    Distribution1D d(f);
    EXPECT_EQ(d.integral(), 0.f);
    for (int i = 0; i < 5; ++i) EXPECT_NEAR(d.discretePmf(i), 0.2f, 1e-7f);
    float pdf;
    int offset;
    float x = d.sampleContinuous(0.5f, &pdf, &offset);
    EXPECT_NEAR(x, 0.5f, 1e-6f);
    EXPECT_EQ(offset, 2);
    EXPECT_EQ(pdf, 1.f);
    EXPECT_EQ(d.pdf(0.9f), 1.f);
    x = d.sampleContinuous(OneMinusEpsilon, &pdf, &offset);
    EXPECT_LT(x, 1.f);
    EXPECT_EQ(offset, 4);
}

TEST(Distribution1D, SinglePiece) {
    float v = 3.f;
    Distribution1D d(&v, 1);
    float pdf;
    EXPECT_NEAR(d.sampleContinuous(0.25f, &pdf), 0.25f, 1e-6f);
    EXPECT_EQ(pdf, 1.f);
    EXPECT_EQ(d.sampleDiscrete(0.7f), 0);
}

// Large tables search from a bucket table: the piece found must be the one the definition
// names (the largest i with cdf[i] <= u, at most n - 1) for every u, on tables made to
// trouble the buckets: a spike holding most of the mass, runs of zero pieces (equal CDF
// values), pieces far below a bucket's width, an all-zero table; u at random, at the CDF's
// own values and their neighbours, at the bucket edges k/n, and at 0 and just below 1.
TEST(Distribution1D, LargeTablesFindThePieceTheCdfNames) {
    std::mt19937_64 rng(17);
    std::vector<std::vector<float>> tables;
    for (int n : {64, 65, 100, 1000, 4097}) {
        const size_t count = size_t(n);
        std::vector<float> smooth(count), spike(count, 1e-6f), runs(count), steep(count);
        for (int i = 0; i < n; ++i) {
            smooth[size_t(i)] = 1.f + 0.5f * std::sin(0.1f * float(i));
            runs[size_t(i)] = (i / 7) % 3 == 0 ? 0.f : uniformFloat(rng);
            steep[size_t(i)] = std::exp(-0.05f * float(i));
        }
        spike[size_t(n / 3)] = 1e6f;
        spike[size_t(n / 3) + 1] = 3e5f;
        tables.push_back(smooth);
        tables.push_back(spike);
        tables.push_back(runs);
        tables.push_back(steep);
        tables.push_back(std::vector<float>(count, 0.f));
    }
    for (const std::vector<float>& f : tables) {
        const Distribution1D d(f);
        const std::vector<float>& cdf = d.cdf();
        const int n = d.count();
        ASSERT_EQ(cdf.size(), size_t(n) + 1);
        auto expected = [&](float u) {
            int i = 0;
            for (int j = 0; j <= n; ++j)
                if (cdf[size_t(j)] <= u) i = j;
            return std::min(i, n - 1);
        };
        std::vector<float> us = {0.f, OneMinusEpsilon};
        for (int k = 0; k < 2000; ++k) us.push_back(uniformFloat(rng));
        for (float c : cdf) {
            us.push_back(c);
            us.push_back(std::nextafter(c, 0.f));
            us.push_back(std::nextafter(c, 1.f));
        }
        for (int k = 0; k <= n; ++k) {
            const float edge = float(k) / float(n);
            us.push_back(edge);
            us.push_back(std::nextafter(edge, 0.f));
            us.push_back(std::nextafter(edge, 1.f));
        }
        for (float u : us) {
            if (!(u >= 0.f && u < 1.f)) continue;
            float pmf = 0.f;
            ASSERT_EQ(d.sampleDiscrete(u, &pmf), expected(u)) << "n " << n << " u " << u;
            int offset = -1;
            d.sampleContinuous(u, nullptr, &offset);
            ASSERT_EQ(offset, expected(u));
        }
    }
}

// 6 x 4 grid with a zero row and zero cells.
std::vector<float> gridFunction() {
    return {1.f, 2.f, 0.f, 4.f, 1.f, 1.f,   //
            0.f, 0.f, 0.f, 0.f, 0.f, 0.f,   //
            3.f, 0.5f, 1.f, 0.f, 2.f, 6.f,  //
            1.f, 1.f, 1.f, 1.f, 1.f, 0.1f};
}

TEST(Distribution2D, SamplesMatchFunction) {
    const int nu = 6, nv = 4;
    std::vector<float> f = gridFunction();
    Distribution2D d(f.data(), nu, nv);
    double total = 0.0;
    for (float v : f) total += v;
    EXPECT_NEAR(d.integral(), total / (nu * nv), 1e-5);
    const long long n = 200000;
    std::vector<double> observed(nu * nv, 0.0), expected(nu * nv, 0.0);
    std::mt19937_64 rng(3);
    for (long long i = 0; i < n; ++i) {
        float pdf = 0.f;
        Vec2 p = d.sampleContinuous(Vec2(uniformFloat(rng), uniformFloat(rng)), &pdf);
        ASSERT_GE(p.x, 0.f);
        ASSERT_LT(p.x, 1.f);
        ASSERT_GE(p.y, 0.f);
        ASSERT_LT(p.y, 1.f);
        ASSERT_NEAR(pdf, d.pdf(p), 1e-4f * pdf);
        int iu = std::min(int(p.x * nu), nu - 1), iv = std::min(int(p.y * nv), nv - 1);
        ASSERT_GT(f[iv * nu + iu], 0.f);
        observed[iv * nu + iu] += 1.0;
    }
    for (int c = 0; c < nu * nv; ++c) expected[c] = n * f[c] / total;
    chi2::Result r = chi2::testCounts(observed, expected, 0.01, kChi2Family);
    EXPECT_TRUE(r.passed) << r.message;
}

TEST(Distribution2D, PdfIntegratesToOne) {
    const int nu = 6, nv = 4;
    std::vector<float> f = gridFunction();
    Distribution2D d(f.data(), nu, nv);
    const int m = 12;  // sub-cells per cell side
    double sum = 0.0;
    for (int j = 0; j < nv * m; ++j)
        for (int i = 0; i < nu * m; ++i)
            sum += d.pdf(Vec2((i + 0.5f) / (nu * m), (j + 0.5f) / (nv * m)));
    EXPECT_NEAR(sum / (nu * m * nv * m), 1.0, 1e-5);
}

TEST(Distribution2D, AllZeroFallsBackToUniform) {
    std::vector<float> f(3 * 5, 0.f);
    Distribution2D d(f.data(), 3, 5);
    EXPECT_EQ(d.integral(), 0.f);
    float pdf = 0.f;
    Vec2 p = d.sampleContinuous(Vec2(OneMinusEpsilon, OneMinusEpsilon), &pdf);
    EXPECT_EQ(pdf, 1.f);
    EXPECT_LT(p.x, 1.f);
    EXPECT_LT(p.y, 1.f);
    EXPECT_EQ(d.pdf(Vec2(0.3f, 0.6f)), 1.f);
}

}  // namespace
}  // namespace rlpbrt
