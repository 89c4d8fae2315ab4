// Tests of the guiding interface and the `hemi` backend: factory, lookup, sampling vs pdf
// (chi-square), normalisation, learning (running mean, fixed alpha), hazards (rejected
// targets, extreme parameters) and determinism across thread schedules.
#include "guiding/guiding.h"
#include "guiding/hemi.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
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

std::unique_ptr<HemiField> makeHemi(const SceneInfo& scene,
                                    std::map<std::string, std::string> params = {}) {
    return test::makeField<HemiField>("hemi", scene, std::move(params));
}

// World direction of stratum j's centre in a region.
glm::vec3 strataCentre(const HemiField& f, int region, int j) {
    return Frame::fromZ(f.regionNormal(region)).toWorld(f.layout().centre(j));
}

// Sum over strata of pdf(centre) * stratum solid angle: the pdf's integral over the sphere
// (exact because the pdf is constant per stratum and zero outside the hemisphere).
double strataIntegral(const HemiField& f, int region) {
    double sum = 0.0;
    for (int j = 0; j < f.layout().count(); ++j)
        sum += double(f.pdf(region, strataCentre(f, region, j))) * f.layout().stratumSolidAngle();
    return sum;
}

// Exact chi-square in the region's strata: each stratum split into 2x2 equal-area sub-cells
// (halves in cos(theta) and in phi) whose expected count is N * P_j / 4, P_j from pdf().
chi2::Result strataTest(const HemiField& f, int region, uint64_t seed, int samples) {
    const StrataLayout& layout = f.layout();
    const int n = layout.count();
    const Frame frame = Frame::fromZ(f.regionNormal(region));
    std::vector<double> observed(size_t(4 * n + 1), 0.0), expected(size_t(4 * n + 1), 0.0);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    for (int i = 0; i < samples; ++i) {
        float pdf = 0.f;
        glm::vec3 w = f.sample(region, glm::vec2(uni(rng), uni(rng)), uni(rng), &pdf);
        glm::vec3 local = frame.toLocal(w);
        int j = layout.stratumOf(local);
        if (j < 0) {
            observed.back() += 1.0;
            continue;
        }
        int row = j / layout.cols(), col = j % layout.cols();
        float phi = std::atan2(local.y, local.x);
        if (phi < 0.f) phi += 2.f * 3.14159265f;
        int a = local.z * layout.rows() - row >= 0.5f ? 1 : 0;
        int b = phi / (2.f * 3.14159265f) * layout.cols() - col >= 0.5f ? 1 : 0;
        observed[size_t(4 * j + 2 * a + b)] += 1.0;
    }
    for (int j = 0; j < n; ++j) {
        double pj = double(f.pdf(region, strataCentre(f, region, j))) * layout.stratumSolidAngle();
        for (int k = 0; k < 4; ++k) expected[size_t(4 * j + k)] = samples * pj / 4.0;
    }
    return chi2::testCounts(observed, expected);
}

TEST(GuidingFactory, NoneAndErrors) {
    std::string error = "stale";
    GuideConfig none;
    EXPECT_EQ(createGuidingField(none, planeScene(), &error), nullptr);
    EXPECT_TRUE(error.empty());

    GuideConfig unknown;
    unknown.backend = "octree";
    EXPECT_EQ(createGuidingField(unknown, planeScene(), &error), nullptr);
    EXPECT_NE(error.find("octree"), std::string::npos) << error;

    const std::vector<std::pair<std::string, std::string>> bad = {
        {"alpha", "0"},          {"alpha", "1.5"},      {"alpha", "-0.1"},
        {"alpha", "abc"},        {"alpha", "nan"},      {"alpha", ""},
        {"strata", "0x8"},       {"strata", "65x1"},    {"strata", "8x"},
        {"strata", "x8"},        {"strata", "8x8x8"},   {"strata", "8.5x8"},
        {"strata", "-8x8"},      {"points", "0"},       {"points", "-1"},
        {"points", "1e3"},       {"points", "67108865"}, {"points", "99999999999999999999"},
        {"normal-angle", "0"},   {"normal-angle", "180"}, {"normal-angle", "inf"},
        {"init", "0"},           {"init", "-1"},        {"init", "inf"},
        {"init", "1e39"},        {"init", "1e400"},     {"epsilon", "1.5"},
        {"epsilon", "-0.1"},     {"knn", "0"},          {"knn", "65"},
        {"max-mb", "0"},         {"colour", "red"},     {"learn-cap", "-1"},
        {"learn-cap", "x"},      {"learn-cap", "2e9"},
    };
    for (const auto& [key, value] : bad) {
        GuideConfig cfg;
        cfg.backend = "hemi";
        cfg.params[key] = value;
        error.clear();
        EXPECT_EQ(createGuidingField(cfg, planeScene(), &error), nullptr) << key << "=" << value;
        EXPECT_FALSE(error.empty()) << key << "=" << value;
        EXPECT_NE(error.find(key), std::string::npos) << error;
    }

    // Memory guard: refused before anything is allocated.
    GuideConfig huge;
    huge.backend = "hemi";
    huge.params = {{"strata", "64x64"}, {"points", "67108864"}};
    EXPECT_EQ(createGuidingField(huge, planeScene(), &error), nullptr);
    EXPECT_NE(error.find("MiB"), std::string::npos) << error;

    // No surface sampler.
    GuideConfig hemi;
    hemi.backend = "hemi";
    EXPECT_EQ(createGuidingField(hemi, SceneInfo{}, &error), nullptr);
    EXPECT_FALSE(error.empty());

    // Valid values, "mix" is accepted and ignored, "N" means NxN.
    hemi.params = {{"alpha", "0.25"}, {"strata", "4"}, {"points", "100"}, {"mix", "0.5"},
                   {"normal-angle", "45"}, {"init", "2"}, {"epsilon", "0"}, {"knn", "16"},
                   {"max-mb", "10"}};
    auto f = createGuidingField(hemi, planeScene(), &error);
    ASSERT_TRUE(f) << error;
    auto* h = dynamic_cast<HemiField*>(f.get());
    ASSERT_TRUE(h);
    EXPECT_FALSE(h->params().alphaVisits);
    EXPECT_EQ(h->params().fixedAlpha, 0.25);
    EXPECT_EQ(h->layout().cols(), 4);
    EXPECT_EQ(h->layout().rows(), 4);
    EXPECT_EQ(h->numRegions(), 200);
    EXPECT_EQ(h->params().knn, 16);
    EXPECT_EQ(h->q(5, 3), 2.0);
    EXPECT_NE(f->describe().find("4x4"), std::string::npos) << f->describe();
}

TEST(HemiField, DefaultsAndMemory) {
    auto f = makeHemi(planeScene());
    ASSERT_TRUE(f);
    EXPECT_EQ(f->numRegions(), 2 * 1024);
    EXPECT_EQ(f->layout().count(), 256);  // 16x16
    EXPECT_TRUE(f->params().patchLookup);
    EXPECT_TRUE(f->params().alphaVisits);
    EXPECT_EQ(f->params().warmup, 8.0);
    EXPECT_EQ(f->params().smooth, 2.0);
    // Untrained, every region has its frame (one cache line) and block index, and all share
    // one block of tables: Q (double), estimates (float), visits (uint64), CDF (257 floats).
    // The spot lobes (on by default) hold per region only their share, two counts and a
    // block index until a region finds a spot.
    const size_t block = 256 * 20 + 257 * 4;
    ASSERT_NE(f->spots(), nullptr);
    EXPECT_EQ(f->spots()->settings().perRegion, 4);
    const size_t perRegion = size_t(f->numRegions()) * (64 + 4 + 10);
    EXPECT_GE(f->bytes(), perRegion + block);
    // Points, tree and the lookup's cell memo: 8192 entries of one cache line.
    ASSERT_NE(f->cellCache(), nullptr);
    EXPECT_EQ(f->cellCache()->bytes(), 1024u * 8u * 64u);
    EXPECT_LE(f->bytes(), perRegion + block + 1024 * 64 + f->cellCache()->bytes());
    EXPECT_EQ(f->learnedRegions(), 0u);
    EXPECT_FALSE(f->describe().empty());
    // Record buffers are scratch, reported apart from the learned data.
    const size_t before = f->bytes();
    f->beginPass(4);
    for (int i = 0; i < 1000; ++i) f->record(i % 4, 0, glm::vec3(0, 0, 1), 1.f);
    EXPECT_EQ(f->bytes(), before);
    EXPECT_GE(f->scratchBytes(), 1000u * 12u);
    f->endPass();
    // The region that learned has tables of its own now: exactly one block more.
    EXPECT_EQ(f->learnedRegions(), 1u);
    EXPECT_EQ(f->bytes(), before + block);
    // Every region learned: within the estimate that max-mb checks.
    f->beginPass(1);
    for (int r = 0; r < f->numRegions(); ++r) f->record(0, r, f->regionNormal(r), 1.f);
    f->endPass();
    EXPECT_EQ(f->learnedRegions(), size_t(f->numRegions()));
    EXPECT_GE(f->bytes(), perRegion + size_t(f->numRegions()) * block);
    EXPECT_LE(double(f->bytes()), 1.05 * hemiEstimatedBytes(f->params()));
}

