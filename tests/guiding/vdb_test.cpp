// Tests of the `vdb` guiding backend: factory errors, voxel activation and lookup (inactive
// voxels, neighbours, far points), sampling vs pdf (chi-square) for untrained and trained
// fields in both table layouts, normalisation, learning, deterministic merge, and save/load
// (round trip, mismatch errors), including hemi's binary format.
#include "guiding/guiding.h"
#include "guiding/hemi.h"
#include "guiding/vdb.h"

#include <gtest/gtest.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "guiding/test_scenes.h"
#include "render/chi2.h"

namespace rlpbrt::guiding {
namespace {

using test::cornerScene;
using test::gaussianDirection;
using test::planeScene;
using test::sphereTest;
using test::trainBright;

std::unique_ptr<VdbField> makeVdb(const SceneInfo& scene,
                                  std::map<std::string, std::string> params = {}) {
    return test::makeField<VdbField>("vdb", scene, std::move(params));
}

// Sum over strata of pdf(centre) * stratum solid angle: the pdf's integral over the sphere.
double strataIntegral(const VdbField& f, int region) {
    double sum = 0.0;
    for (int j = 0; j < f.strataPerRegion(); ++j)
        sum += double(f.pdf(region, f.strataCentre(region, j))) * f.stratumSolidAngle();
    return sum;
}

// Each test case below runs up to 8 chi-square tests of each kind (regions x table layouts):
// a family-wise 1% level over them (Sidak).
constexpr int kTestsPerCase = 8;

// Exact chi-square in the region's own strata: expected count N * P_j per stratum.
chi2::Result strataTest(const VdbField& f, int region, uint64_t seed, int samples) {
    const int n = f.strataPerRegion();
    std::vector<double> observed(size_t(n + 1), 0.0), expected(size_t(n + 1), 0.0);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    for (int i = 0; i < samples; ++i) {
        float pdf = 0.f;
        glm::vec3 w = f.sample(region, glm::vec2(uni(rng), uni(rng)), uni(rng), &pdf);
        int j = f.stratumOf(region, w);
        observed[size_t(j < 0 ? n : j)] += 1.0;
    }
    for (int j = 0; j < n; ++j)
        expected[size_t(j)] =
            samples * double(f.pdf(region, f.strataCentre(region, j))) * f.stratumSolidAngle();
    return chi2::testCounts(observed, expected, 0.01, kTestsPerCase);
}

std::string tempPath(const std::string& name) {
    return ::testing::TempDir() + "rlpbrt_vdb_test_" + name;
}

TEST(VdbFactory, ParametersAndErrors) {
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"alpha", "0"},      {"alpha", "x"},        {"strata", "0x8"},  {"strata", "65"},
        {"voxel", "0"},      {"voxel", "4097"},     {"voxel", "1.5"},   {"voxel-size", "0"},
        {"voxel-size", "-1"}, {"voxel-size", "inf"}, {"points", "0"},   {"dirs", "cube"},
        {"init", "0"},       {"epsilon", "2"},      {"cosine", "2"},    {"max-mb", "0"},
        {"knn", "8"},        {"normal-angle", "0"}, {"normal-angle", "180"}, {"normals", "0"},
        {"normals", "17"},   {"learn-cap", "-1"},
    };
    for (const auto& [key, value] : bad) {
        GuideConfig cfg;
        cfg.backend = "vdb";
        cfg.params[key] = value;
        std::string error;
        EXPECT_EQ(createGuidingField(cfg, planeScene(), &error), nullptr) << key << "=" << value;
        EXPECT_NE(error.find(key), std::string::npos) << error;
        EXPECT_NE(error.find("vdb"), std::string::npos) << error;
    }
    GuideConfig both;
    both.backend = "vdb";
    both.params = {{"voxel", "8"}, {"voxel-size", "0.1"}};
    std::string error;
    EXPECT_EQ(createGuidingField(both, planeScene(), &error), nullptr);
    EXPECT_NE(error.find("not both"), std::string::npos) << error;

    GuideConfig huge;
    huge.backend = "vdb";
    huge.params = {{"voxel", "4096"}, {"strata", "64"}, {"points", "67108864"}};
    EXPECT_EQ(createGuidingField(huge, planeScene(), &error), nullptr);
    EXPECT_NE(error.find("MiB"), std::string::npos) << error;

    GuideConfig noSampler;
    noSampler.backend = "vdb";
    EXPECT_EQ(createGuidingField(noSampler, SceneInfo{}, &error), nullptr);
    EXPECT_FALSE(error.empty());

