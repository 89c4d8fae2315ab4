// Tests of the strata tables shared by the hemi and vdb backends: the hierarchical smoothing of
// the estimates (StrataTable::setSmoothing over StrataLayout::quadtree).
#include "guiding/strata_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "guiding/directional.h"

namespace rlpbrt::guiding {
namespace {

TEST(StrataLayout, QuadtreeHalvesTheGridUpToOneRoot) {
    const auto levels = StrataLayout(8, 8).quadtree();
    ASSERT_EQ(levels.size(), 3u);  // 8x8 -> 4x4 -> 2x2 -> 1
    EXPECT_EQ(levels[0].size(), 64u);
    EXPECT_EQ(levels[1].size(), 16u);
    EXPECT_EQ(levels[2].size(), 4u);
    EXPECT_EQ(levels[0][0], 0u);
    EXPECT_EQ(levels[0][1], 0u);    // (0, 1) -> (0, 0)
    EXPECT_EQ(levels[0][8], 0u);    // (1, 0) -> (0, 0)
    EXPECT_EQ(levels[0][9], 0u);    // (1, 1) -> (0, 0)
    EXPECT_EQ(levels[0][2], 1u);    // (0, 2) -> (0, 1)
    EXPECT_EQ(levels[0][63], 15u);  // (7, 7) -> (3, 3)
    for (uint32_t p : levels[2]) EXPECT_EQ(p, 0u);
    // Odd sizes: 3 columns x 5 rows -> 2x3 -> 1x2 -> 1.
    const auto odd = StrataLayout(3, 5).quadtree();
    ASSERT_EQ(odd.size(), 3u);
    EXPECT_EQ(odd[0].size(), 15u);
    EXPECT_EQ(odd[1].size(), 6u);
    EXPECT_EQ(odd[2].size(), 2u);
    EXPECT_EQ(odd[0][2], 1u);   // (0, 2) -> (0, 1)
    EXPECT_EQ(odd[0][14], 5u);  // (4, 2) -> (2, 1)
    EXPECT_EQ(odd[1][5], 1u);   // (2, 1) -> (1, 0)
    // One stratum: a single level mapping it to the root.
    const auto one = StrataLayout(1, 1).quadtree();
    ASSERT_EQ(one.size(), 1u);
    EXPECT_EQ(one[0], std::vector<uint32_t>{0u});
}

TEST(StrataLayout, SphereQuadtreeJoinsTheTwoHemispheres) {
    const auto levels = StrataLayout(4, 2).sphereQuadtree();
    // Per hemisphere 4x2 -> 2x1 -> 1; then the two hemisphere roots -> 1.
    ASSERT_EQ(levels.size(), 3u);
    EXPECT_EQ(levels[0].size(), 16u);
    EXPECT_EQ(levels[1].size(), 4u);
    EXPECT_EQ(levels[2], (std::vector<uint32_t>{0u, 0u}));
    EXPECT_EQ(levels[0][0], 0u);   // upper (0, 0) -> upper node 0
    EXPECT_EQ(levels[0][7], 1u);   // upper (1, 3) -> upper node (0, 1)
    EXPECT_EQ(levels[0][8], 2u);   // lower (0, 0) -> lower node 0, numbered after the upper 2
    EXPECT_EQ(levels[0][15], 3u);  // lower (1, 3) -> lower node (0, 1)
    EXPECT_EQ(levels[1], (std::vector<uint32_t>{0u, 0u, 1u, 1u}));
}

// One region of 4x4 strata, one pass of records: per entry of `records`, `count` targets of
// `target` in stratum `stratum`. Returns the region's estimates and checks that the policy
// was built from them.
struct Records {
    int stratum, count;
    float target;
};
std::vector<double> trainOnce(double prior, const std::vector<Records>& records) {
    StrataTable table;
    if (prior > 0.0) table.setSmoothing(StrataLayout(4, 4).quadtree(), prior);
    std::vector<double> fromPolicy;
    auto policy = [&](int, const double* q, float* cdf) {
        fromPolicy.assign(q, q + 16);
        buildStrataCdf(q, 16, 0.1, cdf);
    };
    table.reset(1, 16, 1e-3, policy);
    table.beginPass(1);
    for (const Records& r : records)
        for (int i = 0; i < r.count; ++i) table.record(0, 0, r.target, [&] { return r.stratum; });
    table.endPass(true, 1.0, policy);
    std::vector<double> est(16);
    table.estimate(0, est.data());
    EXPECT_EQ(fromPolicy, est);
    for (int j = 0; j < 16; ++j) EXPECT_EQ(table.estimates(0)[j], float(est[size_t(j)]));
    return est;
}

TEST(StrataTable, WithoutSmoothingTheEstimatesAreQ) {
    const std::vector<double> est = trainOnce(0.0, {{5, 10, 5.f}});
    for (int j = 0; j < 16; ++j) EXPECT_EQ(est[size_t(j)], j == 5 ? 5.0 : 1e-3) << j;
}

TEST(StrataTable, SmoothingShrinksTowardsTheCoarserMeans) {
    // Prior 2; 10 targets of 5 in stratum 0 (row 0, column 0) and 10 of 1 in stratum 15 (row
    // 3, column 3). The 2x2 level: node A holds strata 0, 1, 4, 5, node D 10, 11, 14, 15; B and
    // C hold the rest. The root: the mean of all 20 targets.
    const double k = 2.0;
    const double root = (50.0 + 10.0) / 20.0;
    const double a = (50.0 + k * root) / (10.0 + k), d = (10.0 + k * root) / (10.0 + k);
    const std::vector<double> est = trainOnce(k, {{0, 10, 5.f}, {15, 10, 1.f}});
    EXPECT_NEAR(est[0], (50.0 + k * a) / (10.0 + k), 1e-12);
    EXPECT_NEAR(est[15], (10.0 + k * d) / (10.0 + k), 1e-12);
    for (int j : {1, 4, 5}) EXPECT_NEAR(est[size_t(j)], a, 1e-12) << j;   // A's mean
    for (int j : {10, 11, 14}) EXPECT_NEAR(est[size_t(j)], d, 1e-12) << j;  // D's mean
    for (int j : {2, 3, 6, 7, 8, 9, 12, 13}) EXPECT_NEAR(est[size_t(j)], root, 1e-12) << j;
    // Each visited stratum stays closest to its own mean.
    EXPECT_GT(est[0], est[1]);
    EXPECT_GT(est[1], est[2]);
    EXPECT_GT(est[2], est[14]);
    EXPECT_GT(est[14], est[15]);
}

TEST(StrataTable, TheRootIsInitOnlyBeforeAnyVisit) {
    StrataTable table;
    table.setSmoothing(StrataLayout(4, 4).quadtree(), 2.0);
    table.reset(1, 16, 0.25, [](int, const double* q, float* cdf) {
        buildStrataCdf(q, 16, 0.1, cdf);
    });
    for (int j = 0; j < 16; ++j) EXPECT_EQ(table.estimates(0)[j], 0.25f);
}

TEST(StrataTable, ManyVisitsKeepTheirOwnQ) {
    const std::vector<double> est = trainOnce(2.0, {{6, 20000, 3.f}});
    EXPECT_NEAR(est[6], 3.0, 3.0 * 1e-3);
    // Unvisited strata take the neighbourhood's mean, 3 (no visit of their own to hold it).
    EXPECT_NEAR(est[0], 3.0, 3.0 * 1e-3);
}

// Lazy tables (one shared block until a region learns) hold the same data per region as
// tables with a block per region, over passes that reach new regions, and after assign().
TEST(StrataTable, LazyTablesMatchEagerOnesRegionByRegion) {
    const int regions = 6, n = 16;
    auto policy = [](int, const double* q, float* cdf) { buildStrataCdf(q, n, 0.1, cdf); };
    StrataTable eager, lazy;
    for (StrataTable* t : {&eager, &lazy}) t->setSmoothing(StrataLayout(4, 4).quadtree(), 2.0);
    eager.reset(regions, n, 1e-3, policy);
    lazy.reset(regions, n, 1e-3, policy, /*lazy=*/true);
    EXPECT_EQ(eager.learnedRegions(), size_t(regions));
    EXPECT_EQ(lazy.learnedRegions(), 0u);
    EXPECT_LT(lazy.bytes(), eager.bytes());
    auto same = [&](const StrataTable& a, const StrataTable& b, const char* when) {
        for (size_t r = 0; r < size_t(regions); ++r) {
            for (int j = 0; j < n; ++j) {
                EXPECT_EQ(a.q(r)[j], b.q(r)[j]) << when << " region " << r;
                EXPECT_EQ(a.visits(r)[j], b.visits(r)[j]) << when << " region " << r;
                EXPECT_EQ(a.estimates(r)[j], b.estimates(r)[j]) << when << " region " << r;
            }
            for (int j = 0; j <= n; ++j) EXPECT_EQ(a.cdf(r)[j], b.cdf(r)[j]) << when << r;
        }
    };
    same(eager, lazy, "untrained");
    // Pass 1 reaches regions 4 and 1, pass 2 regions 1, 3 and 5 (blocks appended out of
    // region order across passes).
    const std::vector<std::vector<int>> passes = {{4, 1}, {1, 3, 5}};
    for (size_t p = 0; p < passes.size(); ++p) {
        for (StrataTable* t : {&eager, &lazy}) {
            t->beginPass(2);
            for (int r : passes[p])
                for (int i = 0; i < 5; ++i)
                    t->record(i % 2, r, float(r + i + p), [&] { return (r * 3 + i) % n; });
            t->endPass(true, 1.0, policy);
        }
        same(eager, lazy, p == 0 ? "pass 1" : "pass 2");
    }
    EXPECT_EQ(lazy.learnedRegions(), 4u);  // 1, 3, 4, 5; 0 and 2 share the prior
    // assign(): region-major data, as a saved field holds it.
    std::vector<double> q;
    std::vector<uint64_t> visits;
    for (size_t r = 0; r < size_t(regions); ++r) {
        q.insert(q.end(), eager.q(r), eager.q(r) + n);
        visits.insert(visits.end(), eager.visits(r), eager.visits(r) + n);
    }
    StrataTable loaded;
    loaded.setSmoothing(StrataLayout(4, 4).quadtree(), 2.0);
    loaded.reset(regions, n, 1e-3, policy, /*lazy=*/true);
    loaded.assign(q, visits, policy);
    same(eager, loaded, "assigned");
    EXPECT_EQ(loaded.learnedRegions(), 4u);
    // Grown from no regions, a lazy table shares an untrained block like the rest.
    StrataTable grown;
    grown.setSmoothing(StrataLayout(4, 4).quadtree(), 2.0);
    grown.reset(0, n, 1e-3, policy, /*lazy=*/true);
    grown.grow(3, 1e-3, policy);
    EXPECT_EQ(grown.learnedRegions(), 0u);
    for (size_t r = 0; r < 3; ++r)
        for (int j = 0; j <= n; ++j) EXPECT_EQ(grown.cdf(r)[j], eager.cdf(0)[j]) << r;
}

}  // namespace
}  // namespace rlpbrt::guiding