TEST(HemiField, LookupOnPlaneSidesAndAngle) {
    auto f = makeHemi(planeScene(), {{"points", "1024"}});
    ASSERT_TRUE(f);
    glm::vec3 p(0.3f, 0.6f, 0.f);
    int up = f->lookup(p, glm::vec3(0, 0, 1));
    int down = f->lookup(p, glm::vec3(0, 0, -1));
    ASSERT_GE(up, 0);
    ASSERT_GE(down, 0);
    EXPECT_EQ(up % 2, 0);
    EXPECT_EQ(down, up + 1);  // same point, the other side
    EXPECT_EQ(f->regionNormal(up), glm::vec3(0, 0, 1));
    EXPECT_EQ(f->regionNormal(down), glm::vec3(0, 0, -1));
    // Surfaces only: no region in a medium, and the integrator is told so.
    EXPECT_EQ(f->lookupMedium(p), -1);
    EXPECT_FALSE(f->guidesMedia());
    // The nearest point by brute force.
    float best = FLT_MAX;
    int bestRegion = -1;
    for (int r = 0; r < f->numRegions(); r += 2) {
        glm::vec3 d = f->regionPosition(r) - p;
        float d2 = glm::dot(d, d);
        if (d2 < best) best = d2, bestRegion = r;
    }
    EXPECT_EQ(up, bestRegion);
    // Tilted normals: 29 degrees is admissible, 31 is not (default 30).
    auto tilted = [](float deg) {
        float a = deg * 3.14159265f / 180.f;
        return glm::vec3(std::sin(a), 0.f, std::cos(a));
    };
    EXPECT_EQ(f->lookup(p, tilted(29.f)), up);
    EXPECT_EQ(f->lookup(p, tilted(31.f)), -1);
    EXPECT_EQ(f->lookup(p, -tilted(29.f)), down);
    EXPECT_EQ(f->lookup(p, glm::vec3(1, 0, 0)), -1);
    EXPECT_EQ(f->lookup(glm::vec3(NAN, 0, 0), glm::vec3(0, 0, 1)), -1);
    EXPECT_EQ(f->lookup(p, glm::vec3(0.f)), -1);
}

// Brute force: the region of the first point, among the knn points nearest to `from`, whose
// normal is within 30 degrees of +-n (the hemisphere on n's side), or -1.
int firstAdmissibleNear(const HemiField& f, const glm::vec3& from, const glm::vec3& n, int knn) {
    const float cosMax = std::cos(30.f * 3.14159265f / 180.f);
    std::vector<std::pair<float, int>> byDist;
    for (int i = 0; i < f.numRegions() / 2; ++i) {
        const glm::vec3 d = f.regionPosition(2 * i) - from;
        byDist.emplace_back(glm::dot(d, d), i);
    }
    std::sort(byDist.begin(), byDist.end());
    for (int k = 0; k < knn && k < int(byDist.size()); ++k) {
        const float c = glm::dot(n, f.regionNormal(2 * byDist[size_t(k)].second));
        if (std::abs(c) >= cosMax) return 2 * byDist[size_t(k)].second + (c >= 0.f ? 0 : 1);
    }
    return -1;
}

TEST(HemiField, LookupReturnsNearestAdmissibleAmongKNearest) {
    for (int knn : {1, 8, 64}) {
        auto f = makeHemi(cornerScene(), {{"points", "2000"}, {"knn", std::to_string(knn)},
                                          {"lookup", "exact"}});
        ASSERT_TRUE(f);
        const float cosMax = std::cos(30.f * 3.14159265f / 180.f);
        std::mt19937_64 rng(17);
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        int found = 0;
        for (int q = 0; q < 500; ++q) {
            glm::vec3 p(uni(rng) * 0.2f, uni(rng), uni(rng) * 0.2f);  // near the corner
            glm::vec3 n = gaussianDirection(rng);
            const int expected = firstAdmissibleNear(*f, p, n, knn);
            int got = f->lookup(p, n);
            EXPECT_EQ(got, expected) << "knn " << knn << " query " << q;
            if (got >= 0) {
                ++found;
                float c = glm::dot(n, f->regionNormal(got));
                EXPECT_GE(c, cosMax - 1e-6f);
            }
        }
        EXPECT_GT(found, 20);  // about 13% (knn 1) to 27% of random normals are admissible
    }
}

// lookup=cell: the first admissible of the k points nearest to the centre of the query's cell,
// whatever order the cells were filled in (and with knn above the memo's entry size, exact).
TEST(HemiField, CellLookupTakesTheFirstAdmissibleNearTheCellCentre) {
    for (int knn : {1, 8, 13, 20}) {
        auto f = makeHemi(cornerScene(), {{"points", "2000"}, {"knn", std::to_string(knn)}});
        ASSERT_TRUE(f);
        const CellCache* cache = f->cellCache();
        ASSERT_EQ(cache != nullptr, knn <= CellCache::kMaxCandidates);
        std::mt19937_64 rng(23);
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        int found = 0;
        for (int q = 0; q < 600; ++q) {
            // Each query twice: the first may fill its cell, the second reads the memo.
            glm::vec3 p(uni(rng) * 0.2f, uni(rng), uni(rng) * 0.2f);
            const glm::vec3 n = gaussianDirection(rng);
            const int expected =
                firstAdmissibleNear(*f, cache ? cache->centreOf(p) : p, n, knn);
            EXPECT_EQ(f->lookup(p, n), expected) << "knn " << knn << " query " << q;
            EXPECT_EQ(f->lookup(p, n), expected) << "knn " << knn << " query " << q << " again";
            found += expected >= 0;
        }
        EXPECT_GT(found, 20);
        if (cache) {
            EXPECT_GT(cache->size(), 10u);
            EXPECT_LE(cache->size(), 600u);
        }
    }
}

// lookup=patch: a patch answers with the first of the knn points nearest to its centre whose
// normal is within the admissible angle of the patch's normal (memoised per patch), on the
// query normal's side, when that point is admissible for the query normal too; otherwise,
// and for kNoPatch or keys past the patches, the cell lookup answers. Here the patches are a
// 10x10 grid over the corner's floor and another over its wall.
TEST(HemiField, PatchLookupTakesThePatchCentresAdmissiblePoint) {
    auto f = makeHemi(cornerScene(), {{"points", "2000"}});
    ASSERT_TRUE(f);
    EXPECT_NEAR(f->patchSize(), std::sqrt(2.0 / 2000.0), 1e-6);
    auto centreOf = [](uint32_t i, glm::vec3* p, glm::vec3* n) {
        if (i >= 200) return false;
        const float a = (float(i % 100 / 10) + 0.5f) / 10.f, b = (float(i % 10) + 0.5f) / 10.f;
        *p = i < 100 ? glm::vec3(a, b, 0.f) : glm::vec3(0.f, b, a);
        // The floor's normal given downwards: the orientation must not matter.
        *n = i < 100 ? glm::vec3(0.f, 0.f, -1.f) : glm::vec3(1.f, 0.f, 0.f);
        return true;
    };
    f->setPatches(200, centreOf);
    ASSERT_EQ(f->numPatches(), 200u);
    const float cosMax = std::cos(30.f * 3.14159265f / 180.f);
    std::mt19937_64 rng(29);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    int viaPatch = 0, viaCell = 0;
    for (int q = 0; q < 800; ++q) {
        const uint32_t patch = uint32_t(q % 200);
        glm::vec3 c, pn;
        ASSERT_TRUE(centreOf(patch, &c, &pn));
        // A query on the patch, with a normal near the patch's (either side) or anywhere.
        glm::vec3 p = c + glm::vec3(uni(rng) - 0.5f, uni(rng) - 0.5f, uni(rng) - 0.5f) * 0.05f;
        glm::vec3 n = q % 4 == 3 ? gaussianDirection(rng)
                                 : glm::normalize((q % 2 ? -pn : pn) + 0.3f * gaussianDirection(rng));
        const int point = firstAdmissibleNear(*f, c, pn, 8);  // region on pn's side
        int expected = -1;
        if (point >= 0) {
            const float cq = glm::dot(n, f->regionNormal(point & ~1));
            if (std::abs(cq) >= cosMax) expected = (point & ~1) + (cq >= 0.f ? 0 : 1);
        }
        const int cell = f->lookup(p, n);
        if (expected >= 0) {
            ++viaPatch;
        } else {
            expected = cell;
            ++viaCell;
        }
        EXPECT_EQ(f->lookupPatch(patch, p, n), expected) << "query " << q;
        EXPECT_EQ(f->lookupPatch(patch, p, n), expected) << "query " << q << " again";
        EXPECT_EQ(f->patchPoint(patch), point < 0 ? -1 : point / 2) << "query " << q;
        EXPECT_EQ(f->lookupPatch(GuidingField::kNoPatch, p, n), cell);
        EXPECT_EQ(f->lookupPatch(200, p, n), cell);
    }
    EXPECT_GT(viaPatch, 400);
    EXPECT_GT(viaCell, 50);
    // Other lookups want no patches.
    EXPECT_EQ(makeHemi(cornerScene(), {{"lookup", "cell"}})->patchSize(), 0.f);
    EXPECT_EQ(makeHemi(cornerScene(), {{"lookup", "exact"}})->patchSize(), 0.f);
    auto cellOnly = makeHemi(cornerScene(), {{"lookup", "cell"}});
    cellOnly->setPatches(200, centreOf);
    EXPECT_EQ(cellOnly->numPatches(), 0u);
}