    auto f = makeVdb(planeScene(), {{"alpha", "0.25"}, {"strata", "4x2"}, {"voxel", "8"},
                                    {"init", "2"}, {"epsilon", "0"}, {"mix", "0.3"},
                                    {"target", "sum"}, {"dirs", "sphere"}});
    ASSERT_TRUE(f);
    EXPECT_DOUBLE_EQ(f->voxelSize(), 1.0 / 8.0);
    EXPECT_EQ(f->layout().count(), 8);
    EXPECT_EQ(f->strataPerRegion(), 16);
    EXPECT_EQ(f->numRegions(), int(f->activeVoxels()));
    EXPECT_EQ(f->q(3, 5), 2.0);
    auto g = makeVdb(planeScene(), {{"voxel-size", "0.25"}});
    ASSERT_TRUE(g);
    EXPECT_DOUBLE_EQ(g->voxelSize(), 0.25);
    EXPECT_EQ(g->numRegions(), 2 * int(g->activeVoxels()));
    EXPECT_NE(g->describe().find("active voxels"), std::string::npos) << g->describe();
}

TEST(VdbField, DefaultVoxelSizeFromScene) {
    auto f = makeVdb(planeScene());
    ASSERT_TRUE(f);
    // sqrt(area / 1024) = 1/32 for the unit square, within [1/1024, 1/4].
    EXPECT_DOUBLE_EQ(f->voxelSize(), 1.0 / 32.0);
    EXPECT_EQ(f->pointCount(), 65536u);
    EXPECT_EQ(f->activeVoxels(), 32u * 32u);
    EXPECT_EQ(f->stats().activeVoxels, 32u * 32u);
    EXPECT_GT(f->bytes(), f->gridBytes());
    EXPECT_LE(double(f->bytes()), vdbEstimatedBytes(f->params(), planeScene()));
}

TEST(VdbField, ActiveVoxelsAreExactlyThoseTheSurfacesCross) {
    auto f = makeVdb(cornerScene(), {{"voxel", "16"}});
    ASSERT_TRUE(f);
    std::set<std::tuple<int, int, int>> expected;
    for (int a = 0; a < 16; ++a)
        for (int b = 0; b < 16; ++b) {
            expected.insert({a, b, 0});  // floor: z = 0
            expected.insert({0, a, b});  // wall: x = 0
        }
    EXPECT_EQ(f->activeVoxels(), expected.size());
    for (const auto& [i, j, k] : expected) EXPECT_GE(f->voxelIndex(glm::ivec3(i, j, k)), 0);
    EXPECT_LT(f->voxelIndex(glm::ivec3(1, 1, 1)), 0);
    EXPECT_LT(f->voxelIndex(glm::ivec3(8, 8, 8)), 0);
    // Indices are a permutation of 0..voxels-1.
    std::set<int> seen;
    for (const auto& [i, j, k] : expected) seen.insert(f->voxelIndex(glm::ivec3(i, j, k)));
    EXPECT_EQ(seen.size(), expected.size());
    EXPECT_EQ(*seen.begin(), 0);
    EXPECT_EQ(*seen.rbegin(), int(expected.size()) - 1);
}

