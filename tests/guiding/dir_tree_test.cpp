// Tests of the adaptive directional quadtree (guiding/dir_tree.h): refinement where the mass
// is, the density's integral, sampling against the density (chi-square), the sources that
// carry data into a refined tree, and the equal-area maps.
#include "guiding/dir_tree.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "render/chi2.h"
#include "test_scenes.h"

namespace rlpbrt::guiding {
namespace {

// A peaked density on the square: a narrow Gaussian at (0.3, 0.7) over a uniform floor.
float peaked(glm::vec2 a) {
    const glm::vec2 d = a - glm::vec2(0.3f, 0.7f);
    return 0.05f + 50.f * std::exp(-glm::dot(d, d) / (2.f * 0.01f * 0.01f));
}

// Leaf masses of f: f at the leaf's centre times its area (inner entries 0).
std::vector<float> massesOf(const DirTree& t, float (*f)(glm::vec2)) {
    std::vector<float> m(t.size(), 0.f);
    for (uint32_t i = 0; i < t.size(); ++i) {
        if (!t.node(i).leaf()) continue;
        glm::vec2 o;
        float e;
        t.square(i, &o, &e);
        m[i] = f(o + 0.5f * e) * e * e;
    }
    return m;
}

// A tree refined to f over a few rounds, as a field refines between passes.
DirTree treeFor(float (*f)(glm::vec2), double share, int depth, int rounds = 8) {
    DirTree t;
    for (int r = 0; r < rounds; ++r) {
        t.setLeafMasses(massesOf(t, f));
        t = t.refined(share, depth);
    }
    t.setLeafMasses(massesOf(t, f));
    return t;
}

TEST(DirTree, StartsUniform) {
    DirTree t;
    EXPECT_EQ(t.size(), 1u);
    EXPECT_EQ(t.leaves(), 1u);
    float d = 0.f;
    const glm::vec2 a = t.sample(glm::vec2(0.25f, 0.75f), &d);
    EXPECT_FLOAT_EQ(d, 1.f);
    EXPECT_FLOAT_EQ(a.x, 0.25f);
    EXPECT_FLOAT_EQ(a.y, 0.75f);
    EXPECT_FLOAT_EQ(t.density(glm::vec2(0.9f, 0.1f)), 1.f);
}

TEST(DirTree, RefinesWhereTheMassIsAndStaysSmall) {
    const double share = 0.01;
    const int depth = 10;
    const DirTree t = treeFor(peaked, share, depth);
    int peakDepth = 0, floorDepth = 0;
    t.leafOf(glm::vec2(0.3f, 0.7f), &peakDepth);
    t.leafOf(glm::vec2(0.9f, 0.1f), &floorDepth);
    // The peak's sigma is 1/100 of the square; a leaf of the floor holds about 0.6 / 4^depth
    // of the mass (the floor is 0.05 of 0.081), so it stops splitting at depth 3 or 4.
    EXPECT_GE(peakDepth, 7);
    EXPECT_LE(floorDepth, 4);
    // At most 1 / share nodes per level hold more than share of the mass.
    EXPECT_LE(t.leaves(), size_t(1 + 3 * depth / share));
    // The density follows the peak: far higher there than on the floor.
    EXPECT_GT(t.density(glm::vec2(0.3f, 0.7f)), 100.f * t.density(glm::vec2(0.9f, 0.1f)));
}

TEST(DirTree, DensityIntegratesToOne) {
    const DirTree t = treeFor(peaked, 0.01, 12);
    double integral = 0.0;
    for (uint32_t i = 0; i < t.size(); ++i) {
        if (!t.node(i).leaf()) continue;
        glm::vec2 o;
        float e;
        t.square(i, &o, &e);
        uint32_t leaf = 0;
        const float d = t.density(o + 0.5f * e, &leaf);
        EXPECT_EQ(leaf, i);
        EXPECT_NEAR(d * e * e, t.node(i).mass / t.totalMass(), 1e-6);
        integral += double(d) * e * e;
    }
    EXPECT_NEAR(integral, 1.0, 1e-5);
}

// Sampling against the density: with leaves no deeper than 6 every leaf is a union of the
// 64 x 64 cells, so a cell's expected count is its centre's density times its area.
TEST(DirTree, SamplesFollowTheDensity) {
    const DirTree t = treeFor(peaked, 0.005, 6);
    ASSERT_GT(t.leaves(), 100u);
    constexpr int kGrid = 64;
    constexpr int kSamples = 400000;
    std::vector<double> observed(kGrid * kGrid, 0.0), expected(kGrid * kGrid, 0.0);
    for (int y = 0; y < kGrid; ++y)
        for (int x = 0; x < kGrid; ++x)
            expected[size_t(y * kGrid + x)] =
                kSamples * double(t.density(glm::vec2((x + 0.5f) / kGrid, (y + 0.5f) / kGrid))) /
                (kGrid * kGrid);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    int mismatches = 0;
    for (int n = 0; n < kSamples; ++n) {
        float d = 0.f;
        uint32_t leaf = 0;
        const glm::vec2 a = t.sample(glm::vec2(uni(rng), uni(rng)), &d, &leaf);
        ASSERT_TRUE(a.x >= 0.f && a.x < 1.f && a.y >= 0.f && a.y < 1.f);
        uint32_t at = 0;
        const float da = t.density(a, &at);
        if (at != leaf || std::abs(da - d) > 1e-4f * da) ++mismatches;
        const int x = std::min(int(a.x * kGrid), kGrid - 1);
        const int y = std::min(int(a.y * kGrid), kGrid - 1);
        observed[size_t(y * kGrid + x)] += 1.0;
    }
    EXPECT_EQ(mismatches, 0);
    const chi2::Result r = chi2::testCounts(observed, expected);
    EXPECT_TRUE(r.passed) << r.message;
}

TEST(DirTree, NeverSamplesALeafWithoutMass) {
    DirTree t = treeFor(peaked, 0.01, 8);
    std::vector<float> m = massesOf(t, peaked);
    // Empty every leaf in the right half.
    for (uint32_t i = 0; i < t.size(); ++i) {
        glm::vec2 o;
        float e;
        t.square(i, &o, &e);
        if (t.node(i).leaf() && o.x >= 0.5f) m[i] = 0.f;
    }
    t.setLeafMasses(m);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    for (int n = 0; n < 100000; ++n) {
        float d = 0.f;
        const glm::vec2 a = t.sample(glm::vec2(uni(rng), uni(rng)), &d);
        ASSERT_LT(a.x, 0.5f);
        ASSERT_GT(d, 0.f);
    }
    EXPECT_EQ(t.density(glm::vec2(0.75f, 0.5f)), 0.f);
}

TEST(DirTree, RefinedSourcesCarryTheMass) {
    DirTree t = treeFor(peaked, 0.01, 10);
    // Move the peak: the old fine leaves merge, the new place splits.
    auto moved = [](glm::vec2 a) { return peaked(glm::vec2(1.f) - a); };
    std::vector<float> m(t.size(), 0.f);
    for (uint32_t i = 0; i < t.size(); ++i) {
        glm::vec2 o;
        float e;
        t.square(i, &o, &e);
        if (t.node(i).leaf()) m[i] = moved(o + 0.5f * e) * e * e;
    }
    t.setLeafMasses(m);
    std::vector<DirTree::Source> sources;
    const DirTree r = t.refined(0.01, 10, &sources);
    ASSERT_EQ(sources.size(), r.size());
    EXPECT_NEAR(r.totalMass(), t.totalMass(), 1e-4 * t.totalMass());
    int merged = 0, split = 0;
    double sum = 0.0;
    for (uint32_t i = 0; i < r.size(); ++i) {
        const DirTree::Source s = sources[i];
        EXPECT_NEAR(r.node(i).mass, t.node(s.from).mass * s.fraction, 1e-5 * t.totalMass());
        glm::vec2 o, so;
        float e, se;
        r.square(i, &o, &e);
        t.square(s.from, &so, &se);
        // The new node lies inside its source and covers `fraction` of it.
        EXPECT_NEAR(e * e, se * se * s.fraction, 1e-7f);
        EXPECT_TRUE(o.x >= so.x && o.y >= so.y && o.x + e <= so.x + se && o.y + e <= so.y + se);
        if (r.node(i).leaf()) {
            sum += r.node(i).mass;
            merged += !t.node(s.from).leaf();
            split += s.fraction < 1.f;
        }
    }
    EXPECT_NEAR(sum, r.totalMass(), 1e-4 * r.totalMass());
    EXPECT_GT(merged, 0);
    EXPECT_GT(split, 0);
    int oldPeak = 0, newPeak = 0;
    r.leafOf(glm::vec2(0.3f, 0.7f), &oldPeak);
    r.leafOf(glm::vec2(0.7f, 0.3f), &newPeak);
    EXPECT_LT(oldPeak, newPeak);
}

TEST(DirTree, WithoutMassRefinesToOneLeaf) {
    DirTree t = treeFor(peaked, 0.01, 8);
    t.setLeafMasses(std::vector<float>(t.size(), 0.f));
    const DirTree r = t.refined(0.01, 8);
    EXPECT_EQ(r.size(), 1u);
    EXPECT_FLOAT_EQ(r.density(glm::vec2(0.2f, 0.9f)), 1.f);
}

TEST(DirTree, EqualAreaMapsRoundTrip) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    for (int n = 0; n < 10000; ++n) {
        const glm::vec2 a(uni(rng), uni(rng));
        glm::vec2 b;
        const glm::vec3 w = DirTree::sphereDirection(a);
        EXPECT_NEAR(glm::length(w), 1.f, 1e-5f);
        ASSERT_TRUE(DirTree::spherePoint(w, &b));
        EXPECT_NEAR(a.x, b.x, 1e-4f);
        EXPECT_NEAR(std::min(std::abs(a.y - b.y), 1.f - std::abs(a.y - b.y)), 0.f, 1e-4f);
        const glm::vec3 h = DirTree::hemisphereDirection(a);
        if (h.z > 1e-3f) {
            ASSERT_TRUE(DirTree::hemispherePoint(h, &b));
            EXPECT_NEAR(a.x, b.x, 1e-4f);
        }
    }
    glm::vec2 b;
    EXPECT_FALSE(DirTree::hemispherePoint(glm::vec3(0.f, 0.f, -1.f), &b));
    EXPECT_FALSE(DirTree::spherePoint(glm::vec3(NAN), &b));
    // Equal area: uniform directions on the sphere give uniform square points (a chi-square
    // over an 8 x 8 grid).
    std::vector<double> observed(64, 0.0), expected(64, 100000.0 / 64);
    for (int n = 0; n < 100000; ++n) {
        ASSERT_TRUE(DirTree::spherePoint(test::gaussianDirection(rng), &b));
        observed[size_t(std::min(int(b.y * 8), 7) * 8 + std::min(int(b.x * 8), 7))] += 1.0;
    }
    const chi2::Result r = chi2::testCounts(observed, expected);
    EXPECT_TRUE(r.passed) << r.message;
}

}  // namespace
}  // namespace rlpbrt::guiding