// A patch whose centre function fails, or gives no usable normal, has no point: the cell
// lookup answers for it.
TEST(HemiField, PatchWithoutCentreFallsBackToTheCellLookup) {
    auto f = makeHemi(cornerScene(), {{"points", "500"}});
    ASSERT_TRUE(f);
    f->setPatches(3, [](uint32_t i, glm::vec3* p, glm::vec3* n) {
        *p = glm::vec3(0.5f, 0.5f, 0.f);
        *n = i == 1 ? glm::vec3(0.f) : glm::vec3(std::nanf(""), 0.f, 1.f);
        return i != 0;
    });
    const glm::vec3 p(0.5f, 0.5f, 0.f), n(0.f, 0.f, 1.f);
    for (uint32_t i = 0; i < 3; ++i) {
        EXPECT_EQ(f->lookupPatch(i, p, n), f->lookup(p, n));
        EXPECT_EQ(f->patchPoint(i), -1);
    }
    EXPECT_GE(f->lookup(p, n), 0);
}

TEST(HemiField, LookupNearCornerPicksFloorOrWallByNormal) {
    auto f = makeHemi(cornerScene(), {{"points", "4000"}});
    ASSERT_TRUE(f);
    glm::vec3 p(0.01f, 0.5f, 0.01f);
    int floor = f->lookup(p, glm::vec3(0, 0, 1));
    int wall = f->lookup(p, glm::vec3(1, 0, 0));
    ASSERT_GE(floor, 0);
    ASSERT_GE(wall, 0);
    EXPECT_EQ(f->regionNormal(floor), glm::vec3(0, 0, 1));
    EXPECT_EQ(f->regionNormal(wall), glm::vec3(1, 0, 0));
    EXPECT_EQ(f->regionPosition(floor).z, 0.f);
    EXPECT_EQ(f->regionPosition(wall).x, 0.f);
    // 45 degrees between both: neither is admissible at 30 degrees.
    EXPECT_EQ(f->lookup(p, glm::normalize(glm::vec3(1, 0, 1))), -1);
}

// With the cosine product (the default) the untrained policy is cosine-weighted per stratum:
// still sampled exactly by its pdf, integrating to one, denser at the normal than at grazing
// angles (ratio of the stratum-centre cosines, up to the epsilon floor).
TEST(HemiField, CosineProductPolicyMatchesPdf) {
    auto f = makeHemi(cornerScene(), {{"points", "64"}});
    ASSERT_TRUE(f);
    for (int region : {0, 1, 63, 100}) {
        chi2::SphereResult r = sphereTest(*f, region, 900 + uint64_t(region));
        EXPECT_TRUE(r.passed) << "region " << region << ": " << r.message;
        EXPECT_NEAR(strataIntegral(*f, region), 1.0, 1e-5);
        chi2::Result exact = strataTest(*f, region, 950 + uint64_t(region), 200000);
        EXPECT_TRUE(exact.passed) << "region " << region << ": " << exact.message;
        glm::vec3 n = f->regionNormal(region);
        glm::vec3 t = glm::normalize(glm::cross(n, std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0)
                                                                        : glm::vec3(0, 1, 0)));
        float top = f->pdf(region, n), grazing = f->pdf(region, glm::normalize(t + 0.02f * n));
        EXPECT_GT(top, 1.0f / (2.0f * float(PiDouble)));
        EXPECT_GT(top, 4.f * grazing);
    }
}

TEST(HemiField, UntrainedSamplingMatchesPdf) {
    auto f = makeHemi(cornerScene(), {{"points", "64"}, {"cosine", "0"}});
    ASSERT_TRUE(f);
    for (int region : {0, 1, 63, 100}) {
        chi2::SphereResult r = sphereTest(*f, region, 100 + uint64_t(region));
        EXPECT_TRUE(r.passed) << "region " << region << ": " << r.message;
        // The untrained policy is uniform over the region's hemisphere.
        EXPECT_NEAR(f->pdf(region, f->regionNormal(region)), 1.0 / (2.0 * PiDouble), 1e-6);
        EXPECT_EQ(f->pdf(region, -f->regionNormal(region)), 0.f);
        EXPECT_NEAR(strataIntegral(*f, region), 1.0, 1e-5);
        chi2::Result exact = strataTest(*f, region, 400 + uint64_t(region), 200000);
        EXPECT_TRUE(exact.passed) << "region " << region << ": " << exact.message;
    }
}

// Hierarchical smoothing (smooth=K): 8 records of 100 in one stratum and 8 of 0 in a distant
// one, none elsewhere. Without smoothing the other strata keep init. With it, the root takes
// the mean of all targets (50) and every node below it the mean of the targets under it,
// shrunk towards its parent: the unvisited sibling in the bright stratum's 2x2 block gets
// nearly its block's mean, a stratum in an unvisited quarter of the hemisphere the root's
// mean, and the dark stratum stays near 0. The smoothed policy is sampled exactly by its pdf.
TEST(HemiField, SmoothingSpreadsSparseVisitsAndKeepsThePdfExact) {
    for (const char* smooth : {"0", "2"}) {
        auto f = makeHemi(planeScene(),
                          {{"points", "16"}, {"strata", "16x16"}, {"smooth", smooth}});
        ASSERT_TRUE(f);
        const int region = 4;
        const int bright = 5 * 16 + 6;  // row 5, column 6: its 2x2 block holds columns 6, 7
        const int sibling = 5 * 16 + 7, far = 5 * 16 + 14, dark = 12 * 16 + 2;
        auto at = [&](int j) { return f->radiance(region, strataCentre(*f, region, j)); };
        f->beginPass(1);
        for (int i = 0; i < 8; ++i) {
            f->record(0, region, strataCentre(*f, region, bright), 100.f);
            f->record(0, region, strataCentre(*f, region, dark), 0.f);
        }
        f->endPass();
        ASSERT_EQ(f->stratumOf(region, strataCentre(*f, region, bright)), bright);
        if (std::string(smooth) == "0") {
            EXPECT_EQ(at(bright), 100.f);
            EXPECT_EQ(at(dark), 0.f);
            EXPECT_EQ(at(sibling), 1e-3f);
            EXPECT_EQ(at(far), 1e-3f);
            continue;
        }
        // Prior 2: the root 800 / 16; each node on the way down (S + 2 parent) / (N + 2),
        // with S, N = 800, 8 on the bright stratum's path and 0, 8 on the dark one's.
        const double root = 800.0 / 16.0;
        double up = root, down = root;
        for (int level = 0; level < 3; ++level) {  // the 2x2, 4x4 and 8x8 nodes
            up = (800.0 + 2.0 * up) / 10.0;
            down = (0.0 + 2.0 * down) / 10.0;
        }
        EXPECT_NEAR(at(far), root, 1e-5 * root);
        EXPECT_NEAR(at(sibling), up, 1e-5 * up);
        EXPECT_NEAR(at(bright), (800.0 + 2.0 * up) / 10.0, 1e-5 * up);
        EXPECT_NEAR(at(dark), (2.0 * down) / 10.0, 1e-5 * up);
        EXPECT_GT(at(bright), at(sibling));
        EXPECT_GT(at(sibling), at(far));
        EXPECT_GT(at(far), 100.f * at(dark));
        EXPECT_GT(f->pdf(region, strataCentre(*f, region, sibling)),
                  f->pdf(region, strataCentre(*f, region, far)));
        EXPECT_NEAR(strataIntegral(*f, region), 1.0, 1e-5);
        chi2::Result exact = strataTest(*f, region, 700, 1000000);
        EXPECT_TRUE(exact.passed) << exact.message;
        chi2::SphereResult r = sphereTest(*f, region, 701, 100000);
        EXPECT_TRUE(r.passed) << r.message;
    }
}

