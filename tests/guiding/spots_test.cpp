// Tests of the spot lobes (guiding/spots.h) and of hemi's mixture of strata and lobes
// (spots=N): the von Mises-Fisher lobe's sampling against its pdf (chi-square) and its unit
// integral, a trained field's sampleAt against pdfAt over the sphere, trained and untrained,
// the lobes' samples kept out of the strata's means, and the lobes saved and restored
// (--guide-save, checkpoints).
#include "guiding/spots.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "guiding/hemi.h"
#include "guiding/test_scenes.h"
#include "render/chi2.h"

namespace rlpbrt::guiding {
namespace {

using test::planeScene;
using test::trainBright;

// The integral of vmfPdf over the sphere: 2 pi times a quadrature over t = 1 - cos(theta) in
// [0, 2] on a geometric grid (the density falls as e^(-kappa t)).
double vmfIntegral(float kappa) {
    double sum = 0.0, t0 = 0.0;
    for (double t1 = 1e-9; t0 < 2.0; t1 = std::min(2.0, t1 * 1.001)) {
        const double tm = 0.5 * (t0 + t1);
        sum += double(vmfPdf(kappa, float(1.0 - tm))) * (t1 - t0);
        t0 = t1;
    }
    return 2.0 * 3.14159265358979 * sum;
}

TEST(VonMisesFisher, PdfIntegratesToOne) {
    for (float kappa : {0.5f, 20.f, 1600.f, 2e4f})
        EXPECT_NEAR(vmfIntegral(kappa), 1.0, 2e-3) << "kappa " << kappa;
}

// cos(theta) about the mean falls in bins of t = 1 - cos with probabilities from the closed
// form (e^(-kappa t0) - e^(-kappa t1)) / (1 - e^(-2 kappa)); phi is uniform.
TEST(VonMisesFisher, SamplesMatchThePdfExactly) {
    const glm::vec3 mean = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
    const Frame frame = Frame::fromZ(mean);
    for (float kappa : {0.5f, 20.f, 1600.f, 2e4f}) {
        const int tBins = 16, phiBins = 8, n = 400000;
        std::vector<double> observed(size_t(tBins * phiBins), 0.0), expected(observed.size());
        // Bin edges at quantiles of t, so that every bin expects the same mass.
        std::vector<double> edges(size_t(tBins + 1));
        const double norm = -std::expm1(-2.0 * double(kappa));
        for (int i = 0; i <= tBins; ++i)
            edges[size_t(i)] = -std::log1p(-norm * double(i) / tBins) / double(kappa);
        edges[size_t(tBins)] = 2.0;
        for (double& e : expected) e = double(n) / double(tBins * phiBins);
        std::mt19937_64 rng(17 + uint64_t(kappa));
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        for (int i = 0; i < n; ++i) {
            const glm::vec3 w = vmfSample(mean, kappa, glm::vec2(uni(rng), uni(rng)));
            ASSERT_NEAR(glm::length(w), 1.f, 1e-4f);
            const glm::vec3 l = frame.toLocal(w);
            const double t = 1.0 - double(l.z);
            int tb = int(std::upper_bound(edges.begin(), edges.end(), t) - edges.begin()) - 1;
            tb = std::clamp(tb, 0, tBins - 1);
            double phi = std::atan2(double(l.y), double(l.x));
            if (phi < 0.0) phi += 2.0 * 3.14159265358979;
            const int pb = std::clamp(int(phi / (2.0 * 3.14159265358979) * phiBins), 0, phiBins - 1);
            observed[size_t(tb * phiBins + pb)] += 1.0;
        }
        // At kappa 2e4 float directions resolve t down to ~1e-7 (bins of width 1e-6 and
        // up): the rounding of the frame moves few samples across an edge.
        chi2::Result r = chi2::testCounts(observed, expected, 0.01, 4);
        EXPECT_TRUE(r.passed) << "kappa " << kappa << ": " << r.message;
    }
}

std::unique_ptr<HemiField> makeHemi(std::map<std::string, std::string> params) {
    return test::makeField<HemiField>("hemi", planeScene(), std::move(params));
}

// Candidates of a spot: from points x of the region around xc, directions to hits scattered
// by `jitter` around `spot`, each bringing `light`.
void trainSpot(HemiField& f, int region, const glm::vec3& xc, const glm::vec3& spot,
               float jitter, float light, int passes, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<float> g(0.f, 1.f);
    for (int p = 0; p < passes; ++p) {
        f.beginPass(1);
        for (int i = 0; i < 200; ++i) {
            const glm::vec3 x = xc + 0.05f * glm::vec3(g(rng), g(rng), 0.f);
            const glm::vec3 hit = spot + jitter * glm::vec3(g(rng), g(rng), g(rng));
            f.recordSpot(0, region, x, glm::normalize(hit - x), hit, light);
        }
        f.endPass();
    }
}

TEST(HemiSpots, RefusedWithTreeDirections) {
    GuideConfig cfg;
    cfg.backend = "hemi";
    cfg.params = {{"spots", "2"}, {"directions", "tree"}};
    std::string error;
    EXPECT_FALSE(createGuidingField(cfg, planeScene(), &error));
    EXPECT_NE(error.find("directions=strata"), std::string::npos) << error;
}

TEST(HemiSpots, UntrainedFieldIsTheStrata) {
    auto f = makeHemi({{"points", "16"}, {"spots", "4"}, {"warmup", "0"}});
    ASSERT_TRUE(f);
    const glm::vec3 x(0.5f, 0.5f, 0.f), w = glm::normalize(glm::vec3(0.2f, 0.1f, 1.f));
    EXPECT_EQ(f->pdfAt(4, x, w), f->pdf(4, w));
    EXPECT_EQ(f->spots()->activeLobes(), 0u);
    chi2::SphereResult r = test::sphereTestAt(*f, 4, x, 11);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdfIntegral, 1.0, 2e-3);
}

TEST(HemiSpots, TrainedLobesAimAtTheSpotAndMatchTheirPdf) {
    auto f = makeHemi({{"points", "16"}, {"spots", "2"}, {"warmup", "0"}, {"spot-judge", "0"}});
    ASSERT_TRUE(f);
    const int region = 4;
    trainBright(*f, region, glm::vec3(0.f, 0.f, 1.f), 1, 3);  // Q ~ 0.05 .. 100
    const glm::vec3 xc = f->regionPosition(region);
    const glm::vec3 spot = xc + glm::vec3(0.6f, -0.3f, 0.5f);
    trainSpot(*f, region, xc, spot, 0.02f, 1e4f, 2, 5);
    ASSERT_GT(f->spots()->activeLobes(), 0u);
    const float share = f->spots()->share(region);
    EXPECT_GT(share, 0.f);
    EXPECT_LE(share, 0.5f);
    // From two places in the region the lobe aims at the spot (a point: the records came
    // from many places), so the pdf toward it is far above the strata's.
    for (const glm::vec3& x : {xc, xc + glm::vec3(0.08f, 0.05f, 0.f)}) {
        const glm::vec3 toSpot = glm::normalize(spot - x);
        EXPECT_GT(f->pdfAt(region, x, toSpot), 20.f * f->pdf(region, toSpot));
        chi2::SphereResult r = test::sphereTestAt(*f, region, x, 21);
        EXPECT_TRUE(r.passed) << r.message;
        EXPECT_NEAR(r.pdfIntegral, 1.0, 3e-3);
    }
    // Dim candidates (below spot-outlier x the stratum's Q) shape nothing.
    auto g = makeHemi({{"points", "16"}, {"spots", "2"}, {"warmup", "0"}, {"spot-judge", "0"}});
    trainBright(*g, region, glm::vec3(0.f, 0.f, 1.f), 1, 3);
    trainSpot(*g, region, xc, spot, 0.02f, 1e-3f, 2, 5);
    EXPECT_EQ(g->spots()->activeLobes(), 0u);
}

TEST(HemiSpots, LobeSamplesStayOutOfTheStrata) {
    auto f = makeHemi({{"points", "16"}, {"spots", "1"}, {"warmup", "0"},
                       {"spot-share", "1"}, {"spot-judge", "0"}});
    ASSERT_TRUE(f);
    const int region = 4;
    trainBright(*f, region, glm::vec3(0.f, 0.f, 1.f), 1, 3);
    const glm::vec3 xc = f->regionPosition(region);
    trainSpot(*f, region, xc, xc + glm::vec3(0.f, 0.4f, 0.6f), 0.02f, 1e4f, 2, 7);
    ASSERT_GT(f->spots()->share(region), 0.f);
    const std::vector<uint64_t> before = f->visitTable();
    // Draws with uStratum 0 take the lobes (share > 0); recording them changes no visits.
    f->beginPass(1);
    int recorded = 0;
    for (int i = 0; i < 100; ++i) {
        float pdf = 0.f;
        int bin = -1;
        const glm::vec3 w = f->sampleAt(region, xc, glm::vec2((i + 0.5f) / 100.f, 0.37f), 0.f,
                                        &pdf, &bin);
        ASSERT_GT(pdf, 0.f);
        EXPECT_FLOAT_EQ(pdf, f->pdfAt(region, xc, w));
        if (bin < 0) continue;  // below the hemisphere
        f->record(0, region, w, 5.f, bin);
        ++recorded;
    }
    f->endPass();
    EXPECT_GT(recorded, 0);
    EXPECT_EQ(f->visitTable(), before);
}

// Every lobe query of two fields alike, from a few places of each region.
int lobeMismatches(const HemiField& a, const HemiField& b) {
    std::mt19937_64 rng(9);
    int mismatches = 0;
    for (int r = 0; r < a.numRegions(); ++r) {
        mismatches += a.spots()->share(r) != b.spots()->share(r);
        const glm::vec3 xc = a.regionPosition(r);
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 x = xc + 0.01f * float(i) * glm::vec3(1.f, 0.5f, 0.f);
            const glm::vec3 w = test::gaussianDirection(rng);
            mismatches += a.pdfAt(r, x, w) != b.pdfAt(r, x, w);
            float pa = 0.f, pb = 0.f;
            const glm::vec2 u(0.3f + 0.05f * float(i), 0.6f);
            const glm::vec3 sa = a.sampleAt(r, x, u, 0.01f, &pa);
            const glm::vec3 sb = b.sampleAt(r, x, u, 0.01f, &pb);
            mismatches += sa != sb || pa != pb;
        }
    }
    return mismatches;
}

