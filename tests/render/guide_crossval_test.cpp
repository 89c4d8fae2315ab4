// Cross-validation of the guiding backends: on the same scene and seed, the images of
// --guide=none, hemi and vdb must have the same expectation (guiding changes the noise only).
// For each pair the difference image D = A - B has expectation 0 at every pixel. It is cut
// into 20x20-pixel blocks whose means m_b are independent, zero-mean estimates (the pixel
// filter correlates only pixels near block edges); the standard error of mean(D) is then
// sqrt(sum m_b^2) / B, and |mean(D)| must stay within 4 of them (per channel).
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "guiding/guiding.h"
#include "parser/diagnostics.h"
#include "render/render.h"
#include "render/scene.h"
#include "render/scene_builder.h"
#include "shared_data.h"

namespace rlpbrt {
namespace {

struct Rendered {
    Image image;
    guiding::GuidingStats stats;
    RenderResult::AutoTrial autoTrial;
};

Rendered renderWith(const std::string& scenePath, const char* backend, int spp,
                    const std::map<std::string, std::string>& params = {}) {
    Diagnostics diag;
    diag.setStream(nullptr);
    SceneDesc desc;
    EXPECT_TRUE(loadSceneDesc(scenePath, diag, &desc));
    BuildOptions bo;
    bo.sppOverride = spp;
    bo.seed = 7;
    std::unique_ptr<Scene> scene = buildScene(desc, bo, diag);
    EXPECT_NE(scene, nullptr);
    if (!scene) return {};
    guiding::GuideConfig gc;
    gc.backend = backend;
    gc.params = params;
    std::unique_ptr<guiding::GuidingField> field;
    RenderOptions ro;
    std::string err;
    EXPECT_TRUE(setupGuiding(*scene, gc, &field, &ro.guide, &err)) << err;
    ro.nThreads = 1;  // CTest runs tests in parallel
    Rendered out;
    RenderResult r = render(*scene, ro);
    out.image = std::move(r.image);
    out.autoTrial = r.autoTrial;
    if (field) out.stats = field->stats();
    return out;
}

// |mean(A - B)| in units of its standard error from 20x20 block means, per channel.
void expectSameMean(const Image& a, const Image& b, const char* what) {
    ASSERT_EQ(a.width, b.width);
    ASSERT_EQ(a.height, b.height);
    constexpr int kBlock = 20;
    const int bx = a.width / kBlock, by = a.height / kBlock;
    ASSERT_GE(bx * by, 50);
    for (int c = 0; c < 3; ++c) {
        double sum = 0.0, sumSq = 0.0, meanA = 0.0;
        for (int j = 0; j < by; ++j)
            for (int i = 0; i < bx; ++i) {
                double m = 0.0;
                for (int y = j * kBlock; y < (j + 1) * kBlock; ++y)
                    for (int x = i * kBlock; x < (i + 1) * kBlock; ++x) {
                        m += double(a.at(x, y, c)) - double(b.at(x, y, c));
                        meanA += a.at(x, y, c);
                    }
                m /= kBlock * kBlock;
                sum += m;
                sumSq += m * m;
            }
        const double blocks = double(bx * by);
        const double mean = sum / blocks, se = std::sqrt(sumSq) / blocks;
        meanA /= blocks * kBlock * kBlock;
        std::printf("%s channel %d: mean %.6g, difference %.3g +- %.3g (%.2f sigma)\n", what, c,
                    meanA, mean, se, se > 0 ? std::abs(mean) / se : 0.0);
        EXPECT_GT(se, 0.0) << what << ": identical images (the guide was not used?)";
        EXPECT_LE(std::abs(mean), 4.0 * se) << what << " channel " << c;
    }
}

TEST(GuideCrossValidation, NoneHemiVdbAgreeOnCornellBox) {
    RLPBRT_REQUIRE_SHARED();
    const std::string scene = test::sharedDir() + "/scenes/cornell-box/scene.small.pbrt";
    const int spp = 16;
    Rendered none = renderWith(scene, "none", spp);
    Rendered hemi = renderWith(scene, "hemi", spp);
    Rendered vdb = renderWith(scene, "vdb", spp);
    ASSERT_FALSE(none.image.empty());
    EXPECT_GT(hemi.stats.records, 0u);
    EXPECT_GT(vdb.stats.records, 0u);
    EXPECT_GT(vdb.stats.activeVoxels, 0u);
    expectSameMean(hemi.image, none.image, "hemi - none");
    expectSameMean(vdb.image, none.image, "vdb - none");
    expectSameMean(hemi.image, vdb.image, "hemi - vdb");
}

// The integrator's own --guide-param keys: mix (a number or "learn"), target, samples.
TEST(GuideCrossValidation, IntegratorParametersAreValidated) {
    RLPBRT_REQUIRE_SHARED();
    Diagnostics diag;
    diag.setStream(nullptr);
    SceneDesc desc;
    ASSERT_TRUE(loadSceneDesc(test::sharedDir() + "/scenes/cornell-box/scene.small.pbrt", diag,
                              &desc));
    std::unique_ptr<Scene> scene = buildScene(desc, BuildOptions(), diag);
    ASSERT_NE(scene, nullptr);
    auto setup = [&](const std::map<std::string, std::string>& params, GuideSettings* gs,
                     std::string* err) {
        guiding::GuideConfig gc;
        gc.backend = "hemi";
        gc.params = params;
        std::unique_ptr<guiding::GuidingField> field;
        return setupGuiding(*scene, gc, &field, gs, err);
    };
    GuideSettings gs;
    std::string err;
    ASSERT_TRUE(setup({{"mix", "learn"}, {"samples", "independent"}}, &gs, &err)) << err;
    EXPECT_TRUE(gs.learnMix);
    EXPECT_TRUE(gs.independentPasses);
    EXPECT_FLOAT_EQ(gs.mix, 0.5f);  // the value where no selection is learned yet
    ASSERT_TRUE(setup({{"mix", "0.25"}, {"samples", "sequence"}}, &gs, &err)) << err;
    EXPECT_FALSE(gs.learnMix);
    EXPECT_FALSE(gs.independentPasses);
    EXPECT_FLOAT_EQ(gs.mix, 0.25f);
    EXPECT_EQ(gs.autoSpp, 0);  // always guide unless asked
    ASSERT_TRUE(setup({{"auto", "16"}}, &gs, &err)) << err;
    EXPECT_EQ(gs.autoSpp, 16);
    EXPECT_TRUE(gs.adjointRoulette);  // the default
    ASSERT_TRUE(setup({{"rr", "pbrt"}}, &gs, &err)) << err;
    EXPECT_FALSE(gs.adjointRoulette);
    ASSERT_TRUE(setup({{"rr", "adjoint"}}, &gs, &err)) << err;
    EXPECT_TRUE(gs.adjointRoulette);
    EXPECT_FLOAT_EQ(gs.rouletteWindow, 0.1f);  // the default
    ASSERT_TRUE(setup({{"rr-window", "0.25"}}, &gs, &err)) << err;
    EXPECT_FLOAT_EQ(gs.rouletteWindow, 0.25f);
    EXPECT_EQ(gs.learnSpp, -1);  // the default: learn in every pass
    ASSERT_TRUE(setup({{"learn", "16"}}, &gs, &err)) << err;
    EXPECT_EQ(gs.learnSpp, 16);
    ASSERT_TRUE(setup({{"learn", "all"}}, &gs, &err)) << err;
    EXPECT_EQ(gs.learnSpp, -1);
    for (const auto& bad : std::vector<std::map<std::string, std::string>>{
             {{"mix", "learnt"}}, {{"mix", "1.5"}}, {{"samples", "random"}},
             {{"target", "all"}}, {{"auto", "-1"}}, {{"auto", "16x"}}, {{"auto", ""}},
             {{"rr", "russian"}}, {{"rr-window", "0"}}, {{"rr-window", "1.5"}},
             {{"rr-window", "wide"}}, {{"learn", "-2"}}, {{"learn", "some"}}}) {
        err.clear();
        EXPECT_FALSE(setup(bad, &gs, &err)) << bad.begin()->first;
        EXPECT_NE(err.find(bad.begin()->first), std::string::npos) << err;
    }
}

// A guided render's passes continue the one sequence per pixel of a plain render (the default,
// samples=sequence): with mix=0 the guide learns but never samples, so every path takes the
// same sampler dimensions as without guiding, and the images agree up to the summation order
// of the passes (relative 1e-5). With samples=independent each pass draws its own set, and
// the images differ by the noise.
TEST(GuideCrossValidation, GuidedPassesContinueThePixelSequence) {
    RLPBRT_REQUIRE_SHARED();
    const std::string scene = test::sharedDir() + "/scenes/cornell-box/scene.small.pbrt";
    const int spp = 16;
    Rendered none = renderWith(scene, "none", spp);
    // (lights=scene: the learned light choice would change next-event estimation.)
    Rendered seq = renderWith(scene, "hemi", spp, {{"mix", "0"}, {"lights", "scene"}});
    Rendered own = renderWith(scene, "hemi", spp,
                              {{"mix", "0"}, {"lights", "scene"}, {"samples", "independent"}});
    ASSERT_FALSE(none.image.empty());
    EXPECT_GT(seq.stats.records, 0u);
    auto relDiff = [&](const Image& a) {
        double diff = 0.0, sum = 0.0;
        for (int y = 0; y < a.height; ++y)
            for (int x = 0; x < a.width; ++x)
                for (int c = 0; c < 3; ++c) {
                    diff += std::abs(double(a.at(x, y, c)) - double(none.image.at(x, y, c)));
                    sum += std::abs(double(none.image.at(x, y, c)));
                }
        return diff / sum;
    };
    EXPECT_LT(relDiff(seq.image), 1e-5);
    EXPECT_GT(relDiff(own.image), 1e-2);

    // The auto trial's plain pass and the plain passes after it continue the same sequence:
    // with mix=0 the guided passes sample as plain ones do, so guided and plain cost the same
    // per sample up to the learning, the trial runs (at 4 spp: guided pass 4..6, plain pass
    // 6..8) and the image equals the plain render if the verdict is off. If guiding stays, the
    // trial's plain samples weigh w = guided / plain variance (two estimates of one variance
    // here), which moves the image by at most |1 - w| of it.
    Rendered trial =
        renderWith(scene, "hemi", spp, {{"mix", "0"}, {"lights", "scene"}, {"auto", "4"}});
    EXPECT_TRUE(trial.autoTrial.ran);
    EXPECT_GT(trial.autoTrial.guidedCost, 0.0);
    EXPECT_GT(trial.autoTrial.plainCost, 0.0);
    EXPECT_EQ(trial.autoTrial.guidedSpp, trial.autoTrial.keptGuiding ? spp : 6);
    const double w = trial.autoTrial.guidedCost / trial.autoTrial.plainCost;
    EXPECT_LT(relDiff(trial.image), 1e-5 + (trial.autoTrial.keptGuiding ? std::abs(1.0 - w) : 0.0))
        << "kept " << trial.autoTrial.keptGuiding << ", w " << w;
}

}  // namespace
}  // namespace rlpbrt