// learn-cap: a region stops learning (from the next pass on) once it holds learn-cap x strata
// records, keeps its guide, and ignores its records; the others go on; 0 never stops.
TEST(HemiField, RegionStopsLearningAtTheCap) {
    EXPECT_EQ(makeHemi(planeScene())->params().learnCap, 256.0);
    // (judge=0: these even lights would stop direction learning, HemiField.Judge...)
    auto f = makeHemi(planeScene(), {{"learn-cap", "2"}, {"judge", "0"}});  // 512 records
    ASSERT_TRUE(f);
    const int r = 0;
    const glm::vec3 n = f->regionNormal(r);
    const glm::vec3 side = glm::normalize(n + 0.8f * Frame::fromZ(n).s);
    EXPECT_TRUE(f->learns(r));
    f->beginPass(2);
    for (int i = 0; i < 511; ++i) f->record(i % 2, r, n, 1.f);
    f->endPass();
    EXPECT_TRUE(f->learns(r));  // 511 < 512
    EXPECT_EQ(f->stats().cappedRegions, 0u);
    f->beginPass(1);
    f->record(0, r, n, 1.f);
    f->endPass();
    EXPECT_FALSE(f->learns(r));
    EXPECT_EQ(f->stats().cappedRegions, 1u);
    EXPECT_TRUE(f->learns(r + 2));
    EXPECT_FALSE(f->learns(-1));
    // Its records are ignored from now on: the policy and the counters stay.
    const float pdfN = f->pdf(r, n), pdfSide = f->pdf(r, side);
    const uint64_t records = f->stats().records;
    f->beginPass(1);
    for (int i = 0; i < 1000; ++i) f->record(0, r, side, 100.f);
    f->recordSpot(0, r, glm::vec3(0.f), side, glm::vec3(1.f), 1e4f, -1);
    f->record(0, r + 2, side, 1.f);
    f->endPass();
    EXPECT_EQ(f->pdf(r, n), pdfN);
    EXPECT_EQ(f->pdf(r, side), pdfSide);
    EXPECT_EQ(f->stats().records, records + 1);
    // Its selection samples (mix=learn) too: it keeps the selection it had (none here), while
    // a region that still learns takes one from the same samples.
    const guiding::SelectionSample sel{1.f, 1.f, 2.f, 0.5f, 1.f};
    f->beginPass(1);
    for (int i = 0; i < 64; ++i) {
        f->recordSelection(0, r, sel);
        f->recordSelection(0, r + 2, sel);
    }
    f->endPass();
    EXPECT_EQ(f->selection(r), -1.f);
    EXPECT_GE(f->selection(r + 2), 0.f);
    // learn-cap 0: a region never stops.
    auto g = makeHemi(planeScene(), {{"learn-cap", "0"}, {"judge", "0"}});
    ASSERT_TRUE(g);
    g->beginPass(1);
    for (int i = 0; i < 100000; ++i) g->record(0, r, n, 1.f);
    g->endPass();
    EXPECT_TRUE(g->learns(r));
    EXPECT_EQ(g->stats().cappedRegions, 0u);
}

// prune: a learned region whose cosine sampling of its learned light has a relative variance
// (sum Q^2 cos x sum cos / (sum Q cos)^2 - 1 over the strata) of at most prune samples the
// BSDF alone (guides() false), from the pass whose learning shows it; 0 never prunes, an
// untrained region (confidence 0) is never pruned, a concentrated light keeps its guide.
// judge: once the regions' visit-weighted confidence reaches 0.5, a field whose learned light
// the guide's mixture would sample no better than cosine sampling (predicted second moment
// above judge of cosine sampling's) stops guiding and learning directions for good, and,
// without a learned light choice, is inactive (the integrator skips it). A concentrated light
// keeps it; judge 0 (the default) never stops; a saved field reaches the same verdict.
TEST(HemiField, JudgeStopsDirectionGuidingWhereItCannotGain) {
    EXPECT_EQ(makeHemi(planeScene())->params().judge, 0.8);  // the default (session 44)
    auto trainEven = [](HemiField& f, int r, int passes) {
        for (int p = 0; p < passes; ++p) {
            f.beginPass(1);
            for (int j = 0; j < f.layout().count(); ++j)
                for (int i = 0; i < 16; ++i) f.record(0, r, strataCentre(f, r, j), 1.f);
            f.endPass();
        }
    };
    const int r = 2;
    for (const char* judge : {"0", "0.9"}) {
        SCOPED_TRACE(judge);
        auto f = makeHemi(planeScene(), {{"smooth", "0"}, {"prune", "0"}, {"judge", judge}});
        ASSERT_TRUE(f);
        EXPECT_EQ(f->sceneMeasures().ratio, 1.0);  // no visits yet
        EXPECT_EQ(f->sceneMeasures().confidence, 0.0);
        // 16 records per stratum: confidence 16 / (16 + warmup 8) = 2/3 after one pass.
        trainEven(*f, r, 1);
        const HemiField::SceneMeasures m = f->sceneMeasures();
        const double ratio = m.ratio;
        EXPECT_NEAR(m.confidence, 2.0 / 3.0, 1e-6);
        // Even light: the guide's CDF is cosine sampling mixed with epsilon's uniform share,
        // slightly worse than cosine sampling alone.
        EXPECT_GT(ratio, 1.0);
        EXPECT_LT(ratio, 1.1);
        const bool off = std::string(judge) != "0";
        EXPECT_EQ(f->directionsOff(), off);
        EXPECT_EQ(f->active(), !off);
        EXPECT_EQ(f->guides(r), !off);
        EXPECT_EQ(f->learns(r), !off);
        EXPECT_EQ(f->learnsSpots(), !off);
        // After the verdict nothing is learned any more (records are ignored).
        const uint64_t records = f->stats().records;
        trainEven(*f, r, 1);
        EXPECT_EQ(f->stats().records == records, off);
        if (!off) continue;
        // A saved field reaches the verdict again on load; one without judge does not.
        std::string state, error;
        ASSERT_TRUE(f->saveState(&state, &error)) << error;
        auto g = makeHemi(planeScene(), {{"smooth", "0"}, {"prune", "0"}, {"judge", judge}});
        ASSERT_TRUE(g->loadState(state, &error)) << error;
        EXPECT_TRUE(g->directionsOff());
        EXPECT_FALSE(g->active());
        auto h = makeHemi(planeScene(), {{"smooth", "0"}, {"prune", "0"}, {"judge", "0"}});
        ASSERT_TRUE(h->loadState(state, &error)) << error;
        EXPECT_FALSE(h->directionsOff());
        EXPECT_TRUE(h->guides(r));
    }
    // A concentrated light: predicted far below cosine sampling, the guide stays.
    auto f = makeHemi(planeScene(), {{"judge", "0.9"}});
    trainBright(*f, 4, glm::normalize(glm::vec3(0.3f, -0.2f, 1.f)), 2, 5);
    EXPECT_LT(f->sceneMeasures().ratio, 0.5);
    EXPECT_GE(f->sceneMeasures().confidence, 0.5);
    EXPECT_FALSE(f->directionsOff());
    EXPECT_TRUE(f->active());
    EXPECT_TRUE(f->guides(4));
    // Not yet judged below confidence 0.5 (few records): an even light's field guides on.
    auto young = makeHemi(planeScene(), {{"prune", "0"}, {"judge", "0.9"}});
    young->beginPass(1);
    for (int j = 0; j < young->layout().count(); ++j)
        young->record(0, r, strataCentre(*young, r, j), 1.f);
    young->endPass();
    EXPECT_FALSE(young->directionsOff());
    EXPECT_TRUE(young->guides(r));
}