TEST(HemiSpots, SavedStateRestoresTheLobesAndLearnsOnAlike) {
    const std::map<std::string, std::string> params = {
        {"points", "16"}, {"spots", "2"}, {"warmup", "0"}, {"spot-judge", "0"}};
    auto f = makeHemi(params);
    ASSERT_TRUE(f);
    const int region = 4;
    trainBright(*f, region, glm::vec3(0.f, 0.f, 1.f), 1, 3);
    const glm::vec3 xc = f->regionPosition(region);
    trainSpot(*f, region, xc, xc + glm::vec3(0.6f, -0.3f, 0.5f), 0.02f, 1e4f, 2, 5);
    ASSERT_GT(f->spots()->activeLobes(), 0u);
    std::string state, error;
    ASSERT_TRUE(f->saveState(&state, &error)) << error;
    auto g = makeHemi(params);
    ASSERT_TRUE(g->loadState(state, &error)) << error;
    EXPECT_EQ(g->spots()->activeLobes(), f->spots()->activeLobes());
    EXPECT_EQ(lobeMismatches(*f, *g), 0);
    // Both learn a second spot alike (the restored accumulators match the candidates).
    for (HemiField* h : {f.get(), g.get()})
        trainSpot(*h, region, xc, xc + glm::vec3(-0.4f, 0.2f, 0.7f), 0.03f, 2e4f, 2, 6);
    EXPECT_EQ(lobeMismatches(*f, *g), 0);
    EXPECT_GT(f->spots()->activeLobes(), 1u);

    // A field without spots loads the strata alone; one with another number of lobes per
    // region refuses; a truncated section is refused.
    auto plain = makeHemi({{"points", "16"}, {"spots", "0"}, {"warmup", "0"}});
    EXPECT_TRUE(plain->loadState(state, &error)) << error;
    EXPECT_EQ(plain->pdf(region, glm::vec3(0.f, 0.f, 1.f)), f->pdf(region, glm::vec3(0.f, 0.f, 1.f)));
    auto other = makeHemi({{"points", "16"}, {"spots", "3"}, {"warmup", "0"}});
    EXPECT_FALSE(other->loadState(state, &error));
    EXPECT_NE(error.find("spots=2"), std::string::npos) << error;
    std::string plainState;
    ASSERT_TRUE(plain->saveState(&plainState, &error)) << error;
    // (a field with spots loading one saved without them: the lobes start empty)
    auto fresh = makeHemi(params);
    EXPECT_TRUE(fresh->loadState(plainState, &error)) << error;
    EXPECT_EQ(fresh->spots()->activeLobes(), 0u);
}

