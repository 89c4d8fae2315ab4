// What the integrator teaches a guiding field: with target=path (the default) each guided
// vertex is trained on the radiance its sampled direction brought back as the estimator counts
// it (emission with its MIS weight against next-event estimation, not the vertex's own NEE);
// with Eq. 1's targets (target=sample) on the full emission. A recording field with a known
// policy on a diffuse plane under a uniform sky makes both exact per record.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <vector>

#include "guiding/guiding.h"
#include "parser/diagnostics.h"
#include "render/integrator.h"
#include "render/sampler.h"
#include "render/sampling.h"
#include "render/scene.h"
#include "render/scene_builder.h"
#include "scene_text.h"

namespace rlpbrt {
namespace {


// One region everywhere, uniform over the upper hemisphere (z > 0), recording every target
// and counting its lookups and samples. Its bins: 0 below 60 degrees from the normal, 1 above
// (-1 outside the hemisphere).
class RecordingField final : public guiding::GuidingField {
public:
    struct Record {
        glm::vec3 w;
        float target;
        int bin;  // as passed to record()
    };
    static int binOf(const glm::vec3& w) { return w.z > 0.5f ? 0 : w.z > 0.f ? 1 : -1; }
    int locate(const guiding::VertexQuery& q) const override {
        ++lookups;
        return !q.medium && q.n.z > 0.f ? 0 : -1;
    }
    glm::vec3 sample(int, glm::vec2 u, float, float* pdf, int* bin) const override {
        ++samples;
        const float z = u.x, r = std::sqrt(std::max(0.f, 1.f - z * z)), phi = 2.f * Pi * u.y;
        const glm::vec3 w(r * std::cos(phi), r * std::sin(phi), z);
        *pdf = this->pdf(0, w, bin);
        return w;
    }
    float pdf(int, const glm::vec3& w, int* bin) const override {
        if (bin) *bin = binOf(w);
        return w.z > 0.f ? 1.f / (2.f * Pi) : 0.f;
    }
    float scatteredEstimate(int, const std::function<float(const glm::vec3&)>&) const override {
        return 0.f;
    }
    float radiance(int, const glm::vec3&, int) const override { return 0.f; }
    float irradianceEstimate(int, const glm::vec3&) const override { return irradiance; }
    void beginPass(int) override {}
    void record(int, int region, const glm::vec3& w, float target, int bin) override {
        std::lock_guard<std::mutex> lock(mutex_);
        EXPECT_EQ(region, 0);
        records.push_back(Record{w, target, bin});
    }
    void endPass() override {}
    size_t bytes() const override { return 0; }
    std::string describe() const override { return "recording"; }
    guiding::GuidingStats stats() const override { return {}; }

