// Surface patches (render/patches.h): the cut counts per triangle, the budget, keys of real
// ray hits against the patches' centres (Embree's barycentric convention), no keys for
// quadrics, and the integrator's setup handing them to the hemi backend.
#include "render/patches.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <set>
#include <string>

#include "guiding/guiding.h"
#include "guiding/hemi.h"
#include "parser/diagnostics.h"
#include "render/integrator.h"
#include "render/scene.h"
#include "render/scene_builder.h"
#include "scene_text.h"

namespace rlpbrt {
namespace {

// A 2 x 2 quad at z = 0 (two triangles with edges 2, 2 and 2.83), a small triangle at z = 1
// (edges 0.1, 0.1, 0.14), a sphere away from both, and a mesh of one triangle as large as the
// quad's and one as small (x in [4, 6]).
const char* kScene = R"(
Film "image" "integer xresolution" [8] "integer yresolution" [8]
Sampler "random" "integer pixelsamples" [1]
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" [30]
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Material "matte"
Shape "trianglemesh" "point P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]
  "integer indices" [0 1 2  0 2 3]
Shape "trianglemesh" "point P" [3 3 1  3.1 3 1  3 3.1 1] "integer indices" [0 1 2]
AttributeBegin
  Translate -5 -5 0
  Shape "sphere" "float radius" [1]
AttributeEnd
Shape "trianglemesh" "point P" [4 -1 0  6 -1 0  6 1 0  5 1.5 0  5.1 1.5 0  5 1.6 0]
  "integer indices" [0 1 2  3 4 5]
WorldEnd
)";

std::unique_ptr<Scene> buildTestScene() {
    auto scene = test::sceneFromText(kScene, "patches.pbrt");
    EXPECT_NE(scene, nullptr);
    return scene;
}

// The hit of a ray straight down (-z) through (x, y) from above z.
bool hitDown(const Scene& scene, float x, float y, float z, SurfaceInteraction* si) {
    Ray ray(Vec3(x, y, z), Vec3(0.f, 0.f, -1.f));
    return scene.intersect(ray, si);
}

TEST(SurfacePatches, CutsPerTriangleFromTheLongestEdge) {
    auto scene = buildTestScene();
    ASSERT_TRUE(scene);
    // Size 0.25: the quad's triangles ceil(2.83 / 0.25) = 12 cuts (144 patches each), the small
    // triangle one patch, the last mesh 144 + 1.
    SurfacePatches patches(scene->worldPrimitives(), 0.25f, 1u << 20);
    EXPECT_EQ(patches.count(), 2u * 144u + 1u + 144u + 1u);
    EXPECT_EQ(patches.size(), 0.25f);
    // A budget below that grows the size until the patches fit.
    SurfacePatches tight(scene->worldPrimitives(), 0.25f, 100);
    EXPECT_LE(tight.count(), 100u);
    EXPECT_GE(tight.count(), 3u);
    EXPECT_GT(tight.size(), 0.25f);
    // A budget below the triangle count: no patches at all.
    SurfacePatches none(scene->worldPrimitives(), 0.25f, 2);
    EXPECT_EQ(none.count(), 0u);
    // A size that is not positive: one patch per triangle.
    SurfacePatches whole(scene->worldPrimitives(), 0.f, 1u << 20);
    EXPECT_EQ(whole.count(), 5u);
    // Every key of a hit is in range and kNone elsewhere.
    SurfaceInteraction si;
    ASSERT_TRUE(hitDown(*scene, -5.f, -5.f, 3.f, &si));  // the sphere
    EXPECT_EQ(patches.key(si), SurfacePatches::kNone);
    EXPECT_EQ(none.key(si), SurfacePatches::kNone);
    Vec3 p, n;
    EXPECT_FALSE(patches.centre(patches.count(), &p, &n));
    // Coordinates out of [0, 1] (rounding) or NaN clamp to the triangle's cells.
    SurfaceInteraction odd;
    odd.primitive = 0;  // the quad
    odd.primID = 1;     // its second triangle: patches [144, 288)
    for (Vec2 bary : {Vec2(-0.5f, 1.5f), Vec2(std::nanf(""), 2e30f), Vec2(1.f, 1.f)}) {
        odd.bary = bary;
        const uint32_t key = patches.key(odd);
        EXPECT_GE(key, 144u);
        EXPECT_LT(key, 288u);
    }
    odd.bary = Vec2(-0.5f, 1.5f);
    EXPECT_EQ(patches.key(odd), 144u + 11u);  // cell (0, 11)
}

// Each patch's centre, hit by a ray, gives back that patch's key; hits spread over the
// quad reach every patch, and a hit's point lies within a patch's size of its centre.
TEST(SurfacePatches, KeysOfHitsMatchThePatchCentres) {
    auto scene = buildTestScene();
    ASSERT_TRUE(scene);
    SurfacePatches patches(scene->worldPrimitives(), 0.25f, 1u << 20);
    // The quad's triangles come first: patches [0, 144) and [144, 288), cell (a, b) of the
    // barycentric square at a * 12 + b. Cells with a + b <= 11 reach into the triangle (the
    // others only touch its far edge).
    std::set<uint32_t> inside;
    for (uint32_t i = 0; i < 288; ++i)
        if ((i % 144) / 12 + (i % 144) % 12 <= 11) inside.insert(i);
    ASSERT_EQ(inside.size(), 2u * 78u);
    for (uint32_t i = 0; i < patches.count(); ++i) {
        Vec3 c, n;
        ASSERT_TRUE(patches.centre(i, &c, &n));
        EXPECT_NEAR(std::abs(n.z), 1.f, 1e-6f) << i;
        EXPECT_EQ(c.z, i == 288 ? 1.f : 0.f) << i;
        if (!inside.count(i)) continue;  // (the quad's cells past the far edge, the others)
        SurfaceInteraction si;
        ASSERT_TRUE(hitDown(*scene, c.x, c.y, 2.f, &si)) << i;
        EXPECT_EQ(patches.key(si), i);
    }
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> uni(-1.f, 1.f);
    std::set<uint32_t> reached;
    for (int q = 0; q < 20000; ++q) {
        SurfaceInteraction si;
        const float x = uni(rng), y = uni(rng);
        ASSERT_TRUE(hitDown(*scene, x, y, 0.5f, &si));
        const uint32_t key = patches.key(si);
        ASSERT_LT(key, patches.count());
        reached.insert(key);
        Vec3 c, n;
        ASSERT_TRUE(patches.centre(key, &c, &n));
        EXPECT_LT(glm::length(c - si.p), 0.25f * 1.5f) << q;
    }
    reached.erase(288);  // the small triangle, missed by these rays
    EXPECT_EQ(reached, inside);
    // The mixed mesh: its large triangle's cell (0, 0) is patch 289, its small triangle 433.
    for (uint32_t i : {289u, 300u, 433u}) {
        Vec3 c, n;
        ASSERT_TRUE(patches.centre(i, &c, &n));
        EXPECT_GT(c.x, 4.f);
        SurfaceInteraction si;
        ASSERT_TRUE(hitDown(*scene, c.x, c.y, 1.f, &si)) << i;
        EXPECT_EQ(patches.key(si), i);
    }
    SurfaceInteraction si;
    ASSERT_TRUE(hitDown(*scene, 3.02f, 3.02f, 2.f, &si));
    const uint32_t key = patches.key(si);
    ASSERT_LT(key, patches.count());
    Vec3 c, n;
    ASSERT_TRUE(patches.centre(key, &c, &n));
    EXPECT_NEAR(c.x, 3.f + 0.1f / 3.f, 1e-5f);
    EXPECT_NEAR(c.y, 3.f + 0.1f / 3.f, 1e-5f);
}

// setupGuiding gives the hemi backend patches of its points' spacing (lookup=patch, the
// default), and none with lookup=cell or without guiding.
TEST(SurfacePatches, SetupHandsThemToTheHemiBackend) {
    auto scene = buildTestScene();
    ASSERT_TRUE(scene);
    guiding::GuideConfig config;
    config.backend = "hemi";
    config.params["points"] = "256";
    std::unique_ptr<guiding::GuidingField> field;
    GuideSettings settings;
    std::string error;
    ASSERT_TRUE(setupGuiding(*scene, config, &field, &settings, &error)) << error;
    ASSERT_TRUE(settings.patches);
    const auto* hemi = dynamic_cast<const guiding::HemiField*>(field.get());
    ASSERT_NE(hemi, nullptr);
    EXPECT_EQ(settings.patches->size(), hemi->patchSize());
    EXPECT_GT(settings.patches->count(), 3u);
    EXPECT_EQ(hemi->numPatches(), settings.patches->count());
    // A vertex on the quad, through the patch interface: an admissible region of the floor.
    SurfaceInteraction si;
    ASSERT_TRUE(hitDown(*scene, 0.3f, -0.2f, 1.f, &si));
    const uint32_t key = settings.patches->key(si);
    ASSERT_LT(key, settings.patches->count());
    const int region = field->lookupPatch(key, si.p, Vec3(0.f, 0.f, 1.f));
    ASSERT_GE(region, 0);
    EXPECT_GE(hemi->regionNormal(region).z, std::cos(30.f * 3.14159265f / 180.f));
    EXPECT_GE(hemi->patchPoint(key), 0);

    config.params["lookup"] = "cell";
    ASSERT_TRUE(setupGuiding(*scene, config, &field, &settings, &error)) << error;
    EXPECT_FALSE(settings.patches);
    config.backend = "none";
    ASSERT_TRUE(setupGuiding(*scene, config, &field, &settings, &error)) << error;
    EXPECT_FALSE(settings.patches);
}

}  // namespace
}  // namespace rlpbrt