TEST(HemiSpots, CorruptLobeBytesAreRefused) {
    SpotLobes a;
    SpotSettings ss;
    ss.perRegion = 2;
    a.reset(3, ss);
    a.beginPass(2);
    for (int i = 0; i < 4; ++i)
        a.record(i % 2, 1, glm::vec3(0.f), glm::vec3(0.f, 0.f, 1.f),
                 glm::vec3(0.f, 0.01f * float(i), 1.f), 100.f, 1.f);
    const std::string candidates = a.takeCandidates();
    EXPECT_EQ(candidates.size(), 4u * 48u);
    SpotLobes b;
    b.reset(3, ss);
    EXPECT_FALSE(b.putCandidates(candidates.substr(1)));
    SpotLobes small;
    small.reset(1, ss);  // region 1 does not exist there
    EXPECT_FALSE(small.putCandidates(candidates));
    ASSERT_TRUE(b.putCandidates(candidates));
    b.endPass([](size_t) { return 1.0; });
    EXPECT_EQ(b.activeLobes(), 1u);
    const std::string saved = b.write();
    SpotLobes c;
    c.reset(3, ss);
    std::string why;
    EXPECT_TRUE(c.read(saved, &why)) << why;
    EXPECT_FALSE(c.read(saved.substr(0, saved.size() - 3), &why));
    std::string nan = saved;
    // The first lobe's point.x (after perRegion, the region count and region 0's and 1's
    // lobe counts) becomes a NaN.
    const uint32_t nanBits = 0x7fc00000u;
    std::memcpy(&nan[4 + 8 + 4 + 4], &nanBits, 4);
    EXPECT_FALSE(c.read(nan, &why));
    EXPECT_EQ(c.activeLobes(), 0u);
}