TEST(HemiField, PruneLeavesEvenRegionsToTheBsdf) {
    EXPECT_EQ(makeHemi(planeScene())->params().prune, 0.3);  // the default (session 43)
    // Strata 0 .. n-1 with Q 1, except stratum k with Q 1 + a.
    const int k = 37;
    const double a = 3.0;
    auto train = [&](HemiField& f, int r) {
        f.beginPass(1);
        for (int j = 0; j < f.layout().count(); ++j)
            f.record(0, r, strataCentre(f, r, j), j == k ? float(1.0 + a) : 1.f);
        f.endPass();
    };
    auto expectedVariance = [&](const HemiField& f) {
        double qc = 0.0, q2c = 0.0, cs = 0.0;
        for (int j = 0; j < f.layout().count(); ++j) {
            const double c = f.layout().centre(j).z, q = j == k ? 1.0 + a : 1.0;
            qc += q * c;
            q2c += q * q * c;
            cs += c;
        }
        return q2c * cs / (qc * qc) - 1.0;
    };
    const int r = 0, even = 2, untrained = 4;
    double v = 0.0;
    {
        auto f = makeHemi(planeScene(), {{"smooth", "0"}});
        v = expectedVariance(*f);
    }
    ASSERT_GT(v, 0.01);
    for (double prune : {0.0, 0.999 * v, 1.001 * v}) {
        SCOPED_TRACE(prune);
        auto f = makeHemi(planeScene(), {{"smooth", "0"}, {"prune", std::to_string(prune)}});
        ASSERT_TRUE(f);
        EXPECT_EQ(f->params().prune, std::stod(std::to_string(prune)));
        EXPECT_TRUE(f->guides(r));  // before any learning
        train(*f, r);
        // An even light (Q 1 everywhere): variance 0.
        f->beginPass(1);
        for (int j = 0; j < f->layout().count(); ++j)
            f->record(0, even, strataCentre(*f, even, j), 1.f);
        f->endPass();
        const bool pruned = prune > v;
        EXPECT_EQ(f->guides(r), !pruned);
        EXPECT_EQ(f->guides(even), prune == 0.0);
        EXPECT_TRUE(f->guides(untrained));
        EXPECT_FALSE(f->guides(-1));
        EXPECT_EQ(f->stats().prunedRegions, uint64_t(pruned) + uint64_t(prune > 0.0));
        // Pruning leaves the policy and the learning as they are: the learned region's
        // pdf still follows its light, and it still learns (records count).
        EXPECT_GT(f->pdf(r, strataCentre(*f, r, k)), f->pdf(r, strataCentre(*f, r, k + 1)));
        EXPECT_TRUE(f->learns(r));
        // A light found later (one stratum far brighter) brings the guide back.
        f->beginPass(1);
        for (int i = 0; i < 64; ++i) f->record(0, r, strataCentre(*f, r, 5), 1000.f);
        f->endPass();
        EXPECT_TRUE(f->guides(r));
    }
    // A concentrated light is far above any sensible prune.
    auto g = makeHemi(planeScene(), {{"points", "16"}, {"prune", "1"}});
    trainBright(*g, 4, glm::normalize(glm::vec3(0.3f, -0.2f, 1.f)), 1, 5);
    EXPECT_TRUE(g->guides(4));
}

TEST(HemiField, TrainedSamplingMatchesPdfAndFollowsLight) {
    auto f = makeHemi(planeScene(), {{"points", "16"}});
    ASSERT_TRUE(f);
    const glm::vec3 bright = glm::normalize(glm::vec3(0.3f, -0.2f, 1.f));
    trainBright(*f, 4, bright, 3, 5);
    // The other side; off the world pole, where chi2.h's quadrature is least accurate.
    const glm::vec3 below = glm::normalize(glm::vec3(-0.6f, 0.5f, -0.6f));
    trainBright(*f, 5, below, 1, 6);
    // Strata inside the cone got ~100, the others 0.05: the cone takes most of the mass.
    EXPECT_GT(f->pdf(4, bright), 4.f / (2.f * 3.14159265f));
    EXPECT_LT(f->pdf(4, glm::vec3(1, 0, 0.05f)), 0.5f / (2.f * 3.14159265f));
    EXPECT_GT(f->pdf(5, below), 4.f / (2.f * 3.14159265f));
    for (int region : {4, 5}) {
        chi2::SphereResult r = sphereTest(*f, region, 200 + uint64_t(region), 100000);
        EXPECT_TRUE(r.passed) << "region " << region << ": " << r.message;
        chi2::Result exact = strataTest(*f, region, 300 + uint64_t(region), 1000000);
        EXPECT_TRUE(exact.passed) << "region " << region << ": " << exact.message;
        // Quadrature of the piecewise-constant pdf: 1 to within the integration tolerance.
        EXPECT_NEAR(r.pdfIntegral, 1.0, 2e-3);
        EXPECT_NEAR(strataIntegral(*f, region), 1.0, 1e-5);
    }
    EXPECT_GT(f->stats().rejectedRecords, 0u);  // directions below the hemisphere
}

TEST(HemiField, SampleReportsPdfOfItsDirection) {
    // The finest strata (the narrowest margins of sample()'s shortcut away from stratum
    // edges), the default, and a layout whose columns come from the azimuth.
    for (const char* strata : {"16x16", "7x5", "64x64"}) {
        SCOPED_TRACE(strata);
        auto g = makeHemi(cornerScene(), {{"points", "8"}, {"strata", strata}});
        ASSERT_TRUE(g);
        trainBright(*g, 2, glm::normalize(glm::vec3(1, 1, 0.2f)), 2, 9);
        std::mt19937_64 rng(23);
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        for (int i = 0; i < 100000; ++i) {
            float pdf = 0.f;
            int bin = -2, againBin = -2;
            // Every tenth sample near a stratum edge, where the shortcut does not apply.
            glm::vec2 u(uni(rng), uni(rng));
            if (i % 10 == 0) u.x = (i % 20 == 0) ? 0.f : 0.99999994f;
            glm::vec3 w = g->sample(2, u, uni(rng), &pdf, &bin);
            ASSERT_GT(pdf, 0.f);
            ASSERT_TRUE(std::isfinite(pdf));
            ASSERT_NEAR(glm::length(w), 1.f, 1e-5f);
            float again = g->pdf(2, w, &againBin);
            if (again > 0.f) {  // 0 only exactly on the horizon
                ASSERT_EQ(pdf, again);
                ASSERT_EQ(bin, againBin);
            }
        }
    }
    auto f = makeHemi(cornerScene(), {{"points", "8"}, {"strata", "64x64"}});
    ASSERT_TRUE(f);
    trainBright(*f, 2, glm::normalize(glm::vec3(1, 1, 0.2f)), 2, 9);
    // Edge values of the sample dimensions.
    for (float a : {0.f, 0.99999994f})
        for (float b : {0.f, 0.99999994f})
            for (float c : {0.f, 0.99999994f}) {
                float pdf = 0.f;
                glm::vec3 w = f->sample(2, glm::vec2(a, b), c, &pdf);
                EXPECT_GT(pdf, 0.f);
                EXPECT_TRUE(std::isfinite(w.x) && std::isfinite(w.y) && std::isfinite(w.z));
            }
    float pdf = 1.f;
    EXPECT_EQ(f->sample(-1, glm::vec2(0.5f), 0.5f, &pdf), glm::vec3(0.f));
    EXPECT_EQ(pdf, 0.f);
    EXPECT_EQ(f->pdf(-1, glm::vec3(0, 0, 1)), 0.f);
    EXPECT_EQ(f->pdf(f->numRegions(), glm::vec3(0, 0, 1)), 0.f);
}

TEST(HemiField, RunningMeanConvergesToTargets) {
    auto f = makeHemi(planeScene(),
                      {{"points", "4"}, {"strata", "4x2"}, {"epsilon", "0.1"}, {"cosine", "0"},
                       {"smooth", "0"}, {"judge", "0"}});
    ASSERT_TRUE(f);
    const int region = 2, n = f->layout().count();
    std::mt19937_64 rng(31);
    std::normal_distribution<double> noise(0.0, 0.5);
    std::vector<double> sum(size_t(n), 0.0);
    std::vector<uint64_t> count(size_t(n), 0);
    for (int pass = 0; pass < 5; ++pass) {
        f->beginPass(3);
        for (int i = 0; i < 300; ++i) {
            int j = i % n;
            float t = float(std::max(0.0, (j + 1) + noise(rng)));
            f->record(i % 3, region, strataCentre(*f, region, j), t);
            sum[size_t(j)] += t;
            ++count[size_t(j)];
        }
        f->endPass();
        for (int j = 0; j < n; ++j) {
            // Q is the mean of every target so far (alpha = 1/(1+visits)).
            EXPECT_NEAR(f->q(region, j), sum[size_t(j)] / double(count[size_t(j)]),
                        1e-12 * sum[size_t(j)]);
            EXPECT_EQ(f->visits(region, j), count[size_t(j)]);
        }
    }
    // Noise-free constant targets: Q equals T exactly after one pass.
    auto g = makeHemi(planeScene(),
                      {{"points", "4"}, {"strata", "4x2"}, {"epsilon", "0.1"}, {"cosine", "0"},
                       {"smooth", "0"}, {"judge", "0"}});
    ASSERT_TRUE(g);
    g->beginPass(1);
    double total = 0.0;
    for (int j = 0; j < n; ++j) {
        for (int k = 0; k < 3; ++k) g->record(0, region, strataCentre(*g, region, j), float(j + 1));
        total += j + 1;
    }
    g->endPass();
    for (int j = 0; j < n; ++j) {
        EXPECT_EQ(g->q(region, j), double(j + 1));
        // Policy: P_j = 0.9 * T_j / sum(T) + 0.1 / n, pdf = P_j * n / (2 pi).
        double pj = 0.9 * (j + 1) / total + 0.1 / n;
        EXPECT_NEAR(g->pdf(region, strataCentre(*g, region, j)), pj * n / (2.0 * PiDouble), 1e-6);
    }
    // Untouched regions keep init and the uniform policy.
    EXPECT_EQ(g->q(0, 0), 1e-3);
    EXPECT_NEAR(g->pdf(0, glm::vec3(0, 0, 1)), 1.0 / (2.0 * PiDouble), 1e-6);
}

