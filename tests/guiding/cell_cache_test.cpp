// Tests of the lookup memo of the hemi backend (guiding/cell_cache.h): one evaluation per
// cell, lists equal to a direct evaluation at the cell centre under concurrent filling, and a
// full table that still answers correctly.
#include "guiding/cell_cache.h"

#include <gtest/gtest.h>

#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <random>
#include <vector>

namespace rlpbrt::guiding {
namespace {

// A pure list of a centre: k values derived from its coordinates.
int listOf(const glm::vec3& c, int k, uint32_t* dest) {
    const int n = 1 + int(std::abs(c.x * 7.f + c.y * 3.f + c.z)) % k;
    for (int i = 0; i < n; ++i)
        dest[i] = uint32_t(std::lround(c.x * 1000.f)) * 31u + uint32_t(std::lround(c.y * 1000.f)) * 7u +
                  uint32_t(std::lround(c.z * 1000.f)) + uint32_t(i);
    return n;
}

TEST(CellCache, OneEvaluationPerCellAndTheCellCentre) {
    CellCache cache(glm::vec3(-1.f), glm::vec3(1.f), 0.25f, 4096);
    EXPECT_FLOAT_EQ(cache.cellSize(), 0.25f);
    EXPECT_EQ(cache.capacity(), 4096u);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uni(-1.f, 1.f);
    int fills = 0;
    for (int i = 0; i < 20000; ++i) {
        const glm::vec3 p(uni(rng), uni(rng), uni(rng));
        const glm::vec3 c = cache.centreOf(p);
        // The centre of the cell that holds p.
        for (int a = 0; a < 3; ++a) {
            EXPECT_LE(std::abs(p[a] - c[a]), 0.125f + 1e-6f);
            EXPECT_NEAR(std::fmod(c[a] + 1.f, 0.25f), 0.125f, 1e-5f);
        }
        uint32_t scratch[CellCache::kMaxCandidates];
        const uint32_t* out = nullptr;
        const int n = cache.candidates(
            p,
            [&](const glm::vec3& centre, uint32_t* dest) {
                ++fills;
                EXPECT_EQ(centre, c);
                return listOf(centre, 8, dest);
            },
            scratch, &out);
        uint32_t want[CellCache::kMaxCandidates];
        ASSERT_EQ(n, listOf(c, 8, want));
        for (int j = 0; j < n; ++j) EXPECT_EQ(out[j], want[j]);
    }
    EXPECT_EQ(fills, 8 * 8 * 8);  // every cell once
    EXPECT_EQ(cache.size(), 512u);
}

TEST(CellCache, ConcurrentFillingGivesTheDirectLists) {
    // 8000 cells in 65536 entries: no probe sequence reaches kMaxProbes, every cell is cached.
    CellCache cache(glm::vec3(0.f), glm::vec3(10.f), 0.5f, 65536);
    std::vector<glm::vec3> queries(200000);
    std::mt19937 rng(9);
    std::uniform_real_distribution<float> uni(0.f, 10.f);
    for (glm::vec3& q : queries) q = glm::vec3(uni(rng), uni(rng), uni(rng));
    std::atomic<int> wrong{0};
    tbb::parallel_for(size_t(0), queries.size(), [&](size_t i) {
        uint32_t scratch[CellCache::kMaxCandidates], want[CellCache::kMaxCandidates];
        const uint32_t* out = nullptr;
        const int n = cache.candidates(
            queries[i], [](const glm::vec3& c, uint32_t* d) { return listOf(c, 13, d); }, scratch,
            &out);
        const int m = listOf(cache.centreOf(queries[i]), 13, want);
        bool same = n == m;
        for (int j = 0; same && j < n; ++j) same = out[j] == want[j];
        if (!same) ++wrong;
    });
    EXPECT_EQ(wrong.load(), 0);
    EXPECT_EQ(cache.size(), 8000u);  // 20^3 cells, each cached once
}

TEST(CellCache, AFullTableEvaluatesDirectly) {
    // 4096 cells, 1024 entries: at most 768 are cached, the rest are evaluated each time.
    CellCache cache(glm::vec3(0.f), glm::vec3(16.f), 1.f, 1000);
    EXPECT_EQ(cache.capacity(), 1024u);
    int fills = 0;
    for (int round = 0; round < 2; ++round)
        for (int x = 0; x < 16; ++x)
            for (int y = 0; y < 16; ++y)
                for (int z = 0; z < 16; ++z) {
                    const glm::vec3 p(x + 0.3f, y + 0.6f, z + 0.9f);
                    uint32_t scratch[CellCache::kMaxCandidates], want[CellCache::kMaxCandidates];
                    const uint32_t* out = nullptr;
                    const int n = cache.candidates(
                        p,
                        [&](const glm::vec3& c, uint32_t* d) {
                            ++fills;
                            return listOf(c, 4, d);
                        },
                        scratch, &out);
                    ASSERT_EQ(n, listOf(glm::vec3(x + 0.5f, y + 0.5f, z + 0.5f), 4, want));
                    for (int j = 0; j < n; ++j) ASSERT_EQ(out[j], want[j]);
                }
    EXPECT_EQ(cache.size(), 768u);
    EXPECT_EQ(fills, 4096 + (4096 - 768));
}

TEST(CellCache, HugeBoundsGrowTheCells) {
    // 2^21 cells per axis at most: a tiny cell over huge bounds is enlarged, and points outside
    // the bounds fall in the border cells.
    CellCache cache(glm::vec3(-1e6f), glm::vec3(1e6f), 1e-3f, 1024);
    EXPECT_GE(cache.cellSize(), 2e6f / float(1 << 21));
    const glm::vec3 c = cache.centreOf(glm::vec3(-5e6f, 0.f, 5e6f));
    EXPECT_LT(c.x, -1e6f + cache.cellSize());
    EXPECT_GT(c.z, 1e6f - cache.cellSize());
    // Degenerate bounds and cell size still give a usable grid.
    CellCache flat(glm::vec3(0.f), glm::vec3(0.f), 0.f, 16);
    EXPECT_GT(flat.cellSize(), 0.f);
    EXPECT_TRUE(std::isfinite(flat.centreOf(glm::vec3(3.f)).x));
}

}  // namespace
}  // namespace rlpbrt::guiding