// Lobes sample only where they add to the strata: narrower than SpotSettings::minKappa (the
// field's strata count) and carrying at least 1% of their region's learned light. A wide
// cluster of candidates and a faint narrow one give no active lobe (share 0, density 0); the
// same narrow cluster against a small region total does.
// prune never leaves a region with spot lobes to the BSDF: its strata may be even (a small
// lamp is far below a stratum's resolution) while the lobes are what its guide is for.
// spot-judge: once the regions are confident (0.8), lobes worth less than the verdict's
// threshold (visit-weighted over the regions) stop for good; worth more, they stay. A field
// loaded from the silenced one's state reaches the same verdict.
TEST(HemiSpots, SpotJudgeStopsLobesWorthLittle) {
    for (const char* threshold : {"1e-9", "1e9"}) {
        SCOPED_TRACE(threshold);
        const std::map<std::string, std::string> params = {
            {"points", "16"}, {"spots", "2"}, {"warmup", "0"}, {"judge", "0"},
            {"spot-judge", threshold}};
        auto f = makeHemi(params);
        ASSERT_TRUE(f);
        const int region = 4;
        const glm::vec3 xc = f->regionPosition(region);
        const glm::vec3 spot = xc + glm::vec3(0.6f, -0.3f, 0.5f);
        // One pass (warmup 0: the verdict follows it): the strata's light and the spot's.
        std::mt19937_64 rng(3);
        std::normal_distribution<float> gauss(0.f, 1.f);
        f->beginPass(1);
        for (int i = 0; i < 20000; ++i) {
            const glm::vec3 w = test::gaussianDirection(rng);
            f->record(0, region, w, w.z > 0.9f ? 100.f : 0.05f);
        }
        for (int i = 0; i < 200; ++i) {
            const glm::vec3 x = xc + 0.05f * glm::vec3(gauss(rng), gauss(rng), 0.f);
            const glm::vec3 hit = spot + 0.02f * glm::vec3(gauss(rng), gauss(rng), gauss(rng));
            f->recordSpot(0, region, x, glm::normalize(hit - x), hit, 1e4f);
        }
        f->endPass();
        const bool stays = std::string(threshold) == "1e-9";
        EXPECT_EQ(f->spots()->silenced(), !stays);
        EXPECT_EQ(f->learnsSpots(), stays);
        const glm::vec3 toSpot = glm::normalize(spot - xc);
        if (stays) {
            EXPECT_GT(f->sceneMeasures().spotWorth, 0.0);
            EXPECT_GT(f->pdfAt(region, xc, toSpot), 20.f * f->pdf(region, toSpot));
            continue;
        }
        // Silenced: the strata alone, which a chi-square test of the sampler confirms.
        EXPECT_EQ(f->spots()->activeLobes(), 0u);
        EXPECT_EQ(f->pdfAt(region, xc, toSpot), f->pdf(region, toSpot));
        chi2::SphereResult r = test::sphereTestAt(*f, region, xc, 23);
        EXPECT_TRUE(r.passed) << r.message;
        EXPECT_NEAR(r.pdfIntegral, 1.0, 3e-3);
        EXPECT_NE(f->describe().find("lobes off"), std::string::npos) << f->describe();
        std::string state, error;
        ASSERT_TRUE(f->saveState(&state, &error)) << error;
        auto g = makeHemi(params);
        ASSERT_TRUE(g->loadState(state, &error)) << error;
        EXPECT_TRUE(g->spots()->silenced());
        EXPECT_EQ(g->pdfAt(region, xc, toSpot), f->pdfAt(region, xc, toSpot));
    }
}