TEST(VdbField, LookupFindsSurfaceVoxelsAndNothingFarAway) {
    auto f = makeVdb(cornerScene(), {{"voxel", "16"}});
    ASSERT_TRUE(f);
    const float h = 1.f / 16.f;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    for (int i = 0; i < 1000; ++i) {
        glm::vec3 p(uni(rng), uni(rng), 0.f);  // on the floor
        int up = f->lookup(p, glm::vec3(0, 0, 1));
        ASSERT_GE(up, 0);
        EXPECT_EQ(f->regionVoxel(up), f->voxelIndex(f->voxelCoord(p)));
        int down = f->lookup(p, glm::vec3(0, 0, -1));
        EXPECT_EQ(f->regionVoxel(down), f->regionVoxel(up));
        EXPECT_NE(down, up);
        // Away from the wall's voxels the mean normal is the floor's.
        if (p.x > h) {
            EXPECT_EQ(up % 2, 0);
            EXPECT_NEAR(glm::dot(f->regionFrame(up).n, glm::vec3(0, 0, 1)), 1.f, 1e-6f);
        }
    }
    // Just below the floor: the voxel is inactive, its neighbour above is the nearest.
    glm::vec3 below(0.53f, 0.53f, -0.2f * h);
    EXPECT_LT(f->voxelIndex(f->voxelCoord(below)), 0);
    int r = f->lookup(below, glm::vec3(0, 0, 1));
    ASSERT_GE(r, 0);
    EXPECT_EQ(f->regionVoxel(r), f->voxelIndex(f->voxelCoord(glm::vec3(0.53f, 0.53f, 0.f))));
    // One voxel layer above the floor: neighbour found; two layers above: nothing.
    EXPECT_GE(f->lookup(glm::vec3(0.5f, 0.5f, 1.5f * h), glm::vec3(0, 0, 1)), 0);
    EXPECT_EQ(f->lookup(glm::vec3(0.5f, 0.5f, 2.5f * h), glm::vec3(0, 0, 1)), -1);
    EXPECT_EQ(f->lookup(glm::vec3(0.5f, 0.5f, 0.5f), glm::vec3(0, 0, 1)), -1);
    EXPECT_EQ(f->lookup(glm::vec3(50.f, -3.f, 7.f), glm::vec3(0, 0, 1)), -1);
    EXPECT_EQ(f->lookup(glm::vec3(1e30f, 0.f, 0.f), glm::vec3(0, 0, 1)), -1);
    EXPECT_EQ(f->lookup(glm::vec3(NAN, 0.f, 0.f), glm::vec3(0, 0, 1)), -1);
    EXPECT_EQ(f->lookup(glm::vec3(0.5f, 0.5f, 0.f), glm::vec3(0.f)), -1);
    // Nearest neighbour by distance to the voxel box: just off the wall (x < 0) near the
    // floor's level picks the wall voxel at the same height, not a diagonal one.
    glm::vec3 offWall(-0.1f * h, 0.53f, 0.53f);
    int w = f->lookup(offWall, glm::vec3(1, 0, 0));
    ASSERT_GE(w, 0);
    EXPECT_EQ(f->regionVoxel(w), f->voxelIndex(f->voxelCoord(glm::vec3(0.f, 0.53f, 0.53f))));
}

TEST(VdbField, DominantNormalsPerVoxel) {
    // Corner voxels (x = 0, z = 0) hold the floor and the wall: two dominant normals.
    auto f = makeVdb(cornerScene(), {{"voxel", "16"}});
    ASSERT_TRUE(f);
    EXPECT_EQ(f->clusterCount(), f->activeVoxels() + 16);
    EXPECT_EQ(f->numRegions(), 2 * int(f->clusterCount()));
    const glm::vec3 corner(0.01f, 0.5f, 0.f);
    const int floorUp = f->lookup(corner, glm::vec3(0, 0, 1));
    const int wallOut = f->lookup(corner, glm::vec3(1, 0, 0));
    ASSERT_GE(floorUp, 0);
    ASSERT_GE(wallOut, 0);
    EXPECT_EQ(f->regionVoxel(floorUp), f->regionVoxel(wallOut));
    EXPECT_EQ(f->regionFrame(floorUp).n, glm::vec3(0, 0, 1));
    EXPECT_EQ(f->regionFrame(wallOut).n, glm::vec3(1, 0, 0));
    EXPECT_EQ(f->regionFrame(f->lookup(corner, glm::vec3(-1, 0, 0))).n, glm::vec3(-1, 0, 0));
    // A vertex normal more than normal-angle (30 degrees) from every dominant normal: no data.
    EXPECT_EQ(f->lookup(corner, glm::normalize(glm::vec3(1, 0, 1))), -1);
    EXPECT_EQ(f->lookup(glm::vec3(0.5f, 0.5f, 0.f), glm::normalize(glm::vec3(1, 0, 0.8f))), -1);
    EXPECT_GE(f->lookup(glm::vec3(0.5f, 0.5f, 0.f), glm::normalize(glm::vec3(0.4f, 0, 1))), 0);
    // normals=1: one mean normal per voxel (45 degrees in the corner voxels), and a wider
    // admissible angle.
    auto g = makeVdb(cornerScene(), {{"voxel", "16"}, {"normals", "1"}, {"normal-angle", "60"}});
    ASSERT_TRUE(g);
    EXPECT_EQ(g->clusterCount(), g->activeVoxels());
    const int mixed = g->lookup(corner, glm::vec3(0, 0, 1));
    ASSERT_GE(mixed, 0);
    EXPECT_NEAR(glm::dot(g->regionFrame(mixed).n, glm::vec3(0, 0, 1)), std::sqrt(0.5f), 0.05f);
}

