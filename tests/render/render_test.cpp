// End-to-end properties of the render loop on small scenes written here.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "guiding/guiding.h"
#include "parser/diagnostics.h"
#include "render/render.h"
#include "render/scene.h"
#include "render/scene_builder.h"
#include "scene_text.h"

namespace rlpbrt {
namespace {

// A closed white diffuse box (albedo 0.5) with a ceiling light, 32x32 pixels.
const char* kBox = R"(
Film "image" "integer xresolution" [32] "integer yresolution" [32]
Sampler "sobol" "integer pixelsamples" [8]
Integrator "path" "integer maxdepth" [6]
LookAt 0 -0.9 0.5  0 0 0.5  0 0 1
Camera "perspective" "float fov" [60]
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [4 4 4]
  Shape "trianglemesh" "point P" [-0.2 -0.2 0.99  0.2 -0.2 0.99  0.2 0.2 0.99  -0.2 0.2 0.99]
        "integer indices" [0 2 1  0 3 2]
AttributeEnd
Material "matte" "rgb Kd" [0.5 0.5 0.5]
Shape "trianglemesh" "point P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0  -1 -1 1  1 -1 1  1 1 1  -1 1 1]
  "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 4 5 0 5 1  1 5 6 1 6 2  2 6 7 2 7 3  3 7 4 3 4 0]
WorldEnd
)";

std::unique_ptr<Scene> build(const char* text, int spp, uint64_t seed) {
    BuildOptions bo;
    bo.sppOverride = spp;
    bo.seed = seed;
    auto scene = test::sceneFromText(text, "box.pbrt", bo);
    EXPECT_NE(scene, nullptr);
    return scene;
}

// Same seed and thread count: bit-identical images (tiles merge in a fixed order and every
// sample value depends only on pixel, sample index and dimension).
TEST(Render, DeterministicForSeedAndThreads) {
    auto scene = build(kBox, 8, 7);
    RenderOptions ro;
    ro.nThreads = 2;
    RenderResult a = render(*scene, ro);
    RenderResult b = render(*scene, ro);
    ASSERT_EQ(a.image.pixels.size(), b.image.pixels.size());
    EXPECT_EQ(a.image.pixels, b.image.pixels);
    EXPECT_EQ(a.spp, 8);
}

// A different seed changes the noise, not the expectation: images differ.
TEST(Render, SeedChangesSamples) {
    RenderOptions ro;
    ro.nThreads = 1;
    RenderResult a = render(*build(kBox, 4, 1), ro);
    RenderResult b = render(*build(kBox, 4, 2), ro);
    EXPECT_NE(a.image.pixels, b.image.pixels);
}

// --time renders whole passes and stops within the budget plus one pass.
TEST(Render, TimeBudgetRendersWholePasses) {
    auto scene = build(kBox, 1, 0);
    RenderOptions ro;
    ro.nThreads = 1;
    ro.timeBudget = 0.5;
    RenderResult r = render(*scene, ro);
    EXPECT_GE(r.spp, 1);
    EXPECT_LT(r.seconds, 0.5 + 0.5);  // one pass of 32x32 pixels takes milliseconds
    bool finite = true;
    for (float v : r.image.pixels) finite &= std::isfinite(v);
    EXPECT_TRUE(finite);
}

// A render's passes grow with the samples so far (half of them, at most 64 spp) and take at
// most maxPassPaths camera paths, one sample per pixel at the least: the training records
// of a large image's pass stay within memory. A plain render's passes grow alike (one
// sample per pass before session 37: a wait at every pass's end).
TEST(Render, PassesGrowWithinTheirPathBudget) {
    constexpr int kSpp = 64;  // a power of two, as the sobol sampler rounds to
    auto scene = build(kBox, kSpp, 0);
    const long long pixels = Film(scene->filmParams, scene->filter).sampleBounds().area();
    // The samples each pass added, for a pass budget of `budget` paths (0: the default).
    auto passSizes = [&](const char* guide, long long budget) {
        guiding::GuideConfig gc;
        gc.backend = guide;
        std::unique_ptr<guiding::GuidingField> field;
        RenderOptions ro;
        std::string err;
        EXPECT_TRUE(setupGuiding(*scene, gc, &field, &ro.guide, &err)) << err;
        ro.nThreads = 1;
        if (budget > 0) ro.maxPassPaths = budget;
        std::vector<int> sizes;
        int before = 0;
        ro.onPass = [&](int spp, double, const Film&) {
            sizes.push_back(spp - before);
            before = spp;
        };
        const RenderResult r = render(*scene, ro);
        EXPECT_EQ(r.spp, kSpp);
        EXPECT_EQ(r.passes, int(sizes.size()));
        return sizes;
    };
    // Halves of the samples so far: 1, 1, 1, 1, 2, 3, 4, 6, 9, 14, 21, then the 1 left.
    const std::vector<int> halves{1, 1, 1, 1, 2, 3, 4, 6, 9, 14, 21, 1};
    EXPECT_EQ(passSizes("hemi", 0), halves);
    // A budget of 3 samples per pixel (and a bit): no pass above 3.
    const std::vector<int> three = passSizes("hemi", 3 * pixels + pixels / 2);
    EXPECT_EQ(*std::max_element(three.begin(), three.end()), 3);
    // Below one sample per pixel: one per pass.
    EXPECT_EQ(passSizes("hemi", pixels / 2), std::vector<int>(kSpp, 1));
    EXPECT_EQ(passSizes("none", 0), halves);
    EXPECT_EQ(passSizes("none", pixels / 2), std::vector<int>(kSpp, 1));
}

// A cancel flag set before rendering stops after the first pass with that pass's image.
TEST(Render, CancelStopsAfterAPass) {
    auto scene = build(kBox, 64, 0);
    std::atomic<bool> cancel{true};
    RenderOptions ro;
    ro.nThreads = 1;
    ro.cancel = &cancel;
    RenderResult r = render(*scene, ro);
    EXPECT_TRUE(r.cancelled);
    EXPECT_EQ(r.spp, 1);
}

}  // namespace
}  // namespace rlpbrt