TEST(HemiSpots, RegionWithLobesIsNeverPruned) {
    for (bool spots : {false, true}) {
        SCOPED_TRACE(spots);
        auto f = makeHemi(
            {{"points", "16"}, {"spots", spots ? "2" : "0"}, {"prune", "0.5"}, {"warmup", "0"},
             {"judge", "0"}, {"spot-judge", "0"}});
        ASSERT_TRUE(f);
        const int region = 4;
        const glm::vec3 n = f->regionNormal(region);
        const Frame frame = Frame::fromZ(n);
        f->beginPass(1);
        for (int j = 0; j < f->layout().count(); ++j)
            f->record(0, region, frame.toWorld(f->layout().centre(j)), 1.f);
        f->endPass();
        EXPECT_FALSE(f->guides(region));
        if (!spots) continue;
        const glm::vec3 xc = f->regionPosition(region);
        trainSpot(*f, region, xc, xc + glm::vec3(0.6f, -0.3f, 0.5f), 0.02f, 1e4f, 2, 5);
        ASSERT_GT(f->spots()->share(region), 0.f);
        EXPECT_TRUE(f->guides(region));
    }
}

// A lobe's worth to its region: its light share times how many times narrower than a
// stratum it is (kappa / minKappa); silenced lobes neither sample nor come back on a refit.
TEST(SpotLobes, WorthIsTheLightShareTimesTheNarrowingAndSilenceStopsThem) {
    SpotSettings ss;
    ss.perRegion = 2;
    ss.minKappa = 256.f;
    SpotLobes lobes;
    lobes.reset(2, ss);
    auto pass = [&lobes] {
        lobes.beginPass(1);
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 w = glm::normalize(
                glm::vec3(0.002f * float(i % 3 - 1), 0.002f * float(i / 3 - 1), 1.f));
            lobes.record(0, 0, glm::vec3(0.f), w, w, 100.f, 1.f);
        }
        lobes.endPass([](size_t) { return 1000.0; });
    };
    pass();
    const glm::vec3 up(0.f, 0.f, 1.f);
    ASSERT_EQ(lobes.activeLobes(), 1u);
    // One lobe: its density at its axis is kappa / (2 pi (1 - e^(-2 kappa))), so kappa.
    const double kappa = 2.0 * 3.14159265358979 * double(lobes.pdf(0, glm::vec3(0.f), up));
    ASSERT_GT(kappa, 256.0);
    const double share = 800.0 / 1000.0;
    // (kappa read back from the float density: to 0.5%)
    EXPECT_NEAR(lobes.worth(0), share * kappa / 256.0, 5e-3 * share * kappa / 256.0);
    EXPECT_EQ(lobes.worth(1), 0.f);  // no lobes there
    EXPECT_EQ(lobes.worth(-1), 0.f);
    lobes.setSilenced(true);
    EXPECT_TRUE(lobes.silenced());
    EXPECT_EQ(lobes.share(0), 0.f);
    EXPECT_EQ(lobes.pdf(0, glm::vec3(0.f), up), 0.f);
    EXPECT_EQ(lobes.worth(0), 0.f);
    pass();  // learning on does not bring them back
    EXPECT_EQ(lobes.share(0), 0.f);
    EXPECT_EQ(lobes.activeLobes(), 0u);
    lobes.setSilenced(false);
    lobes.refitAll([](size_t) { return 1000.0; });
    EXPECT_EQ(lobes.activeLobes(), 1u);
    EXPECT_GT(lobes.share(0), 0.f);
}

