// Tests of the guiding layer's directional building blocks: the equal-area hemisphere strata
// and the stratum CDFs.
#include "guiding/directional.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "render/chi2.h"
#include "test_scenes.h"

namespace rlpbrt::guiding {
namespace {

// Uniform directions on the sphere (normalised Gaussian vectors): independent of the
// cylindrical map under test.
using test::gaussianDirection;

TEST(StrataLayout, SampleLandsInItsStratumAndCentresInside) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    for (auto [cols, rows] : {std::pair{1, 1}, {3, 5}, {8, 8}, {64, 64}, {1, 64}, {64, 1}}) {
        StrataLayout layout(cols, rows);
        ASSERT_EQ(layout.count(), cols * rows);
        int mismatches = 0;
        for (int j = 0; j < layout.count(); ++j) {
            EXPECT_EQ(layout.stratumOf(layout.centre(j)), j) << cols << "x" << rows;
            EXPECT_NEAR(glm::length(layout.centre(j)), 1.f, 1e-5f);
            for (int k = 0; k < 8; ++k) {
                glm::vec3 w = layout.sampleStratum(j, glm::vec2(uni(rng), uni(rng)));
                EXPECT_NEAR(glm::length(w), 1.f, 1e-5f);
                EXPECT_GE(w.z, 0.f);
                // Float rounding may put a sample exactly on a stratum edge into its neighbour.
                if (layout.stratumOf(w) != j) ++mismatches;
            }
        }
        EXPECT_LE(mismatches, 2) << cols << "x" << rows;
    }
}

TEST(StrataLayout, IndexEdgesClamp) {
    StrataLayout layout(8, 8);
    EXPECT_EQ(layout.stratumOf(glm::vec3(0, 0, 1)), 7 * 8);            // cos = 1: last row
    EXPECT_EQ(layout.stratumOf(glm::vec3(0, 0, 1.0000001f)), 7 * 8);   // cos slightly > 1
    EXPECT_EQ(layout.stratumOf(glm::vec3(1, -1e-30f, 1e-3f)), 7);      // phi just below 2 pi
    EXPECT_EQ(layout.stratumOf(glm::vec3(1, 0, 1e-3f)), 0);            // phi = 0
    EXPECT_EQ(layout.stratumOf(glm::vec3(1, -0.f, 1e-3f)), 0);         // phi = -0
    EXPECT_EQ(layout.stratumOf(glm::vec3(1, 0, 0)), -1);               // horizon
    EXPECT_EQ(layout.stratumOf(glm::vec3(0, 0, -1)), -1);              // below
    EXPECT_EQ(layout.stratumOf(glm::vec3(NAN, 0, 0.5f)), -1);              // NaN phi
    EXPECT_EQ(layout.stratumOf(glm::vec3(0, 0, NAN)), -1);
    StrataLayout one(1, 1);
    EXPECT_EQ(one.stratumOf(glm::vec3(0, 0, 1)), 0);
    EXPECT_EQ(one.stratumOf(glm::vec3(-1, -1e-30f, 1e-6f)), 0);
}

TEST(StrataLayout, OctantColumnsMatchTheAzimuth) {
    // Column counts dividing 16 take the column from comparisons (branch-free octants and
    // their halves); it must be the azimuth's column for every direction off the edges.
    std::mt19937_64 rng(5);
    for (int cols : {1, 2, 4, 8, 16}) {
        StrataLayout layout(cols, 3);
        int checked = 0;
        for (int i = 0; i < 20000; ++i) {
            glm::vec3 w = gaussianDirection(rng);
            w.z = std::abs(w.z);
            const int j = layout.stratumOf(w);
            ASSERT_GE(j, 0);
            const double phi = std::atan2(double(w.y), double(w.x));
            const double turns = (phi < 0.0 ? phi + 2.0 * PiDouble : phi) / (2.0 * PiDouble) * cols;
            if (std::abs(turns - std::round(turns)) < 1e-5) continue;  // on an edge
            ASSERT_EQ(j % cols, int(turns)) << cols << " cols, w = " << w.x << " " << w.y;
            ++checked;
        }
        EXPECT_GT(checked, 19900);
    }
    // Directions on octant edges (measure zero) are pinned: saved guides keep their strata.
    StrataLayout layout(8, 1);
    EXPECT_EQ(layout.stratumOf(glm::vec3(1, 1, 1)), 1);
    EXPECT_EQ(layout.stratumOf(glm::vec3(0, 1, 1)), 1);
    EXPECT_EQ(layout.stratumOf(glm::vec3(-1, 1, 1)), 3);
    EXPECT_EQ(layout.stratumOf(glm::vec3(-1, 0, 1)), 3);
    EXPECT_EQ(layout.stratumOf(glm::vec3(-1, -1, 1)), 5);
    EXPECT_EQ(layout.stratumOf(glm::vec3(0, -1, 1)), 6);
    EXPECT_EQ(layout.stratumOf(glm::vec3(1, -1, 1)), 7);
    EXPECT_EQ(layout.stratumOf(glm::vec3(0, 0, 1)), 0);
}

TEST(StrataLayout, StrataHaveEqualSolidAngle) {
    // Uniform sphere directions (Gaussian construction) must fill the 8x6 strata equally.
    StrataLayout layout(8, 6);
    std::mt19937_64 rng(11);
    const int n = 200000;
    std::vector<double> observed(size_t(layout.count()) + 1, 0.0);
    for (int i = 0; i < n; ++i) {
        int j = layout.stratumOf(gaussianDirection(rng));
        observed[j < 0 ? size_t(layout.count()) : size_t(j)] += 1.0;
    }
    std::vector<double> expected(observed.size(), 0.5 * n / layout.count());
    expected.back() = 0.5 * n;  // lower hemisphere
    chi2::Result r = chi2::testCounts(observed, expected);
    EXPECT_TRUE(r.passed) << r.message;
}

// cosineSamplingVariance: 0 for an even light (and where there is none), for one lit stratum
// k sum cos / cos_k - 1 (the estimate is q_k sum cos with probability cos_k / sum cos); a
// Monte Carlo run of that estimator agrees for a random light.
TEST(CosineSamplingVariance, EvenOneHotAndMonteCarlo) {
    const StrataLayout layout(8, 8);
    const int n = layout.count();
    std::vector<double> q(size_t(n), 2.5);
    EXPECT_NEAR(cosineSamplingVariance(q.data(), layout), 0.0, 1e-12);
    std::fill(q.begin(), q.end(), 0.0);
    EXPECT_EQ(cosineSamplingVariance(q.data(), layout), 0.0);
    double cs = 0.0;
    for (int j = 0; j < n; ++j) cs += layout.centre(j).z;
    q[17] = 3.0;
    EXPECT_NEAR(cosineSamplingVariance(q.data(), layout), cs / layout.centre(17).z - 1.0, 1e-9);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    for (double& v : q) v = uni(rng) * uni(rng) * 10.0;
    std::vector<double> cdf(size_t(n) + 1, 0.0);
    double mean = 0.0;
    for (int j = 0; j < n; ++j) {
        cdf[size_t(j) + 1] = cdf[size_t(j)] + layout.centre(j).z / cs;
        mean += q[size_t(j)] * layout.centre(j).z;
    }
    // The estimate's second moment, and 5 standard errors of it, from the samples.
    double m2 = 0.0, m4 = 0.0;
    const int samples = 1000000;
    for (int i = 0; i < samples; ++i) {
        const double u = uni(rng) * cdf[size_t(n)];
        const auto it = std::upper_bound(cdf.begin(), cdf.end(), u);
        const int j = std::min(int(it - cdf.begin()) - 1, n - 1);
        const double est = q[size_t(j)] * cs;  // q_j cos_j / (cos_j / cs)
        m2 += est * est;
        m4 += est * est * est * est;
    }
    m2 /= samples;
    m4 /= samples;
    const double se = std::sqrt((m4 - m2 * m2) / samples) / (mean * mean);
    EXPECT_NEAR(cosineSamplingVariance(q.data(), layout), m2 / (mean * mean) - 1.0, 5.0 * se);
}

TEST(StrataCdf, UniformForZeroOrNonFiniteSums) {
    std::vector<double> q(5, 0.0);
    std::vector<float> cdf(6);
    buildStrataCdf(q.data(), 5, 0.1, cdf.data());
    for (int j = 0; j < 5; ++j) EXPECT_FLOAT_EQ(strataProbability(cdf.data(), j), 0.2f);
    q.assign(5, 1e308);  // the sum overflows to Inf
    buildStrataCdf(q.data(), 5, 0.1, cdf.data());
    for (int j = 0; j < 5; ++j) EXPECT_FLOAT_EQ(strataProbability(cdf.data(), j), 0.2f);
    EXPECT_EQ(cdf[0], 0.f);
    EXPECT_EQ(cdf[5], 1.f);
}

TEST(StrataCdf, EpsilonFloorAndProportionality) {
    std::vector<double> q = {0.0, 1.0, 3.0, 0.0};
    std::vector<float> cdf(5);
    buildStrataCdf(q.data(), 4, 0.2, cdf.data());
    EXPECT_NEAR(strataProbability(cdf.data(), 0), 0.05f, 1e-7f);
    EXPECT_NEAR(strataProbability(cdf.data(), 1), 0.8f * 0.25f + 0.05f, 1e-7f);
    EXPECT_NEAR(strataProbability(cdf.data(), 2), 0.8f * 0.75f + 0.05f, 1e-7f);
    EXPECT_NEAR(strataProbability(cdf.data(), 3), 0.05f, 1e-7f);
    EXPECT_EQ(cdf[4], 1.f);
}

TEST(StrataCdf, NeverSelectsZeroProbabilityStratum) {
    std::vector<double> q = {0.0, 2.0, 0.0, 0.0, 1.0, 0.0};
    std::vector<float> cdf(7);
    buildStrataCdf(q.data(), 6, 0.0, cdf.data());
    for (float u : {0.f, 1e-9f, 0.3f, 2.f / 3.f, 0.99999994f, 1.f, 2.f}) {
        int j = sampleStrataCdf(cdf.data(), 6, u);
        EXPECT_TRUE(j == 1 || j == 4) << "u = " << u << " gave " << j;
    }
    EXPECT_EQ(sampleStrataCdf(cdf.data(), 6, 0.f), 1);
    EXPECT_EQ(sampleStrataCdf(cdf.data(), 6, 0.99999994f), 4);
}

TEST(StrataCdf, SampleFrequenciesMatchProbabilities) {
    std::vector<double> q = {1.0, 5.0, 0.5, 2.0, 0.0, 8.0, 1.0, 0.25};
    std::vector<float> cdf(9);
    buildStrataCdf(q.data(), 8, 0.1, cdf.data());
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    const int n = 100000;
    std::vector<double> observed(8, 0.0), expected(8);
    for (int i = 0; i < n; ++i) observed[size_t(sampleStrataCdf(cdf.data(), 8, uni(rng)))] += 1;
    for (int j = 0; j < 8; ++j) expected[size_t(j)] = n * double(strataProbability(cdf.data(), j));
    chi2::Result r = chi2::testCounts(observed, expected);
    EXPECT_TRUE(r.passed) << r.message;
}

// 4 columns x 3 rows, row-major, with a zero stratum and a zero row (the middle one).
std::vector<float> grid2dCdf() {
    const std::vector<double> q = {1.0, 5.0, 0.0, 2.0,  0.0, 0.0, 0.0, 0.0,  8.0, 0.5, 1.0, 3.0};
    std::vector<float> cdf(13);
    buildStrataCdf(q.data(), 12, 0.0, cdf.data());
    return cdf;
}

TEST(StrataCdf2D, StrataAndPositionsFollowTheProbabilities) {
    const std::vector<float> cdf = grid2dCdf();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    const int n = 200000;
    // Counts per stratum, and per (stratum, quarter of cell.x), (stratum, quarter of cell.y):
    // uniform positions put a quarter of a stratum's samples in each.
    std::vector<double> observed(12, 0.0), expected(12), ox(48, 0.0), oy(48, 0.0), e4(48);
    for (int i = 0; i < n; ++i) {
        glm::vec2 cell;
        const int j = sampleStrataCdf2D(cdf.data(), 4, 3, glm::vec2(uni(rng), uni(rng)), &cell);
        ASSERT_TRUE(j >= 0 && j < 12);
        ASSERT_TRUE(cell.x >= 0.f && cell.x < 1.f && cell.y >= 0.f && cell.y < 1.f);
        observed[size_t(j)] += 1;
        ox[size_t(j * 4 + int(cell.x * 4.f))] += 1;
        oy[size_t(j * 4 + int(cell.y * 4.f))] += 1;
    }
    for (int j = 0; j < 12; ++j) {
        expected[size_t(j)] = n * double(strataProbability(cdf.data(), j));
        for (int k = 0; k < 4; ++k) e4[size_t(j * 4 + k)] = expected[size_t(j)] / 4.0;
    }
    for (int j : {2, 4, 5, 6, 7}) EXPECT_EQ(observed[size_t(j)], 0.0) << j;
    for (const auto& [obs, exp] : {std::pair(&observed, &expected), std::pair(&ox, &e4),
                                   std::pair(&oy, &e4)}) {
        chi2::Result r = chi2::testCounts(*obs, *exp);
        EXPECT_TRUE(r.passed) << r.message;
    }
}

TEST(StrataCdf2D, NeverSelectsZeroProbabilityStrataAtTheEdges) {
    const std::vector<float> cdf = grid2dCdf();
    for (float ux : {0.f, 1e-9f, 0.5f, 0.99999994f, 1.f})
        for (float uy : {0.f, 1e-9f, 0.5f, 0.99999994f, 1.f}) {
            glm::vec2 cell;
            const int j = sampleStrataCdf2D(cdf.data(), 4, 3, glm::vec2(ux, uy), &cell);
            EXPECT_GT(strataProbability(cdf.data(), j), 0.f) << ux << " " << uy;
            EXPECT_TRUE(cell.x >= 0.f && cell.x < 1.f && cell.y >= 0.f && cell.y < 1.f);
        }
}

// The property it is for: inside a row the map is linear in u.x (the row's marginal) and, for
// a given u.x, monotone in u.y, so neighbouring u stay neighbouring directions.
TEST(StrataCdf2D, ContinuousAndMonotoneInsideARow) {
    const std::vector<float> cdf = grid2dCdf();
    const float r0 = cdf[8], pr = cdf[12] - cdf[8];  // the last row
    glm::vec2 a, b;
    const int ja = sampleStrataCdf2D(cdf.data(), 4, 3, glm::vec2(r0 + 0.2f * pr, 0.3f), &a);
    const int jb = sampleStrataCdf2D(cdf.data(), 4, 3, glm::vec2(r0 + 0.7f * pr, 0.3f), &b);
    EXPECT_EQ(ja, jb);
    EXPECT_NEAR(a.x, 0.2f, 1e-5f);
    EXPECT_NEAR(b.x, 0.7f, 1e-5f);
    EXPECT_EQ(a.y, b.y);  // the column's position depends on u.y only
    int lastKey = -1;
    for (int i = 0; i < 1000; ++i) {
        glm::vec2 c;
        const int j = sampleStrataCdf2D(cdf.data(), 4, 3, glm::vec2(r0 + 0.5f * pr, i / 1000.f), &c);
        ASSERT_EQ(j / 4, 2);
        const int key = j * 1000000 + int(c.y * 999999.f);
        EXPECT_GE(key, lastKey) << i;
        lastKey = key;
    }
}

TEST(Frame, OrthonormalAndInverse) {
    std::mt19937_64 rng(5);
    for (int i = 0; i < 1000; ++i) {
        glm::vec3 n = gaussianDirection(rng);
        if (i == 0) n = glm::vec3(0, 0, -1);
        if (i == 1) n = glm::vec3(0, 0, 1);
        Frame f = Frame::fromZ(n);
        EXPECT_NEAR(glm::dot(f.s, f.t), 0.f, 1e-5f);
        EXPECT_NEAR(glm::dot(f.s, f.n), 0.f, 1e-5f);
        EXPECT_NEAR(glm::dot(f.t, f.n), 0.f, 1e-5f);
        EXPECT_NEAR(glm::length(f.s), 1.f, 1e-5f);
        glm::vec3 v = gaussianDirection(rng);
        glm::vec3 back = f.toWorld(f.toLocal(v));
        EXPECT_NEAR(glm::length(back - v), 0.f, 1e-5f);
        EXPECT_NEAR(f.toLocal(n).z, 1.f, 1e-5f);
    }
}

}  // namespace
}  // namespace rlpbrt::guiding