// The bin that pdf() and sample() report is the stratum record() and radiance() would find:
// passing it gives the same Q, visits and radiance as passing the direction alone, and a bin
// out of range is ignored (the direction decides).
TEST(HemiField, BinsFromPdfAndSampleStandForTheDirection) {
    const std::map<std::string, std::string> params = {{"points", "4"}, {"strata", "8x4"}};
    auto f = makeHemi(planeScene(), params), g = makeHemi(planeScene(), params);
    ASSERT_TRUE(f && g);
    const int region = 0;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> uni(0.f, 1.f);
    f->beginPass(1);
    g->beginPass(1);
    for (int i = 0; i < 4000; ++i) {
        glm::vec3 w;
        int bin = -2;
        if (i % 2 == 0) {
            float p = 0.f;
            w = f->sample(region, glm::vec2(uni(rng), uni(rng)), uni(rng), &p, &bin);
            EXPECT_FLOAT_EQ(p, f->pdf(region, w));
        } else {
            w = glm::vec3(uni(rng) - 0.5f, uni(rng) - 0.5f, uni(rng) - 0.5f);
            f->pdf(region, w, &bin);
        }
        int again = -2;
        g->pdf(region, w, &again);
        ASSERT_EQ(bin, again);
        const float t = float(i % 7);
        f->record(0, region, w, t, bin);
        g->record(0, region, w, t, i % 3 == 0 ? 1000 : -1);  // out of range: ignored
    }
    f->endPass();
    g->endPass();
    for (int j = 0; j < 32; ++j) {
        EXPECT_EQ(f->q(region, j), g->q(region, j)) << j;
        EXPECT_EQ(f->visits(region, j), g->visits(region, j)) << j;
        const glm::vec3 c = strataCentre(*f, region, j);
        int bin = -2;
        f->pdf(region, c, &bin);
        EXPECT_EQ(bin, j);
        EXPECT_EQ(f->radiance(region, c, bin), f->radiance(region, c));
    }
    int bin = 0;
    EXPECT_EQ(f->pdf(-1, glm::vec3(0, 0, 1), &bin), 0.f);
    EXPECT_EQ(bin, -1);
}

// policyRadiance (the roulette's Q, from the CDF) against radiance (the estimates): equal up
// to the CDF's float rounding, whose bound is derived here: each CDF entry is a double
// rounded to float (at most 2^-25 absolutely, entries <= 1), the difference of two of them
// rounds by at most 2^-24 of itself, and the bound carries the region's scale
// sum_k Q_k cos_k / (1 - epsilon) over the stratum's cosine. Where the CDF holds no Q
// (epsilon = 1) and where the integrator reads the estimates anyway (target=sample), it is
// radiance() exactly.
TEST(HemiField, PolicyRadianceMatchesTheEstimates) {
    struct Case {
        std::map<std::string, std::string> params;
        bool exact;
    };
    const std::vector<Case> cases = {
        {{{"points", "4"}}, false},
        {{{"points", "4"}, {"strata", "7x5"}, {"cosine", "0"}}, false},
        {{{"points", "4"}, {"epsilon", "0"}, {"smooth", "0"}}, false},
        {{{"points", "4"}, {"epsilon", "0.5"}, {"strata", "64x64"}}, false},
        {{{"points", "4"}, {"epsilon", "1"}}, true},
        {{{"points", "4"}, {"target", "sample"}}, true},
    };
    for (const Case& c : cases) {
        auto f = makeHemi(planeScene(), c.params);
        ASSERT_TRUE(f);
        std::string what;
        for (const auto& [k, v] : c.params) what += k + "=" + v + " ";
        const glm::vec3 bright = glm::normalize(glm::vec3(0.3f, -0.2f, 1.f));
        trainBright(*f, 0, bright, 2, 7);
        const double eps = c.params.count("epsilon") ? std::stod(c.params.at("epsilon")) : 0.1;
        const bool cosine = !c.params.count("cosine");
        for (int region : {0, 2}) {  // trained, untrained
            const int n = f->layout().count();
            double sum = 0.0;
            for (int j = 0; j < n; ++j)
                sum += f->radiance(region, strataCentre(*f, region, j)) *
                       (cosine ? f->layout().centre(j).z : 1.0);
            int nonzero = 0;
            for (int j = 0; j < n; ++j) {
                const glm::vec3 w = strataCentre(*f, region, j);
                const float exact = f->radiance(region, w);
                int bin = -1;
                f->pdf(region, w, &bin);
                const float approx = f->policyRadiance(region, w, bin);
                ASSERT_EQ(approx, f->policyRadiance(region, w)) << what << j;
                nonzero += exact > 0.f;
                if (c.exact) {
                    ASSERT_EQ(approx, exact) << what << j;
                    continue;
                }
                const double cosj = cosine ? f->layout().centre(j).z : 1.0;
                const double tol = 3.0 * std::ldexp(1.0, -24) * sum / (1.0 - eps) / cosj +
                                   1e-6 * exact;
                ASSERT_NEAR(approx, exact, tol) << what << " region " << region << " stratum " << j;
                ASSERT_GE(approx, 0.f);
            }
            EXPECT_EQ(nonzero, n) << what;  // init > 0 and smoothing keep every Q positive
        }
        // Outside the hemisphere, and for no region: 0.
        EXPECT_EQ(f->policyRadiance(0, -f->regionNormal(0)), 0.f) << what;
        EXPECT_EQ(f->policyRadiance(-1, glm::vec3(0, 0, 1)), 0.f) << what;
    }
}

TEST(HemiField, FixedAlphaFollowsGeometricSchedule) {
    const std::vector<std::pair<double, std::string>> alphas = {
        {1.0, "1"}, {0.5, "0.5"}, {0.1, "0.1"}, {1e-9, "1e-9"}};
    for (const auto& [alpha, text] : alphas) {
        auto f = makeHemi(planeScene(), {{"points", "1"}, {"strata", "1x1"},
                                         {"alpha", text}, {"init", "1"}, {"judge", "0"}});
        ASSERT_TRUE(f);
        const glm::vec3 up(0, 0, 1);
        double expected = 1.0;
        for (int pass = 0; pass < 10; ++pass) {
            f->beginPass(1);
            const int m = 1 + pass % 3;  // several records per pass act like m updates
            for (int i = 0; i < m; ++i) f->record(0, 0, up, 3.f);
            f->endPass();
            for (int i = 0; i < m; ++i) expected = (1.0 - alpha) * expected + alpha * 3.0;
            EXPECT_NEAR(f->q(0, 0), expected, 1e-12) << "alpha " << alpha;
        }
        if (alpha == 1e-9) {
            EXPECT_GT(f->q(0, 0), 1.0);  // tiny updates are not lost
        }
    }
}