TEST(VdbField, NoSurfaceGivesEmptyField) {
    SceneInfo empty = planeScene();
    empty.samplePoint = [](const glm::vec3&, glm::vec3*, glm::vec3*) { return false; };
    auto f = makeVdb(empty);
    ASSERT_TRUE(f);
    EXPECT_EQ(f->activeVoxels(), 0u);
    EXPECT_EQ(f->numRegions(), 0);
    EXPECT_EQ(f->lookup(glm::vec3(0.5f, 0.5f, 0.f), glm::vec3(0, 0, 1)), -1);
    f->beginPass(2);
    f->record(0, 0, glm::vec3(0, 0, 1), 1.f);
    f->endPass();
    EXPECT_EQ(f->stats().records, 0u);
    float pdf = 1.f;
    EXPECT_EQ(f->sample(0, glm::vec2(0.5f), 0.5f, &pdf), glm::vec3(0.f));
    EXPECT_EQ(pdf, 0.f);
    // Degenerate bounds (a single point) still give a finite voxel size.
    SceneInfo point = planeScene();
    point.boundsMax = point.boundsMin;
    point.totalArea = 0.0;
    point.samplePoint = [](const glm::vec3&, glm::vec3* p, glm::vec3* n) {
        *p = glm::vec3(0.f);
        *n = glm::vec3(0, 0, 1);
        return true;
    };
    auto g = makeVdb(point);
    ASSERT_TRUE(g);
    EXPECT_TRUE(std::isfinite(g->voxelSize()) && g->voxelSize() > 0.0);
    EXPECT_EQ(g->activeVoxels(), 1u);
    EXPECT_GE(g->lookup(glm::vec3(0.f), glm::vec3(0, 0, 1)), 0);
}

TEST(VdbField, AccessorModesGiveTheSameLookups) {
    auto f = makeVdb(cornerScene(), {{"voxel", "16"}});
    ASSERT_TRUE(f);
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<float> uni(-0.1f, 1.1f);
    std::vector<std::pair<glm::vec3, glm::vec3>> queries;
    for (int i = 0; i < 20000; ++i) {
        glm::vec3 p(uni(rng), uni(rng), 0.15f * uni(rng));  // near the floor, some misses
        queries.emplace_back(p, gaussianDirection(rng));
    }
    std::vector<int> reference;
    for (const auto& [p, n] : queries) reference.push_back(f->lookup(p, n));
    EXPECT_GT(std::count(reference.begin(), reference.end(), -1), 100);
    for (auto mode : {VdbField::Accessor::PerLookup, VdbField::Accessor::PerThread,
                      VdbField::Accessor::Uncached, VdbField::Accessor::Hybrid}) {
        f->setAccessor(mode);
        std::vector<int> got(queries.size());
        tbb::parallel_for(size_t(0), queries.size(), [&](size_t i) {
            got[i] = f->lookup(queries[i].first, queries[i].second);
        });
        EXPECT_EQ(got, reference) << int(mode);
    }
}

TEST(VdbField, UntrainedSamplingMatchesPdf) {
    for (const char* dirs : {"hemi", "sphere"}) {
        auto f = makeVdb(cornerScene(), {{"voxel", "8"}, {"dirs", dirs}});
        ASSERT_TRUE(f);
        for (int region : {0, 1, f->numRegions() / 2, f->numRegions() - 1}) {
            chi2::SphereResult r = sphereTest(*f, region, 100 + uint64_t(region), 400000, kTestsPerCase);
            EXPECT_TRUE(r.passed) << dirs << " region " << region << ": " << r.message;
            EXPECT_NEAR(strataIntegral(*f, region), 1.0, 1e-5) << dirs;
            EXPECT_NEAR(r.pdfIntegral, 1.0, 2e-3) << dirs;
            chi2::Result exact = strataTest(*f, region, 400 + uint64_t(region), 200000);
            EXPECT_TRUE(exact.passed) << dirs << " region " << region << ": " << exact.message;
        }
    }
}

TEST(VdbField, TrainedSamplingMatchesPdfAndFollowsLight) {
    for (const char* dirs : {"hemi", "sphere"}) {
        auto f = makeVdb(planeScene(), {{"voxel", "4"}, {"dirs", dirs}});
        ASSERT_TRUE(f);
        const glm::vec3 bright = glm::normalize(glm::vec3(0.3f, -0.2f, 1.f));
        trainBright(*f, 2, bright, 3, 5);
        const glm::vec3 below = glm::normalize(glm::vec3(-0.6f, 0.5f, -0.6f));
        trainBright(*f, 3, below, 1, 6);
        EXPECT_GT(f->pdf(2, bright), 4.f / (2.f * 3.14159265f)) << dirs;
        EXPECT_GT(f->pdf(3, below), 2.f / (2.f * 3.14159265f)) << dirs;
        for (int region : {2, 3}) {
            chi2::SphereResult r = sphereTest(*f, region, 200 + uint64_t(region), 100000, kTestsPerCase);
            EXPECT_TRUE(r.passed) << dirs << " region " << region << ": " << r.message;
            chi2::Result exact = strataTest(*f, region, 300 + uint64_t(region), 1000000);
            EXPECT_TRUE(exact.passed) << dirs << " region " << region << ": " << exact.message;
            EXPECT_NEAR(r.pdfIntegral, 1.0, 2e-3) << dirs;
            EXPECT_NEAR(strataIntegral(*f, region), 1.0, 1e-5) << dirs;
        }
    }
}

