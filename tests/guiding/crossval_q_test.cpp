// Cross-validation of the learned Q: hemi and vdb, fed the same sample stream, learn the same
// incident radiance where both have data.
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "guiding/hemi.h"
#include "guiding/vdb.h"
#include "test_scenes.h"

namespace rlpbrt::guiding {
namespace {

using test::planeScene;

std::unique_ptr<GuidingField> make(const std::string& backend,
                                   const std::map<std::string, std::string>& params) {
    GuideConfig c;
    c.backend = backend;
    c.params = params;
    std::string error;
    auto f = createGuidingField(c, planeScene(), &error);
    EXPECT_TRUE(f) << error;
    return f;
}

// Running moments of the targets one (region, stratum) cell received.
struct Cell {
    double n = 0, sum = 0, sum2 = 0;
    void add(double x) {
        n += 1;
        sum += x;
        sum2 += x * x;
    }
    double var() const { return n > 1 ? (sum2 - sum * sum / n) / (n - 1) : 0.0; }
};

// The stream: points uniform on the unit plane, directions uniform over the upper
// hemisphere, target g(w) = 3 + 4 z^2 + 2 x (a direction-only radiance, so every region's
// stratum converges to the stratum mean of g whatever its spatial extent). With
// alpha = 1/(1 + visits), Q is exactly the mean of a cell's targets. Both fields use the
// same strata around the same normal (+z), so at every stratum centre the two Q values
// estimate the same number: they must agree within 5 standard errors of their difference
// (each from its cell's sample variance and count).
TEST(GuideCrossValidation, HemiAndVdbLearnTheSameQ) {
    // (smooth=0: radiance() is then Q itself, the running mean compared below; learn-cap=0:
    // the mean of every record, however many a cell takes; judge=0: hemi's learning goes on
    // where its guide would gain nothing)
    auto hemi = make("hemi", {{"points", "16"}, {"strata", "4x4"}, {"smooth", "0"},
                              {"learn-cap", "0"}, {"judge", "0"}});
    auto vdb = make("vdb",
                    {{"voxel", "4"}, {"strata", "4x4"}, {"smooth", "0"}, {"learn-cap", "0"}});
    ASSERT_TRUE(hemi && vdb);
    auto* h = dynamic_cast<HemiField*>(hemi.get());
    auto* v = dynamic_cast<VdbField*>(vdb.get());
    ASSERT_TRUE(h && v);
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    std::map<std::pair<int, int>, Cell> hc, vc;
    const glm::vec3 up(0.f, 0.f, 1.f);
    for (int pass = 0; pass < 4; ++pass) {
        hemi->beginPass(1);
        vdb->beginPass(1);
        for (int i = 0; i < 100000; ++i) {
            glm::vec3 p(u(rng), u(rng), 0.f);
            glm::vec3 w = test::gaussianDirection(rng);
            w.z = std::abs(w.z);
            if (!(w.z > 1e-3f)) continue;
            const float g = 3.f + 4.f * w.z * w.z + 2.f * w.x;
            const int rh = hemi->lookup(p, up), rv = vdb->lookup(p, up);
            ASSERT_GE(rh, 0);
            ASSERT_GE(rv, 0);
            hemi->record(0, rh, w, g);
            vdb->record(0, rv, w, g);
            hc[{rh, h->stratumOf(rh, w)}].add(g);
            vc[{rv, v->stratumOf(rv, w)}].add(g);
        }
        hemi->endPass();
        vdb->endPass();
    }
    int compared = 0;
    for (int k = 0; k < 400; ++k) {
        glm::vec3 p(u(rng), u(rng), 0.f);
        const int rh = hemi->lookup(p, up), rv = vdb->lookup(p, up);
        ASSERT_GE(rh, 0);
        ASSERT_GE(rv, 0);
        for (int j = 0; j < 16; ++j) {
            // Centre of hemi's stratum j, and the same direction in vdb's strata.
            const glm::vec3 w = Frame::fromZ(h->regionNormal(rh)).toWorld(h->layout().centre(j));
            const Cell& a = hc[{rh, j}];
            const Cell& b = vc[{rv, v->stratumOf(rv, w)}];
            ASSERT_GT(a.n, 30);
            ASSERT_GT(b.n, 30);
            const double qh = hemi->radiance(rh, w), qv = vdb->radiance(rv, w);
            EXPECT_NEAR(qh, a.sum / a.n, 1e-4 * qh);  // Q is the cell mean (running mean)
            EXPECT_NEAR(qv, b.sum / b.n, 1e-4 * qv);
            const double se = std::sqrt(a.var() / a.n + b.var() / b.n);
            EXPECT_NEAR(qh, qv, 5.0 * se) << "probe " << k << " stratum " << j;
            ++compared;
        }
    }
    EXPECT_EQ(compared, 400 * 16);
}

}  // namespace
}  // namespace rlpbrt::guiding
