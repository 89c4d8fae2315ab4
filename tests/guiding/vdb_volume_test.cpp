// The vdb backend's medium tables (guiding/vdb_volume.h): activation on request, lookups,
// full-sphere sampling against the pdf (chi-square), learning, determinism, save/load.
#include "guiding/guiding.h"
#include "guiding/vdb.h"
#include "guiding/vdb_volume.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "guiding/test_scenes.h"
#include "render/chi2.h"

namespace rlpbrt::guiding {
namespace {

using test::gaussianDirection;
using test::planeScene;
using test::trainBright;

std::unique_ptr<VdbField> makeVdb(const SceneInfo& scene,
                                  std::map<std::string, std::string> params = {}) {
    return test::makeField<VdbField>("vdb", scene, std::move(params));
}

// The unit-square plane with a medium filling [0,1]^2 x [0, 0.5] above it.
SceneInfo foggyPlane() {
    SceneInfo s = planeScene();
    s.boundsMax = glm::vec3(1.f, 1.f, 0.5f);
    s.mediaMin = glm::vec3(0.f);
    s.mediaMax = glm::vec3(1.f, 1.f, 0.5f);
    return s;
}

// Requests the voxels of `points` in slot 0 and ends the pass.
void activate(GuidingField& f, const std::vector<glm::vec3>& points) {
    f.beginPass(1);
    for (const glm::vec3& p : points) f.requestMedium(0, p);
    f.endPass();
}

TEST(VdbVolume, OnlyScenesWithMediaGetTablesAndParametersAreChecked) {
    auto plain = makeVdb(planeScene());
    ASSERT_TRUE(plain);
    EXPECT_EQ(plain->volume(), nullptr);
    EXPECT_EQ(plain->lookupMedium(glm::vec3(0.5f)), -1);
    EXPECT_FALSE(plain->guidesMedia());
    auto off = makeVdb(foggyPlane(), {{"volume", "0"}});
    ASSERT_TRUE(off);
    EXPECT_EQ(off->volume(), nullptr);
    EXPECT_FALSE(off->guidesMedia());  // the integrator then skips medium lookups
    auto on = makeVdb(foggyPlane(), {{"volume-voxel", "4"}});
    ASSERT_TRUE(on);
    ASSERT_NE(on->volume(), nullptr);
    EXPECT_TRUE(on->guidesMedia());
    EXPECT_DOUBLE_EQ(on->volume()->voxelSize(), 0.25);
    EXPECT_EQ(on->volume()->dims(), glm::ivec3(4, 4, 2));
    EXPECT_EQ(on->volume()->strata(), 128);
    for (const char* bad : {"0", "1025", "x", "-1"}) {
        GuideConfig cfg{"vdb", {{"volume-voxel", bad}}};
        std::string error;
        EXPECT_FALSE(createGuidingField(cfg, foggyPlane(), &error)) << bad;
        EXPECT_NE(error.find("volume-voxel"), std::string::npos) << error;
    }
    GuideConfig cfg{"vdb", {{"volume", "yes"}}};
    std::string error;
    EXPECT_FALSE(createGuidingField(cfg, foggyPlane(), &error));
}

// The medium tables keep their own strata and warmup (8x8 and 16 by default) whatever the
// surface tables use (16x16 and 8).
TEST(VdbVolume, MediumTablesHaveTheirOwnStrataAndWarmup) {
    auto def = makeVdb(foggyPlane(), {{"volume-voxel", "4"}});
    ASSERT_TRUE(def && def->volume());
    EXPECT_EQ(def->strataPerRegion(), 256);
    EXPECT_EQ(def->params().warmup, 8.0);
    EXPECT_EQ(def->volume()->strata(), 2 * 8 * 8);
    EXPECT_EQ(def->volume()->params().warmup, 16.0);
    auto f = makeVdb(foggyPlane(), {{"volume-voxel", "4"},
                                    {"strata", "8x4"},
                                    {"volume-strata", "4x2"},
                                    {"volume-warmup", "3"}});
    ASSERT_TRUE(f && f->volume());
    EXPECT_EQ(f->strataPerRegion(), 32);
    EXPECT_EQ(f->volume()->strata(), 2 * 4 * 2);
    EXPECT_EQ(f->volume()->params().warmup, 3.0);
    // A medium cell's pdf integrates to one over the sphere with its own strata.
    activate(*f, {glm::vec3(0.3f, 0.6f, 0.2f)});
    const int cell = f->lookupMedium(glm::vec3(0.3f, 0.6f, 0.2f));
    ASSERT_GE(cell, 0);
    chi2::SphereOptions opt;
    opt.sampleCount = 20000;
    const chi2::SphereResult r = chi2::testSphere(
        [&](const glm::vec3& u) {
            chi2::SphereSample s;
            s.dir = f->sample(cell, glm::vec2(u.x, u.y), u.z, &s.pdf);
            return s;
        },
        [&](const glm::vec3& w) { return f->pdf(cell, w); }, opt);
    EXPECT_NEAR(r.pdfIntegral, 1.0, 1e-3);
    for (const auto& [key, bad] : std::vector<std::pair<std::string, std::string>>{
             {"volume-strata", "0"}, {"volume-strata", "65"}, {"volume-strata", "4x"},
             {"volume-warmup", "-1"}, {"volume-warmup", "x"}}) {
        GuideConfig cfg{"vdb", {{key, bad}}};
        std::string error;
        EXPECT_FALSE(createGuidingField(cfg, foggyPlane(), &error)) << key << "=" << bad;
        EXPECT_NE(error.find(key), std::string::npos) << error;
    }
}

TEST(VdbVolume, VoxelsAreActivatedWhereRequestedInSlotOrder) {
    auto f = makeVdb(foggyPlane(), {{"volume-voxel", "4"}});
    ASSERT_TRUE(f);
    const glm::vec3 a(0.1f, 0.1f, 0.1f), b(0.9f, 0.6f, 0.3f), outside(2.f, 0.5f, 0.2f);
    EXPECT_EQ(f->lookupMedium(a), -1);
    // Requests outside a pass are ignored; in a pass they take effect at its end.
    f->requestMedium(0, a);
    f->beginPass(2);
    f->requestMedium(1, a);
    f->requestMedium(0, b);
    f->requestMedium(0, b);
    f->requestMedium(0, outside);
    f->requestMedium(0, glm::vec3(NAN));
    EXPECT_EQ(f->lookupMedium(a), -1);
    f->endPass();
    const int surfaces = f->numRegions();
    EXPECT_EQ(f->volume()->cells(), 2);
    EXPECT_EQ(f->lookupMedium(b), surfaces + 0);  // slot 0 first
    EXPECT_EQ(f->lookupMedium(a), surfaces + 1);
    EXPECT_EQ(f->lookupMedium(a + glm::vec3(0.1f)), surfaces + 1);  // same voxel
    EXPECT_EQ(f->lookupMedium(outside), -1);
    EXPECT_EQ(f->lookupMedium(glm::vec3(0.6f, 0.1f, 0.1f)), -1);  // not requested
    // Far faces belong to the last voxel.
    activate(*f, {glm::vec3(1.f, 1.f, 0.5f)});
    EXPECT_EQ(f->lookupMedium(glm::vec3(1.f, 1.f, 0.5f)), surfaces + 2);
    EXPECT_EQ(f->stats().mediumCells, 3u);
    // Surface lookups are unaffected by the medium cells.
    EXPECT_GE(f->lookup(glm::vec3(0.5f, 0.5f, 0.f), glm::vec3(0.f, 0.f, 1.f)), 0);
    EXPECT_LT(f->lookup(glm::vec3(0.5f, 0.5f, 0.f), glm::vec3(0.f, 0.f, 1.f)), surfaces);
}

TEST(VdbVolume, SamplingMatchesPdfOverTheWholeSphere) {
    auto f = makeVdb(foggyPlane(), {{"volume-voxel", "2"}});
    ASSERT_TRUE(f);
    activate(*f, {glm::vec3(0.2f), glm::vec3(0.7f, 0.7f, 0.2f)});
    const int r0 = f->lookupMedium(glm::vec3(0.2f)), r1 = f->lookupMedium(glm::vec3(0.7f, 0.7f, 0.2f));
    ASSERT_GE(r0, 0);
    ASSERT_GE(r1, 0);
    // r1 learns a bright direction below the horizon (the lower hemisphere's strata).
    const glm::vec3 bright = glm::normalize(glm::vec3(0.3f, -0.4f, -0.8f));
    trainBright(*f, r1, bright, 3, 7);
    EXPECT_GT(f->pdf(r1, bright), 8.f / (4.f * 3.14159265f));
    EXPECT_GT(f->radiance(r1, bright), 50.f);
    EXPECT_GT(f->confidence(r1), 0.5f);
    EXPECT_EQ(f->confidence(r0), 0.f);  // no records: the phase function only
    for (int region : {r0, r1}) {
        chi2::SphereOptions opt;
        opt.sampleCount = 400000;
        opt.thetaRes = 12;
        opt.phiRes = 24;
        opt.seed = 11 + uint64_t(region);
        opt.numTests = 2;
        chi2::SphereResult r = chi2::testSphere(
            [&](const glm::vec3& u) {
                chi2::SphereSample s;
                s.dir = f->sample(region, glm::vec2(u.x, u.y), u.z, &s.pdf);
                return s;
            },
            [&](const glm::vec3& w) { return f->pdf(region, w); }, opt);
        EXPECT_TRUE(r.passed) << "region " << region << ": " << r.message;
        EXPECT_NEAR(r.pdfIntegral, 1.0, 2e-3);
        // Every sample reports the pdf of its own direction.
        std::mt19937_64 rng(3);
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        for (int i = 0; i < 20000; ++i) {
            float pdf = 0.f;
            glm::vec3 w = f->sample(region, glm::vec2(uni(rng), uni(rng)), uni(rng), &pdf);
            ASSERT_NEAR(glm::length(w), 1.f, 1e-5f);
            ASSERT_EQ(pdf, f->pdf(region, w));
        }
    }
}

TEST(VdbVolume, RunningMeanPerStratumAndEstimates) {
    auto f = makeVdb(foggyPlane(), {{"volume-voxel", "1"}, {"init", "0.5"}, {"smooth", "0"}});
    ASSERT_TRUE(f);
    activate(*f, {glm::vec3(0.5f, 0.5f, 0.25f)});
    const int r = f->lookupMedium(glm::vec3(0.5f, 0.5f, 0.25f));
    ASSERT_GE(r, 0);
    const glm::vec3 up(0.f, 0.f, 1.f), down(0.f, 0.f, -1.f);
    for (float t : {1.f, 2.f, 6.f}) {
        f->beginPass(1);
        f->record(0, r, up, t);
        f->record(0, r, down, 2.f * t);
        f->record(0, r, down, -1.f);   // rejected target
        f->record(0, r, up, NAN);      // rejected target
        f->endPass();
    }
    EXPECT_FLOAT_EQ(f->radiance(r, up), 3.f);    // (1 + 2 + 6) / 3
    EXPECT_FLOAT_EQ(f->radiance(r, down), 6.f);
    EXPECT_EQ(f->stats().rejectedTargets, 6u);
    // Uniform Q over the sphere: the cosine-weighted sum is pi * Q.
    auto g = makeVdb(foggyPlane(), {{"volume-voxel", "1"}, {"init", "2"}});
    activate(*g, {glm::vec3(0.5f, 0.5f, 0.25f)});
    const int rg = g->lookupMedium(glm::vec3(0.5f, 0.5f, 0.25f));
    EXPECT_NEAR(g->irradianceEstimate(rg, glm::normalize(glm::vec3(1.f, 2.f, 3.f))), 2.0 * M_PI,
                0.05);
    EXPECT_NEAR(g->scatteredEstimate(rg, [](const glm::vec3&) { return 1.f; }), 8.0 * M_PI, 1e-3);
}

TEST(VdbVolume, CapStopsActivation) {
    // max-mb leaves room for the surface tables and 10 medium voxels.
    VdbParams vp;
    vp.volumeVoxels = 64;
    const double surfaceMiB = vdbEstimatedBytes(vp, foggyPlane()) / (1024.0 * 1024.0);
    const double perVoxel = 2.0 * 64 * 24 + 64;
    char mb[32];
    std::snprintf(mb, sizeof(mb), "%.17g", surfaceMiB + 10.5 * perVoxel / (1024.0 * 1024.0));
    auto f = makeVdb(foggyPlane(), {{"volume-voxel", "64"}, {"max-mb", mb}});
    ASSERT_TRUE(f);
    EXPECT_EQ(f->volume()->params().maxVoxels, 10u);
    std::vector<glm::vec3> points;
    for (int i = 0; i < 64; ++i) points.emplace_back((i + 0.5f) / 64.f, 0.5f, 0.25f);
    activate(*f, points);
    const int cells = f->volume()->cells();
    EXPECT_EQ(cells, 10);
    EXPECT_EQ(f->lookupMedium(points[9]), f->numRegions() + 9);
    EXPECT_EQ(f->lookupMedium(points[10]), -1);
}

TEST(VdbVolume, SaveLoadRoundTripKeepsMediumTables) {
    const std::map<std::string, std::string> params{{"volume-voxel", "4"}};
    auto a = makeVdb(foggyPlane(), params);
    ASSERT_TRUE(a);
    const glm::vec3 p(0.3f, 0.6f, 0.2f), q(0.8f, 0.1f, 0.4f);
    activate(*a, {p, q});
    trainBright(*a, a->lookupMedium(p), glm::vec3(0.f, 0.f, -1.f), 2, 1);
    const std::string path = ::testing::TempDir() + "rlpbrt_vdb_volume_roundtrip.vdb";
    std::string error;
    ASSERT_TRUE(a->save(path, &error)) << error;
    auto b = makeVdb(foggyPlane(), params);
    ASSERT_TRUE(b->load(path, &error)) << error;
    EXPECT_EQ(b->volume()->cells(), 2);
    EXPECT_EQ(b->lookupMedium(p), a->lookupMedium(p));
    EXPECT_EQ(b->lookupMedium(q), a->lookupMedium(q));
    EXPECT_EQ(b->volume()->table().qTable(), a->volume()->table().qTable());
    EXPECT_EQ(b->volume()->table().visitTable(), a->volume()->table().visitTable());
    EXPECT_EQ(b->volume()->table().cdfTable(), a->volume()->table().cdfTable());
    EXPECT_EQ(b->confidence(b->lookupMedium(p)), a->confidence(a->lookupMedium(p)));
    EXPECT_EQ(b->stats().records, a->stats().records);
    // A field with other medium voxels, or none, refuses the file and stays unchanged.
    auto c = makeVdb(foggyPlane(), {{"volume-voxel", "8"}});
    EXPECT_FALSE(c->load(path, &error));
    EXPECT_NE(error.find("medium voxel size"), std::string::npos) << error;
    EXPECT_EQ(c->volume()->cells(), 0);
    auto d = makeVdb(foggyPlane(), {{"volume", "0"}});
    EXPECT_FALSE(d->load(path, &error));
    EXPECT_NE(error.find("medium tables"), std::string::npos) << error;
    // So does one whose medium tables have other strata.
    auto e = makeVdb(foggyPlane(), {{"volume-voxel", "4"}, {"volume-strata", "4"}});
    EXPECT_FALSE(e->load(path, &error));
    EXPECT_NE(error.find("volume-strata"), std::string::npos) << error;
    EXPECT_EQ(e->volume()->cells(), 0);
    std::remove(path.c_str());
}

}  // namespace
}  // namespace rlpbrt::guiding
