#include "guiding/kdtree.h"

#include <algorithm>
#include <cfloat>
#include <random>
#include <vector>

#include <gtest/gtest.h>

using rlpbrt::guiding::PointKdTree;

namespace {

float dist2(const glm::vec3& a, const glm::vec3& b) {
    glm::vec3 d = a - b;
    return glm::dot(d, d);
}

// Points on the faces of the unit cube (many equal coordinates: ties in the splits) plus a
// few clustered duplicates.
std::vector<glm::vec3> boxPoints(size_t n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    std::vector<glm::vec3> pts;
    for (size_t i = 0; i < n; ++i) {
        int face = int(rng() % 6), axis = face / 2;
        glm::vec3 p;
        p[axis] = (face & 1) ? 1.f : 0.f;
        p[(axis + 1) % 3] = u(rng);
        p[(axis + 2) % 3] = u(rng);
        pts.push_back(p);
        if (i % 97 == 0) pts.push_back(p);  // exact duplicates
    }
    return pts;
}

}  // namespace

// The tree is exact: its nearest distance equals brute force for every query (the index may
// differ only between points at the same distance).
TEST(PointKdTree, NearestMatchesBruteForce) {
    for (size_t n : {size_t(1), size_t(2), size_t(7), size_t(9), size_t(100), size_t(5000)}) {
        auto pts = boxPoints(n, 7);
        PointKdTree tree(pts);
        std::mt19937 rng(3);
        std::uniform_real_distribution<float> u(-0.2f, 1.2f);
        for (int q = 0; q < 2000; ++q) {
            glm::vec3 p(u(rng), u(rng), u(rng));
            float best = FLT_MAX;
            for (const auto& x : pts) best = std::min(best, dist2(x, p));
            float d = 0.f;
            int i = tree.nearest(p, &d);
            ASSERT_GE(i, 0);
            EXPECT_EQ(d, best) << "n=" << n;
            EXPECT_EQ(dist2(pts[size_t(i)], p), best);
        }
    }
}

TEST(PointKdTree, KnnMatchesBruteForceSortedDistances) {
    auto pts = boxPoints(3000, 11);
    PointKdTree tree(pts);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (int k : {1, 2, 8, 64}) {
        for (int q = 0; q < 300; ++q) {
            glm::vec3 p(u(rng), u(rng), u(rng));
            std::vector<float> all;
            for (const auto& x : pts) all.push_back(dist2(x, p));
            std::sort(all.begin(), all.end());
            uint32_t idx[PointKdTree::kMaxK];
            float d[PointKdTree::kMaxK];
            int found = tree.knn(p, k, idx, d);
            ASSERT_EQ(found, k);
            for (int i = 0; i < found; ++i) {
                EXPECT_EQ(d[i], all[size_t(i)]) << "k=" << k << " i=" << i;
                EXPECT_EQ(dist2(pts[idx[i]], p), d[i]);
            }
        }
    }
}

TEST(PointKdTree, EmptyAndSmallTrees) {
    PointKdTree empty({});
    float d = 0.f;
    uint32_t idx[4];
    float dd[4];
    EXPECT_EQ(empty.nearest(glm::vec3(0.f), &d), -1);
    EXPECT_EQ(empty.knn(glm::vec3(0.f), 4, idx, dd), 0);
    PointKdTree three({glm::vec3(0.f), glm::vec3(1.f), glm::vec3(2.f)});
    EXPECT_EQ(three.knn(glm::vec3(1.9f), 8, idx, dd), 3);  // k clamped to the size
    EXPECT_EQ(idx[0], 2u);
    EXPECT_EQ(idx[1], 1u);
    EXPECT_EQ(idx[2], 0u);
    EXPECT_EQ(three.knn(glm::vec3(0.f), 0, idx, dd), 0);
}