TEST(HemiField, RejectsBadTargetsAndRecords) {
    auto f = makeHemi(planeScene(), {{"points", "2"}});
    ASSERT_TRUE(f);
    f->beginPass(2);
    const glm::vec3 up(0, 0, 1);
    f->record(0, 0, up, NAN);
    f->record(0, 0, up, INFINITY);
    f->record(1, 0, up, -INFINITY);
    f->record(1, 0, up, -1.f);
    f->record(0, 0, glm::vec3(0, 0, -1), 1.f);   // below region 0's hemisphere
    f->record(0, 0, glm::vec3(1, 0, 0), 1.f);    // on the horizon
    f->record(0, 0, glm::vec3(NAN), 1.f);        // no direction
    f->record(0, 7, up, 1.f);                    // no such region
    f->record(0, -1, up, 1.f);                   // "no data" region
    f->record(5, 0, up, 1.f);                    // no such slot: ignored
    f->record(-1, 0, up, 1.f);
    f->record(1, 1, glm::vec3(0, 0, -1), 0.f);   // valid: zero target
    f->endPass();
    GuidingStats s = f->stats();
    EXPECT_EQ(s.passes, 1u);
    EXPECT_EQ(s.rejectedTargets, 4u);
    EXPECT_EQ(s.rejectedRecords, 5u);
    EXPECT_EQ(s.records, 1u);
    for (double q : f->qTable()) EXPECT_TRUE(std::isfinite(q));
    EXPECT_EQ(f->q(0, 63), 1e-3);
    EXPECT_EQ(f->q(1, f->stratumOf(1, glm::vec3(0, 0, -1))), 0.0);  // region 1's zenith
    // An all-zero row is not possible here (init elsewhere), but the zero stratum keeps
    // the epsilon floor: sampled with probability 0.1 / 64.
    EXPECT_GT(f->pdf(1, glm::vec3(0, 0, -1)), 0.f);
    // Records without beginPass are dropped safely.
    auto g = makeHemi(planeScene(), {{"points", "2"}});
    g->record(0, 0, up, 1.f);
    g->endPass();
    EXPECT_EQ(g->stats().records, 0u);
}

TEST(HemiField, AllZeroRowFallsBackToUniform) {
    auto f = makeHemi(planeScene(),
                      {{"points", "1"}, {"strata", "2x2"}, {"epsilon", "0"}, {"smooth", "0"}});
    ASSERT_TRUE(f);
    f->beginPass(1);
    for (int j = 0; j < 4; ++j) f->record(0, 0, strataCentre(*f, 0, j), 0.f);
    f->endPass();
    for (int j = 0; j < 4; ++j) {
        EXPECT_EQ(f->q(0, j), 0.0);
        EXPECT_NEAR(f->pdf(0, strataCentre(*f, 0, j)), 1.0 / (2.0 * PiDouble), 1e-6);
    }
}

TEST(HemiField, ScatteredAndIrradianceEstimates) {
    auto f = makeHemi(cornerScene(), {{"points", "4"}, {"init", "2"}});
    ASSERT_TRUE(f);
    for (int region = 0; region < f->numRegions(); ++region) {
        const glm::vec3 n = f->regionNormal(region);
        // Uniform Q = c: the midpoint rule in cos(theta) is exact, (2pi/n) sum c cos_j = pi c.
        auto cosine = [&](const glm::vec3& w) { return std::max(0.f, glm::dot(w, n)); };
        EXPECT_NEAR(f->scatteredEstimate(region, cosine), 2.0 * PiDouble, 1e-5);
        EXPECT_NEAR(f->irradianceEstimate(region, n), 2.0 * PiDouble, 1e-5);
        // A normal opposite to the region's hemisphere sees nothing.
        EXPECT_EQ(f->irradianceEstimate(region, -n), 0.f);
        // Bad fcos values count as zero.
        auto bad = [&](const glm::vec3& w) { return glm::dot(w, n) > 0.5f ? NAN : -1.f; };
        EXPECT_EQ(f->scatteredEstimate(region, bad), 0.f);
        auto inf = [&](const glm::vec3& w) { return INFINITY; };
        EXPECT_EQ(f->scatteredEstimate(region, inf), 0.f);
        // Tilted shading normal: the first moment of Q, (2pi/n) sum_j Q_j dot(w_j, ns) (no
        // clamp of the strata below ns's horizon: the documented approximation), computed
        // here stratum by stratum.
        glm::vec3 ns = glm::normalize(n + glm::vec3(0.2f, 0.3f, 0.1f));
        Frame frame = Frame::fromZ(n);
        double moment = 0.0;
        for (int j = 0; j < f->layout().count(); ++j)
            moment += f->q(region, j) * glm::dot(frame.toWorld(f->layout().centre(j)), ns);
        moment *= f->layout().stratumSolidAngle();
        EXPECT_NEAR(f->irradianceEstimate(region, ns), moment, 1e-5);
        // ... which stays within the clamped sum's neighbourhood for a small tilt.
        auto tilted = [&](const glm::vec3& w) { return std::max(0.f, glm::dot(w, ns)); };
        EXPECT_NEAR(f->irradianceEstimate(region, ns), f->scatteredEstimate(region, tilted),
                    0.05 * f->scatteredEstimate(region, tilted));
    }
    EXPECT_EQ(f->scatteredEstimate(-1, [](const glm::vec3&) { return 1.f; }), 0.f);
    EXPECT_EQ(f->irradianceEstimate(99, glm::vec3(0, 0, 1)), 0.f);
}

TEST(HemiField, ExtremeParametersStayFiniteAndNormalised) {
    const std::vector<std::string> inits = {"1e-30", "1e30", "3.4e38"};
    const std::vector<std::string> alphas = {"visits", "1e-9", "1"};
    const std::vector<std::string> strata = {"1x1", "64x64", "1x64", "64x1"};
    const std::vector<float> targets = {0.f, 1e-45f, 1e-30f, 1.f, 1e30f, FLT_MAX};
    for (const auto& init : inits)
        for (const auto& alpha : alphas)
            for (const auto& st : strata) {
                auto f = makeHemi(planeScene(), {{"points", "1"}, {"init", init},
                                                 {"alpha", alpha}, {"strata", st}});
                ASSERT_TRUE(f);
                ASSERT_EQ(f->numRegions(), 2);
                std::mt19937_64 rng(41);
                for (int pass = 0; pass < 3; ++pass) {
                    f->beginPass(2);
                    for (int i = 0; i < 2000; ++i) {
                        glm::vec3 w = gaussianDirection(rng);
                        f->record(i & 1, w.z > 0 ? 0 : 1, w, targets[size_t(i) % targets.size()]);
                    }
                    f->endPass();
                }
                const std::string what = init + " " + alpha + " " + st;
                for (double q : f->qTable()) ASSERT_TRUE(std::isfinite(q) && q >= 0.0) << what;
                for (float c : f->cdfTable()) ASSERT_TRUE(std::isfinite(c)) << what;
                for (int region : {0, 1}) {
                    EXPECT_NEAR(strataIntegral(*f, region), 1.0, 1e-4) << what;
                    float pdf = 0.f;
                    glm::vec3 w = f->sample(region, glm::vec2(0.3f, 0.7f), 0.5f, &pdf);
                    EXPECT_TRUE(pdf > 0.f && std::isfinite(pdf)) << what;
                    EXPECT_TRUE(std::isfinite(glm::length(w))) << what;
                    auto fcos = [](const glm::vec3& w) { return std::abs(w.z) * 1e10f; };
                    float s = f->scatteredEstimate(region, fcos);
                    EXPECT_TRUE(std::isfinite(s) && s >= 0.f) << what;
                    float e = f->irradianceEstimate(region, f->regionNormal(region));
                    EXPECT_TRUE(std::isfinite(e) && e >= 0.f) << what;
                }
            }
}

TEST(HemiField, ExtremeFieldPassesChiSquare) {
    // 64x64 strata, tiny init, alpha 1e-9, one point: still a valid distribution.
    auto f = makeHemi(planeScene(), {{"points", "1"}, {"init", "1e-30"}, {"alpha", "1e-9"},
                                     {"strata", "64x64"}});
    ASSERT_TRUE(f);
    trainBright(*f, 0, glm::normalize(glm::vec3(-0.5f, 0.5f, 0.3f)), 2, 3);
    chi2::SphereResult r = sphereTest(*f, 0, 77, 100000);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdfIntegral, 1.0, 2e-3);
    chi2::Result exact = strataTest(*f, 0, 78, 2000000);
    EXPECT_TRUE(exact.passed) << exact.message;
}

TEST(HemiField, ManyPointsBuildAndLookup) {
    // A million surface samples (cheap tables with 1x1 strata): lookup still finds the nearest.
    auto f = makeHemi(planeScene(), {{"points", "1000000"}, {"strata", "1x1"}});
    ASSERT_TRUE(f);
    EXPECT_EQ(f->numRegions(), 2000000);
    glm::vec3 p(0.123456f, 0.654321f, 0.f);
    int r = f->lookup(p, glm::vec3(0, 0, 1));
    ASSERT_GE(r, 0);
    // Halton points are about 1/sqrt(1e6) apart: the nearest is within a few spacings.
    EXPECT_LT(glm::length(f->regionPosition(r) - p), 3e-3f);
}