TEST(SpotLobes, WideOrFaintLobesDoNotSample) {
    SpotSettings ss;
    ss.perRegion = 2;
    ss.minKappa = 256.f;
    auto train = [&](float spread, double regionTotal) {
        SpotLobes lobes;
        lobes.reset(1, ss);
        lobes.beginPass(1);
        // Directions about +z, `spread` apart in x and y, towards hits at distance 1.
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 w = glm::normalize(
                glm::vec3(spread * float(i % 3 - 1), spread * float(i / 3 - 1), 1.f));
            lobes.record(0, 0, glm::vec3(0.f), w, w, 100.f, 1.f);
        }
        lobes.endPass([regionTotal](size_t) { return regionTotal; });
        return lobes;
    };
    const glm::vec3 up(0.f, 0.f, 1.f);
    SpotLobes narrow = train(0.002f, 1000.0);  // 800 of 1000: a spot
    EXPECT_EQ(narrow.activeLobes(), 1u);
    EXPECT_GT(narrow.share(0), 0.f);
    EXPECT_GT(narrow.pdf(0, glm::vec3(0.f), up), 100.f);
    SpotLobes wide = train(0.04f, 1000.0);  // about 2 degrees apart: wider than a stratum
    EXPECT_EQ(wide.activeLobes(), 0u);
    EXPECT_EQ(wide.share(0), 0.f);
    EXPECT_EQ(wide.pdf(0, glm::vec3(0.f), up), 0.f);
    ss.minKappa = 0.f;  // (the same cluster does fit a lobe: it is the width that stops it)
    EXPECT_EQ(train(0.04f, 1000.0).activeLobes(), 1u);
    ss.minKappa = 256.f;
    SpotLobes faint = train(0.002f, 1e6);  // 800 of 10^6
    EXPECT_EQ(faint.activeLobes(), 0u);
    EXPECT_EQ(faint.share(0), 0.f);
    EXPECT_EQ(faint.pdf(0, glm::vec3(0.f), up), 0.f);
}

}  // namespace
}  // namespace rlpbrt::guiding