// smooth=K (2 by default): one stratum's records spread to the unvisited strata
// (the root's mean, here the one target value: every estimate is 100 after one pass), for
// hemisphere and full-sphere tables; the policy stays exact. Without it they keep init.
TEST(VdbField, SmoothingSpreadsSparseVisitsAndKeepsThePdfExact) {
    for (const char* dirs : {"hemi", "sphere"}) {
        for (const char* smooth : {"0", "2"}) {
            auto f = makeVdb(planeScene(), {{"voxel", "4"}, {"dirs", dirs}, {"smooth", smooth}});
            ASSERT_TRUE(f);
            const int region = 2;
            const glm::vec3 bright = f->strataCentre(region, 5);
            f->beginPass(1);
            for (int i = 0; i < 8; ++i) f->record(0, region, bright, 100.f);
            f->endPass();
            const glm::vec3 other = f->strataCentre(region, f->strataPerRegion() - 1);
            EXPECT_EQ(f->radiance(region, bright), 100.f) << dirs;
            EXPECT_FLOAT_EQ(f->radiance(region, other), smooth[0] == '0' ? 1e-3f : 100.f)
                << dirs << " smooth " << smooth;
            EXPECT_NEAR(strataIntegral(*f, region), 1.0, 1e-5) << dirs;
            chi2::Result exact = strataTest(*f, region, 800, 400000);
            EXPECT_TRUE(exact.passed) << dirs << " smooth " << smooth << ": " << exact.message;
        }
    }
}

TEST(VdbField, SampleReportsPdfOfItsDirection) {
    for (const char* dirs : {"hemi", "sphere"}) {
        auto f = makeVdb(cornerScene(), {{"voxel", "4"}, {"strata", "32x16"}, {"dirs", dirs}});
        ASSERT_TRUE(f);
        trainBright(*f, 1, glm::normalize(glm::vec3(1, 1, 0.2f)), 2, 9);
        std::mt19937_64 rng(23);
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        for (int i = 0; i < 50000; ++i) {
            float pdf = 0.f;
            glm::vec3 w = f->sample(1, glm::vec2(uni(rng), uni(rng)), uni(rng), &pdf);
            ASSERT_GT(pdf, 0.f);
            ASSERT_NEAR(glm::length(w), 1.f, 1e-5f);
            float again = f->pdf(1, w);
            if (again > 0.f) {
                ASSERT_EQ(pdf, again);
            }
        }
        float pdf = 1.f;
        EXPECT_EQ(f->sample(-1, glm::vec2(0.5f), 0.5f, &pdf), glm::vec3(0.f));
        EXPECT_EQ(pdf, 0.f);
        EXPECT_EQ(f->pdf(f->numRegions(), glm::vec3(0, 0, 1)), 0.f);
    }
}

// learn-cap as hemi's (HemiField.RegionStopsLearningAtTheCap): a surface region stops
// learning once it holds learn-cap x strata records; its Q stays.
TEST(VdbField, RegionStopsLearningAtTheCap) {
    auto f = makeVdb(planeScene(), {{"voxel", "4"}, {"strata", "4"}, {"learn-cap", "1"}});
    ASSERT_TRUE(f);
    const glm::vec3 w = glm::normalize(glm::vec3(0.1f, 0.2f, 1.f));
    const int j = f->stratumOf(0, w);
    ASSERT_GE(j, 0);
    EXPECT_TRUE(f->learns(0));
    for (int n : {8, 7}) {
        f->beginPass(1);
        for (int i = 0; i < n; ++i) f->record(0, 0, w, 2.f);
        f->endPass();
        EXPECT_TRUE(f->learns(0));  // 8, then 15 of 16 records
    }
    f->beginPass(1);
    for (int i = 0; i < 16; ++i) f->record(0, 0, w, 2.f);
    f->endPass();
    EXPECT_FALSE(f->learns(0)) << f->visits(0, j);
    f->beginPass(1);
    for (int i = 0; i < 8; ++i) f->record(0, 0, w, 50.f);
    f->endPass();
    EXPECT_DOUBLE_EQ(f->q(0, j), 2.0);
    EXPECT_EQ(f->visits(0, j), 31u);
    EXPECT_EQ(f->stats().cappedRegions, 1u);
    EXPECT_TRUE(f->learns(1));
    // Nor does it learn a selection (mix=learn) any more; region 1, which learns, does.
    const guiding::SelectionSample sel{1.f, 1.f, 2.f, 0.5f, 1.f};
    f->beginPass(1);
    for (int i = 0; i < 64; ++i) {
        f->recordSelection(0, 0, sel);
        f->recordSelection(0, 1, sel);
    }
    f->endPass();
    EXPECT_EQ(f->selection(0), -1.f);
    EXPECT_GE(f->selection(1), 0.f);
}