TEST(HemiField, NoSurfaceGivesEmptyField) {
    SceneInfo empty = planeScene();
    int calls = 0;
    empty.samplePoint = [&calls](const glm::vec3&, glm::vec3*, glm::vec3*) {
        ++calls;
        return false;
    };
    auto f = makeHemi(empty, {{"points", "100000"}});
    ASSERT_TRUE(f);
    EXPECT_EQ(f->numRegions(), 0);
    EXPECT_LE(calls, 64);
    EXPECT_EQ(f->lookup(glm::vec3(0.f), glm::vec3(0, 0, 1)), -1);
    f->beginPass(1);
    f->record(0, 0, glm::vec3(0, 0, 1), 1.f);
    f->endPass();
    EXPECT_EQ(f->stats().rejectedRecords, 1u);
    EXPECT_FALSE(f->describe().empty());
    // Degenerate draws (zero or non-finite normals) are skipped, good ones kept.
    SceneInfo flaky = planeScene();
    flaky.samplePoint = [](const glm::vec3& u, glm::vec3* p, glm::vec3* n) {
        *p = glm::vec3(u.x, u.y, 0.f);
        *n = u.z < 0.5f ? glm::vec3(0.f) : glm::vec3(0.f, 0.f, 3.f);
        return true;
    };
    auto g = makeHemi(flaky, {{"points", "100"}});
    ASSERT_TRUE(g);
    EXPECT_EQ(g->numRegions(), 200);
    EXPECT_EQ(g->regionNormal(0), glm::vec3(0, 0, 1));  // normalised
}

// Records of one pass: slot s gets a fixed pseudo-random list.
struct SlotRecords {
    std::vector<int> region;
    std::vector<glm::vec3> w;
    std::vector<float> t;
};

std::vector<SlotRecords> makeSlotRecords(int slots, int regions, uint64_t seed) {
    std::vector<SlotRecords> out(static_cast<size_t>(slots));
    for (int s = 0; s < slots; ++s) {
        std::mt19937_64 rng(seed * 1000 + uint64_t(s));
        std::uniform_int_distribution<int> reg(0, regions - 1);
        std::exponential_distribution<float> ex(0.1f);
        for (int i = 0; i < 5000; ++i) {
            out[size_t(s)].region.push_back(reg(rng) & ~1);  // upward hemispheres
            out[size_t(s)].w.push_back(gaussianDirection(rng));
            out[size_t(s)].t.push_back(ex(rng));
        }
    }
    return out;
}

TEST(HemiField, DeterministicAcrossThreadSchedules) {
    const int slots = 16;
    auto run = [&](int schedule) {
        auto f = makeHemi(planeScene(), {{"points", "32"}});
        for (uint64_t pass = 0; pass < 3; ++pass) {
            auto recs = makeSlotRecords(slots, f->numRegions(), pass + 1);
            f->beginPass(slots);
            auto feed = [&](int s) {
                const SlotRecords& r = recs[size_t(s)];
                for (size_t i = 0; i < r.t.size(); ++i) f->record(s, r.region[i], r.w[i], r.t[i]);
            };
            test::feedSlots(slots, schedule, feed);
            f->endPass();
        }
        return f;
    };
    auto a = run(0), b = run(1), c = run(2), d = run(4);
    for (const auto* other : {b.get(), c.get(), d.get()}) test::expectSameTables(*a, *other);
    EXPECT_EQ(a->stats().records, d->stats().records);
    EXPECT_GT(a->stats().records, 0u);
}

// Confidence = visits / (visits + warmup * strata), frozen at endPass: 0 before any data, 1/2
// after warmup * strata records, 1 with warmup 0 (the paper's pure mixture), 0 for invalid
// regions; bad warmup values are refused.
TEST(HemiField, ConfidenceGrowsWithVisits) {
    auto f = makeHemi(planeScene(), {{"points", "1"}, {"strata", "4x4"}, {"warmup", "2"}});
    ASSERT_TRUE(f);
    EXPECT_EQ(f->confidence(0), 0.f);
    EXPECT_EQ(f->confidence(-1), 0.f);
    EXPECT_EQ(f->confidence(f->numRegions()), 0.f);
    f->beginPass(1);
    for (int i = 0; i < 32; ++i) f->record(0, 0, glm::vec3(0.f, 0.f, 1.f), 1.f);
    EXPECT_EQ(f->confidence(0), 0.f);  // not before endPass
    f->endPass();
    EXPECT_FLOAT_EQ(f->confidence(0), 0.5f);  // 32 / (32 + 2 * 16)
    EXPECT_EQ(f->confidence(1), 0.f);         // the other hemisphere saw nothing
    auto pure = makeHemi(planeScene(), {{"points", "1"}, {"warmup", "0"}});
    ASSERT_TRUE(pure);
    EXPECT_EQ(pure->confidence(0), 1.f);
    for (const char* bad : {"-1", "nan", "2e9", "x"}) {
        GuideConfig c;
        c.backend = "hemi";
        c.params = {{"warmup", bad}};
        std::string error;
        EXPECT_FALSE(createGuidingField(c, planeScene(), &error)) << bad;
        EXPECT_NE(error.find("warmup"), std::string::npos) << error;
    }
}

}  // namespace
}  // namespace rlpbrt::guiding

namespace rlpbrt::guiding {
namespace {

// directions=tree: the adaptive quadtree per hemisphere (guiding/tree_table.h) behind the
// same interface. Sampling against the pdf (chi-square over the sphere), the pdf's integral
// (over the tree's leaves), a narrow bright cone resolved finer than the strata, bins.
TEST(HemiField, TreeDirectionsSampleTheirPdfAndResolveANarrowCone) {
    auto f = test::makeField<HemiField>("hemi", test::planeScene(),
                                        {{"points", "16"}, {"directions", "tree"}});
    ASSERT_TRUE(f);
    const glm::vec3 bright = glm::normalize(glm::vec3(0.3f, -0.2f, 1.f));
    // A cone of cos > 0.995 (0.1 rad): about a tenth of a 16x16 stratum's solid angle.
    std::mt19937_64 rng(17);
    for (int p = 0; p < 6; ++p) {
        f->beginPass(1);
        for (int i = 0; i < 40000; ++i) {
            const glm::vec3 w = test::gaussianDirection(rng);
            f->record(0, 4, w, glm::dot(w, bright) > 0.995f ? 1000.f : 0.05f);
        }
        f->endPass();
    }
    // The cone holds about 0.0314 sr x 1000 of the region's light against 6.2 x 0.05 for the
    // rest: its pdf is far above what a 16x16 stratum (0.0245 sr) could give it.
    const float inCone = f->pdf(4, bright);
    EXPECT_GT(inCone, 10.f);
    EXPECT_LT(f->pdf(4, glm::normalize(glm::vec3(-0.5f, 0.5f, 0.3f))), 0.1f);
    chi2::SphereResult r = sphereTest(*f, 4, 41, 100000);
    EXPECT_TRUE(r.passed) << r.message;
    // The pdf's integral over the hemisphere.
    double integral = 0.0;
    {
        std::mt19937_64 g(5);
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        // Monte Carlo over uniform hemisphere directions: E[pdf / (1 / 2pi)] = 1.
        const Frame frame = Frame::fromZ(f->regionNormal(4));
        const int n = 400000;
        for (int i = 0; i < n; ++i) {
            const glm::vec3 local = DirTree::hemisphereDirection(glm::vec2(uni(g), uni(g)));
            integral += double(f->pdf(4, frame.toWorld(local))) * 2.0 * 3.14159265358979;
        }
        integral /= n;
    }
    EXPECT_NEAR(integral, 1.0, 0.02);
    // A sampled direction's bin is its leaf: radiance() agrees with and without it.
    for (int i = 0; i < 100; ++i) {
        float pdf = 0.f;
        int bin = -1;
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        const glm::vec3 w = f->sample(4, glm::vec2(uni(rng), uni(rng)), uni(rng), &pdf, &bin);
        ASSERT_GE(bin, 0);
        EXPECT_FLOAT_EQ(pdf, f->pdf(4, w));
        EXPECT_FLOAT_EQ(f->radiance(4, w, bin), f->radiance(4, w));
    }
    // The smoothing (smooth=2) shrinks the cone's few-visit leaves towards their neighbours a
    // little.
    EXPECT_GT(f->radiance(4, bright), 800.f);
    EXPECT_LT(f->radiance(4, bright), 1050.f);
    std::string error;
    EXPECT_FALSE(f->save("/tmp/rlpbrt-tree-field.bin", &error));
    EXPECT_NE(error.find("directions=tree"), std::string::npos);
}

}  // namespace
}  // namespace rlpbrt::guiding
