// Tests of the learned adaptive-direction tables (guiding/tree_table.h): untrained regions are
// uniform, learning refines where the targets are large, sampling agrees with the density
// (chi-square, unit integral), Q is the running mean of the targets, visits survive the
// refinements, bad records are rejected.
#include "guiding/tree_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "render/chi2.h"

namespace rlpbrt::guiding {
namespace {

// Incident light with a bright spot at (0.3, 0.7) of the square over a dim floor.
float light(glm::vec2 a) {
    const glm::vec2 d = a - glm::vec2(0.3f, 0.7f);
    return glm::dot(d, d) < 0.02f * 0.02f ? 100.f : 0.1f;
}

// Trains region 0 (and region 1 with a constant) for `passes` passes of `perPass` records
// at uniform points, spread over 3 slots.
void train(TreeTable* t, int passes, int perPass, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    for (int p = 0; p < passes; ++p) {
        t->beginPass(3);
        for (int n = 0; n < perPass; ++n) {
            const glm::vec2 a(uni(rng), uni(rng));
            t->record(n % 3, 0, a, light(a));
            if (t->regions() > 1) t->record(n % 3, 1, a, 2.5f);
        }
        t->endPass();
    }
}

double densityIntegral(const TreeTable& t, size_t region) {
    const DirTree& tree = t.tree(region);
    const std::vector<glm::vec3> sq = tree.squares();
    double sum = 0.0;
    for (uint32_t i = 0; i < tree.size(); ++i) {
        if (!tree.node(i).leaf()) continue;
        const glm::vec2 centre(sq[i].x + 0.5f * sq[i].z, sq[i].y + 0.5f * sq[i].z);
        sum += double(t.density(region, centre)) * sq[i].z * sq[i].z;
    }
    return sum;
}

TEST(TreeTable, UntrainedRegionsAreUniform) {
    TreeTable t;
    t.reset(4, TreeTable::Settings{});
    float d = 0.f;
    const glm::vec2 a = t.sample(2, glm::vec2(0.4f, 0.6f), 0.9f, &d);
    EXPECT_FLOAT_EQ(d, 1.f);
    EXPECT_FLOAT_EQ(t.density(2, a), 1.f);
    EXPECT_FLOAT_EQ(t.radianceAt(2, a), 1e-3f);
    EXPECT_EQ(t.confidence(2, 8.0), 0.f);
    EXPECT_EQ(t.tree(2).size(), 1u);
}

TEST(TreeTable, LearnsWhereTheLightIs) {
    TreeTable t;
    TreeTable::Settings s;
    s.splitShare = 0.01;
    s.maxDepth = 10;
    s.smooth = 0.0;  // each leaf its own mean (the smoothing has its own test)
    t.reset(2, s);
    train(&t, 8, 40000, 1);
    int spotDepth = 0, floorDepth = 0;
    t.tree(0).leafOf(glm::vec2(0.3f, 0.7f), &spotDepth);
    t.tree(0).leafOf(glm::vec2(0.8f, 0.2f), &floorDepth);
    EXPECT_GE(spotDepth, 5);
    EXPECT_LE(floorDepth, 3);
    // The spot is 0.126% of the square and holds about 56% of the light: the density there
    // is hundreds of times the floor's, whose density is about the uniform share epsilon
    // plus (1 - epsilon) x 0.44.
    EXPECT_GT(t.density(0, glm::vec2(0.3f, 0.7f)), 100.f);
    EXPECT_LT(t.density(0, glm::vec2(0.8f, 0.2f)), 0.6f);
    EXPECT_NEAR(t.radianceAt(0, glm::vec2(0.3f, 0.7f)), 100.f, 1.f);
    EXPECT_NEAR(t.radianceAt(0, glm::vec2(0.8f, 0.2f)), 0.1f, 0.01f);
    // A constant splits until each leaf holds at most splitShare: 256 leaves of 1/256 (at
    // depth 3 a leaf holds 1/64 > 0.01), each with the constant.
    EXPECT_EQ(t.tree(1).leaves(), 256u);
    EXPECT_NEAR(t.radianceAt(1, glm::vec2(0.5f)), 2.5f, 1e-5f);
    EXPECT_GT(t.confidence(0, 8.0), 0.5f);
    EXPECT_EQ(t.stats().records, uint64_t(8 * 40000 * 2));
    EXPECT_EQ(t.stats().learnedRegions, 2u);
}

TEST(TreeTable, VisitsSurviveRefinement) {
    TreeTable t;
    t.reset(1, TreeTable::Settings{});
    train(&t, 6, 10000, 2);
    const DirTree& tree = t.tree(0);
    ASSERT_GT(tree.leaves(), 4u);
    // Every record is counted once, whatever the splits and merges did with it.
    EXPECT_DOUBLE_EQ(t.visits(0), 60000.0);
}

TEST(TreeTable, DensityIntegratesToOneAndSamplesFollowIt) {
    TreeTable t;
    TreeTable::Settings s;
    s.maxDepth = 6;  // leaves are unions of the 64 x 64 cells below
    s.cosine = true;
    t.reset(1, s);
    train(&t, 6, 20000, 3);
    ASSERT_GT(t.tree(0).leaves(), 10u);
    EXPECT_NEAR(densityIntegral(t, 0), 1.0, 1e-5);
    constexpr int kGrid = 64, kSamples = 300000;
    std::vector<double> observed(kGrid * kGrid, 0.0), expected(kGrid * kGrid, 0.0);
    for (int y = 0; y < kGrid; ++y)
        for (int x = 0; x < kGrid; ++x)
            expected[size_t(y * kGrid + x)] =
                kSamples * double(t.density(0, glm::vec2((x + 0.5f) / kGrid, (y + 0.5f) / kGrid))) /
                (kGrid * kGrid);
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    int mismatches = 0;
    for (int n = 0; n < kSamples; ++n) {
        float d = 0.f;
        const glm::vec2 a = t.sample(0, glm::vec2(uni(rng), uni(rng)), uni(rng), &d);
        if (std::abs(t.density(0, a) - d) > 1e-4f * d) ++mismatches;
        const int x = std::min(int(a.x * kGrid), kGrid - 1);
        const int y = std::min(int(a.y * kGrid), kGrid - 1);
        observed[size_t(y * kGrid + x)] += 1.0;
    }
    EXPECT_EQ(mismatches, 0);
    const chi2::Result r = chi2::testCounts(observed, expected);
    EXPECT_TRUE(r.passed) << r.message;
}

// The smoothing: a leaf without visits takes its neighbourhood's estimate, not init; with
// many visits a leaf keeps its own mean.
TEST(TreeTable, SmoothingFillsLeavesWithoutVisits) {
    TreeTable t;
    TreeTable::Settings s;
    s.smooth = 2.0;
    t.reset(1, s);
    // Pass 1: everything in the lower-left quarter, target 4: the root splits, the empty
    // quarters borrow the root's mean instead of keeping init.
    t.beginPass(1);
    for (int i = 0; i < 1000; ++i)
        t.record(0, 0, glm::vec2(0.1f + 0.3f * (i % 10) / 10.f, 0.1f + 0.3f * (i / 100) / 10.f), 4.f);
    t.endPass();
    EXPECT_GT(t.tree(0).leaves(), 1u);
    EXPECT_NEAR(t.radianceAt(0, glm::vec2(0.2f, 0.2f)), 4.f, 1e-3f);
    EXPECT_NEAR(t.radianceAt(0, glm::vec2(0.9f, 0.9f)), 4.f, 1e-3f);
    EXPECT_NEAR(densityIntegral(t, 0), 1.0, 1e-5);
}

TEST(TreeTable, RejectsBadRecords) {
    TreeTable t;
    t.reset(2, TreeTable::Settings{});
    t.record(0, 0, glm::vec2(0.5f), 1.f);  // no pass open: ignored
    t.beginPass(1);
    t.record(0, 0, glm::vec2(0.5f), NAN);
    t.record(0, 0, glm::vec2(0.5f), -1.f);
    t.record(0, 0, glm::vec2(1.5f, 0.5f), 1.f);
    t.record(0, 7, glm::vec2(0.5f), 1.f);
    t.record(3, 0, glm::vec2(0.5f), 1.f);  // no such slot: ignored
    t.endPass();
    EXPECT_EQ(t.stats().rejectedTargets, 2u);
    EXPECT_EQ(t.stats().rejectedRecords, 2u);
    EXPECT_EQ(t.stats().records, 0u);
    EXPECT_EQ(t.visits(0), 0.0);
}

}  // namespace
}  // namespace rlpbrt::guiding