    std::vector<Record> records;
    mutable std::atomic<int> lookups{0}, samples{0};
    float irradiance = 0.f;  // what irradianceEstimate answers (splitting's expectation)

private:
    std::mutex mutex_;
};

// A large white-ish diffuse plane at z = 0 under a uniform sky of radiance 1; maxdepth given
// (by default 2: the plane's vertex does not sample the path's last direction).
const char* kPlane = R"(
Film "image" "integer xresolution" [8] "integer yresolution" [8]
Sampler "random" "integer pixelsamples" [1]
Integrator "path" "integer maxdepth" [%d]
LookAt 0 0 1  0 0 0  0 1 0
Camera "perspective" "float fov" [30]
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Material "matte" "rgb Kd" [0.5 0.5 0.5]
Shape "trianglemesh" "point P" [-100 -100 0  100 -100 0  100 100 0  -100 100 0]
  "integer indices" [0 1 2  0 2 3]
WorldEnd
)";

std::unique_ptr<Scene> buildPlane(int maxDepth = 2) {
    char text[1024];
    std::snprintf(text, sizeof(text), kPlane, maxDepth);
    auto scene = test::sceneFromText(text, "plane.pbrt");
    EXPECT_NE(scene, nullptr);
    return scene;
}

// Renders 2000 paths straight down at the plane into `field`; returns its records. split:
// GuideSettings::splitMax, with a window that splits every path at its guided vertex.
std::vector<RecordingField::Record> train(const Scene& scene, bool pathTarget,
                                          RecordingField* into = nullptr, int split = 1) {
    RecordingField local;
    RecordingField& field = into ? *into : local;
    GuideSettings gs;
    gs.field = &field;
    gs.mix = 0.5f;
    gs.pathTarget = pathTarget;
    gs.splitMax = split;
    gs.splitWindow = 1e-3f;
    field.irradiance = split > 1 ? 1.f : 0.f;
    PathIntegrator integrator(scene, gs);
    IndependentSampler sampler(1, 3);
    PathStats stats;
    field.beginPass(1);
    for (int i = 0; i < 2000; ++i) {
        sampler.startPixelSample(i % 40, i / 40, 0);
        const Ray ray(Vec3(0.01f * float(i % 40) - 0.2f, 0.01f * float(i / 40) - 0.25f, 1.f),
                      Vec3(0.f, 0.f, -1.f));
        integrator.Li(ray, sampler, stats, 0, /*pixelEstimate=*/split > 1 ? 1.f : 0.f);
    }
    field.endPass();
    return field.records;
}

// What direction w of the plane's vertex brings back from the sky as the estimator counts
// it: the sky's luminance, MIS-weighted against next-event estimation with the direction's
// mixture pdf (half the guide's uniform hemisphere, half Lambertian).
float skyReturn(const Light& sky, const glm::vec3& w) {
    const float dirPdf = 0.5f / (2.f * Pi) + 0.5f * w.z / Pi;
    const LightSampleContext ctx{Vec3(0.f), Vec3(0.f, 0.f, 1.f)};
    const float lightPdf = sky.pdfLi(ctx, w, Vec3(0.f), Vec3(0.f));
    return luminance(Spectrum(1.f)) * powerHeuristic(1, dirPdf, 1, lightPdf);
}

TEST(GuideTargets, PathTargetIsTheMisWeightedReturnOfTheDirection) {
    auto scene = buildPlane();
    ASSERT_TRUE(scene);
    ASSERT_EQ(scene->lights.size(), 1u);
    const Light& sky = *scene->lights[0];
    const auto records = train(*scene, true);
    ASSERT_GT(records.size(), 1900u);  // every path escapes from its one guided vertex
    const float lumSky = luminance(Spectrum(1.f));
    double meanTarget = 0.0;
    for (const auto& r : records) {
        ASSERT_GT(r.w.z, 0.f);
        // Guided or drawn from the BSDF, the direction's bin found by sample() or pdf() comes
        // back with its record (the field need not find it again).
        EXPECT_EQ(r.bin, RecordingField::binOf(r.w)) << r.w.z;
        const float expected = skyReturn(sky, r.w);
        EXPECT_NEAR(r.target, expected, 2e-3f * expected + 1e-6f) << r.w.z;
        meanTarget += r.target;
    }
    // Strictly less than the sky's radiance: next-event estimation delivers the rest.
    meanTarget /= double(records.size());
    EXPECT_GT(meanTarget, 0.2);
    EXPECT_LT(meanTarget, 0.95 * lumSky);
}

// A split path (split=N): every branch's direction is a return of its own, trained on what
// that branch alone brought back, exactly as an unsplit path's (its throughput's share 1 / r
// divides out).
TEST(GuideTargets, EveryBranchOfASplitPathLearnsItsOwnReturn) {
    auto scene = buildPlane();
    ASSERT_TRUE(scene);
    const Light& sky = *scene->lights[0];
    const auto records = train(*scene, true, nullptr, 4);
    // About 4 branches per path (each is a record; a few directions leave the hemisphere's
    // bins or are rejected by the BSDF).
    ASSERT_GT(records.size(), 3 * 1900u);
    ASSERT_LT(records.size(), 4 * 2000u + 1);
    for (const auto& r : records) {
        ASSERT_GT(r.w.z, 0.f);
        EXPECT_EQ(r.bin, RecordingField::binOf(r.w)) << r.w.z;
        const float expected = skyReturn(sky, r.w);
        EXPECT_NEAR(r.target, expected, 2e-3f * expected + 1e-6f) << r.w.z;
    }
}

TEST(GuideTargets, EquationOneTargetIsTheFullEmission) {
    auto scene = buildPlane();
    ASSERT_TRUE(scene);
    const auto records = train(*scene, false);
    ASSERT_GT(records.size(), 1900u);
    for (const auto& r : records) {
        EXPECT_NEAR(r.target, luminance(Spectrum(1.f)), 1e-5f);
        EXPECT_EQ(r.bin, RecordingField::binOf(r.w)) << r.w.z;
    }
}

// The path's last direction (here the only one, maxdepth 1) brings back only emission that
// next-event estimation also samples: it is drawn from the BSDF, and with path targets it
// neither looks up a region nor records a return; Eq. 1 targets are still learned there.
TEST(GuideTargets, TheLastDirectionIsNotGuided) {
    auto one = buildPlane(1);
    ASSERT_TRUE(one);
    RecordingField returns;
    EXPECT_TRUE(train(*one, true, &returns).empty());
    EXPECT_EQ(returns.lookups.load(), 0);
    EXPECT_EQ(returns.samples.load(), 0);
    RecordingField eq1;
    EXPECT_GT(train(*one, false, &eq1).size(), 1900u);
    EXPECT_GT(eq1.lookups.load(), 1900);
    EXPECT_EQ(eq1.samples.load(), 0);
    // With one more bounce allowed the plane's vertex is guided: about half its directions
    // (mix 0.5) come from the field (binomial, n = 2000: sd 22).
    auto two = buildPlane(2);
    ASSERT_TRUE(two);
    RecordingField guided;
    EXPECT_GT(train(*two, true, &guided).size(), 1900u);
    EXPECT_NEAR(guided.samples.load(), 1000, 120);
}

}  // namespace
}  // namespace rlpbrt