// prune as hemi's (HemiField.PruneLeavesEvenRegionsToTheBsdf): a surface region whose
// learned light is even samples the BSDF alone; a concentrated one keeps its guide; never
// with full-sphere tables, nor with prune 0.
TEST(VdbField, PruneLeavesEvenRegionsToTheBsdf) {
    for (const char* prune : {"0", "0.5"}) {
        for (const char* dirs : {"hemi", "sphere"}) {
            SCOPED_TRACE(std::string(prune) + " " + dirs);
            auto f = makeVdb(planeScene(),
                             {{"voxel", "4"}, {"strata", "4"}, {"prune", prune}, {"dirs", dirs}});
            ASSERT_TRUE(f);
            std::mt19937_64 rng(3);
            f->beginPass(1);
            for (int i = 0; i < 4096; ++i) {
                const glm::vec3 w = test::gaussianDirection(rng);
                f->record(0, 0, w, 1.f);
                const float c = glm::dot(w, f->regionFrame(1).n);
                f->record(0, 1, w, c > 0.9f ? 100.f : 1.f);
            }
            f->endPass();
            const bool pruned = std::string(prune) != "0" && std::string(dirs) == "hemi";
            EXPECT_EQ(f->guides(0), !pruned);
            EXPECT_TRUE(f->guides(1));
            EXPECT_EQ(f->stats().prunedRegions, uint64_t(pruned));
            EXPECT_FALSE(f->guides(-1));
        }
    }
}

TEST(VdbField, RunningMeanAndEstimates) {
    auto f = makeVdb(planeScene(), {{"voxel", "4"}});
    ASSERT_TRUE(f);
    const glm::vec3 w = glm::normalize(glm::vec3(0.1f, 0.2f, 1.f));
    const int j = f->stratumOf(0, w);
    ASSERT_GE(j, 0);
    const float targets[] = {1.f, 3.f, 8.f};
    for (float t : targets) {
        f->beginPass(2);
        f->record(1, 0, w, t);
        f->record(0, 0, w, t);
        f->record(0, 0, w, NAN);       // rejected target
        f->record(0, 0, -w, 1.f);      // below the hemisphere: rejected record
        f->record(5, 0, w, 1.f);       // no such slot: ignored
        f->endPass();
    }
    EXPECT_DOUBLE_EQ(f->q(0, j), 4.0);
    EXPECT_EQ(f->visits(0, j), 6u);
    EXPECT_FLOAT_EQ(f->radiance(0, w), 4.f);
    EXPECT_EQ(f->radiance(0, -w), 0.f);
    GuidingStats s = f->stats();
    EXPECT_EQ(s.passes, 3u);
    EXPECT_EQ(s.records, 6u);
    EXPECT_EQ(s.rejectedTargets, 3u);
    EXPECT_EQ(s.rejectedRecords, 3u);
    // Irradiance estimate = scattered estimate with fcos = max(0, n.w).
    for (const glm::vec3& n : {glm::vec3(0, 0, 1), glm::normalize(glm::vec3(1, 0, 1))}) {
        float viaF = f->scatteredEstimate(0, [&](const glm::vec3& d) {
            return std::max(0.f, glm::dot(d, n));
        });
        EXPECT_NEAR(f->irradianceEstimate(0, n), viaF, 1e-5f * viaF);
    }
    EXPECT_EQ(f->scatteredEstimate(-1, [](const glm::vec3&) { return 1.f; }), 0.f);
}

TEST(VdbField, DeterministicMergeAcrossThreadSchedules) {
    const int slots = 16;
    auto run = [&](int schedule) {
        auto f = makeVdb(planeScene(), {{"voxel", "8"}});
        for (uint64_t pass = 0; pass < 3; ++pass) {
            std::vector<std::vector<std::tuple<int, glm::vec3, float>>> recs(slots);
            for (int s = 0; s < slots; ++s) {
                std::mt19937_64 rng(pass * 1000 + uint64_t(s));
                std::uniform_int_distribution<int> reg(0, f->numRegions() - 1);
                std::exponential_distribution<float> ex(0.1f);
                for (int i = 0; i < 3000; ++i)
                    recs[size_t(s)].emplace_back(reg(rng), gaussianDirection(rng), ex(rng));
            }
            f->beginPass(slots);
            auto feed = [&](int s) {
                for (const auto& [r, w, t] : recs[size_t(s)]) f->record(s, r, w, t);
            };
            test::feedSlots(slots, schedule, feed);
            f->endPass();
        }
        return f;
    };
    auto a = run(0), b = run(1), c = run(2), d = run(4);
    for (const auto* o : {b.get(), c.get(), d.get()}) test::expectSameTables(*a, *o);
    EXPECT_GT(a->stats().records, 0u);
}

// Trains every region of a field a little, so that saved tables differ from the initial ones.
void trainAll(GuidingField& f, int regions, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::exponential_distribution<float> ex(0.5f);
    f.beginPass(1);
    for (int r = 0; r < regions; ++r)
        for (int i = 0; i < 40; ++i) f.record(0, r, gaussianDirection(rng), ex(rng));
    f.endPass();
}

template <class Field>
void expectSamePolicy(const Field& a, const Field& b) {
    ASSERT_EQ(a.numRegions(), b.numRegions());
    test::expectSameTables(a, b);
    std::mt19937_64 rng(77);
    std::uniform_int_distribution<int> reg(0, a.numRegions() - 1);
    for (int i = 0; i < 20000; ++i) {
        int r = reg(rng);
        glm::vec3 w = gaussianDirection(rng);
        ASSERT_EQ(a.pdf(r, w), b.pdf(r, w));
    }
    EXPECT_EQ(a.stats().passes, b.stats().passes);
    EXPECT_EQ(a.stats().records, b.stats().records);
}

TEST(VdbField, SaveLoadRoundTrip) {
    for (const char* dirs : {"hemi", "sphere"}) {
        auto a = makeVdb(cornerScene(), {{"voxel", "16"}, {"dirs", dirs}});
        ASSERT_TRUE(a);
        trainAll(*a, a->numRegions(), 1);
        trainAll(*a, a->numRegions(), 2);
        const std::string path = tempPath(std::string("roundtrip_") + dirs + ".vdb");
        std::string error;
        ASSERT_TRUE(a->save(path, &error)) << error;
        auto b = makeVdb(cornerScene(), {{"voxel", "16"}, {"dirs", dirs}});
        ASSERT_TRUE(b);
        EXPECT_NE(a->qTable(), b->qTable());  // untrained
        ASSERT_TRUE(b->load(path, &error)) << error;
        expectSamePolicy(*a, *b);
        EXPECT_EQ(a->activeVoxels(), b->activeVoxels());
        // The loaded grid maps points to the same regions.
        std::mt19937_64 rng(5);
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        for (int i = 0; i < 2000; ++i) {
            glm::vec3 p(uni(rng), uni(rng), 0.f), n = gaussianDirection(rng);
            ASSERT_EQ(a->lookup(p, n), b->lookup(p, n));
        }
        // Saving the loaded field gives a loadable file again, and learning continues.
        ASSERT_TRUE(b->save(path, &error)) << error;
        auto c = makeVdb(cornerScene(), {{"voxel", "16"}, {"dirs", dirs}});
        ASSERT_TRUE(c->load(path, &error)) << error;
        expectSamePolicy(*a, *c);
        trainAll(*a, a->numRegions(), 3);
        trainAll(*c, c->numRegions(), 3);
        expectSamePolicy(*a, *c);
        std::remove(path.c_str());
    }
}

TEST(VdbField, LoadRejectsOtherScenesBackendsAndStructures) {
    auto a = makeVdb(cornerScene(), {{"voxel", "16"}});
    ASSERT_TRUE(a);
    trainAll(*a, a->numRegions(), 1);
    const std::string path = tempPath("mismatch.vdb");
    std::string error;
    ASSERT_TRUE(a->save(path, &error)) << error;

    auto expectFail = [&](GuidingField& f, const char* what, const std::string& file) {
        const std::vector<float> before = [&] {
            auto* v = dynamic_cast<VdbField*>(&f);
            return v ? v->cdfTable() : std::vector<float>();
        }();
        std::string err;
        EXPECT_FALSE(f.load(file, &err)) << what;
        EXPECT_NE(err.find(what), std::string::npos) << err;
        if (auto* v = dynamic_cast<VdbField*>(&f)) {
            EXPECT_EQ(v->cdfTable(), before);
        }
    };
    // Another scene (bounds differ), same parameters.
    auto other = makeVdb(planeScene(), {{"voxel", "16"}});
    expectFail(*other, "another scene", path);
    // Same bounds, another total area.
    SceneInfo moreArea = cornerScene();
    moreArea.totalArea = 2.5;
    auto area = makeVdb(moreArea, {{"voxel", "16"}});
    expectFail(*area, "surface area", path);
    // Another voxel size, strata or table layout.
    auto coarse = makeVdb(cornerScene(), {{"voxel", "8"}});
    expectFail(*coarse, "voxel size", path);
    auto strata = makeVdb(cornerScene(), {{"voxel", "16"}, {"strata", "4"}});
    expectFail(*strata, "strata", path);
    auto sphere = makeVdb(cornerScene(), {{"voxel", "16"}, {"dirs", "sphere"}});
    expectFail(*sphere, "dirs", path);
    // Another backend's file, either way round.
    GuideConfig hc;
    hc.backend = "hemi";
    hc.params = {{"points", "256"}};
    auto hemi = createGuidingField(hc, cornerScene(), &error);
    ASSERT_TRUE(hemi) << error;
    expectFail(*hemi, "'vdb' guiding field", path);
    const std::string hemiPath = tempPath("mismatch.hemi");
    ASSERT_TRUE(hemi->save(hemiPath, &error)) << error;
    expectFail(*a, "'hemi' guiding field", hemiPath);
    // Not a field at all; missing file.
    const std::string junk = tempPath("junk.bin");
    std::ofstream(junk) << "hello, not a field";
    expectFail(*a, "not a saved guiding field", junk);
    expectFail(*a, "not a saved guiding field", tempPath("does_not_exist.vdb"));
    std::remove(path.c_str());
    std::remove(hemiPath.c_str());
    std::remove(junk.c_str());
}

TEST(HemiField, SaveLoadRoundTripAndMismatch) {
    auto make = [](const SceneInfo& s, std::map<std::string, std::string> p) {
        GuideConfig c;
        c.backend = "hemi";
        c.params = std::move(p);
        std::string e;
        auto f = createGuidingField(c, s, &e);
        EXPECT_TRUE(f) << e;
        return std::unique_ptr<HemiField>(dynamic_cast<HemiField*>(f.release()));
    };
    auto a = make(cornerScene(), {{"points", "512"}});
    trainAll(*a, a->numRegions(), 1);
    trainAll(*a, a->numRegions(), 2);
    const std::string path = tempPath("roundtrip.hemi");
    std::string error;
    ASSERT_TRUE(a->save(path, &error)) << error;
    auto b = make(cornerScene(), {{"points", "512"}});
    ASSERT_TRUE(b->load(path, &error)) << error;
    expectSamePolicy(*a, *b);
    auto otherScene = make(planeScene(), {{"points", "512"}});
    EXPECT_FALSE(otherScene->load(path, &error));
    EXPECT_NE(error.find("another scene"), std::string::npos) << error;
    auto otherPoints = make(cornerScene(), {{"points", "256"}});
    EXPECT_FALSE(otherPoints->load(path, &error));
    EXPECT_NE(error.find("points"), std::string::npos) << error;
    auto otherStrata = make(cornerScene(), {{"points", "512"}, {"strata", "4"}});
    EXPECT_FALSE(otherStrata->load(path, &error));
    EXPECT_NE(error.find("strata"), std::string::npos) << error;
    // A truncated file is an error, not a crash.
    std::string data;
    {
        std::ifstream in(path, std::ios::binary);
        data.assign(std::istreambuf_iterator<char>(in), {});
    }
    const std::string cut = tempPath("truncated.hemi");
    std::ofstream(cut, std::ios::binary).write(data.data(), std::streamsize(data.size() / 2));
    EXPECT_FALSE(b->load(cut, &error));
    EXPECT_FALSE(error.empty());
    expectSamePolicy(*a, *b);  // unchanged by the failed load
    std::remove(path.c_str());
    std::remove(cut.c_str());
}

}  // namespace
}  // namespace rlpbrt::guiding
