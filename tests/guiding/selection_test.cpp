// The per-region selection probability (guiding/selection.h): on a one-dimensional integrand
// with known optimal mixtures, sampled from a mixture at another probability, the learner
// must pick the candidate that minimises the second moment.
#include "guiding/selection.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

using rlpbrt::guiding::SelectionLearner;
using rlpbrt::guiding::SelectionSample;

namespace {

// Domain [0, 1): "guide" pdf g(x) = 3 x^2, "BSDF" pdf b(x) = 1, integrand
// pi(x) = w g(x) + (1 - w) b(x). The mixture c g + (1 - c) b is proportional to pi at c = w,
// where the second moment integral of pi^2 / p_c is smallest.
struct Problem {
    double w;
    double g(double x) const { return 3.0 * x * x; }
    double pi(double x) const { return w * g(x) + (1.0 - w); }
};

// Draws n samples from the mixture with selection c0 (scale 1) into `slot` of `region`.
void feed(SelectionLearner& l, int slot, int region, const Problem& prob, double c0, int n,
          uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < n; ++i) {
        double x = u(rng) < c0 ? std::cbrt(u(rng)) : u(rng);
        x = std::min(std::max(x, 1e-6), 1.0 - 1e-6);
        const double pg = prob.g(x), pb = 1.0, p = c0 * pg + (1.0 - c0) * pb;
        SelectionSample s;
        s.integrand = float(prob.pi(x));
        s.pdf = float(p);
        s.pGuide = float(pg);
        s.pOther = float(pb);
        s.scale = 1.f;
        l.record(slot, region, s);
    }
}

}  // namespace

TEST(SelectionLearner, PicksTheCandidateClosestToTheOptimum) {
    // Optimum w: 1 (guide only: the largest candidate, 0.9), 0 (BSDF only), 0.5 and 0.3.
    const double ws[] = {1.0, 0.0, 0.5, 0.3};
    const float expect[] = {0.9f, 0.f, 0.5f, 0.3f};
    SelectionLearner l;
    l.reset(4);
    l.beginPass(2);
    for (int r = 0; r < 4; ++r) feed(l, r % 2, r, Problem{ws[r]}, 0.4, 40000, 11u + uint32_t(r));
    l.endPass();
    for (int r = 0; r < 4; ++r) {
        const float s = l.selection(size_t(r));
        if (ws[r] == 1.0 || ws[r] == 0.0)
            EXPECT_FLOAT_EQ(s, expect[r]) << "region " << r;
        else
            EXPECT_NEAR(s, expect[r], 0.1001f) << "region " << r;  // one candidate step
    }
    EXPECT_EQ(l.learnedRegions(), 4u);
    EXPECT_GT(l.bytes(), 0u);
}

TEST(SelectionLearner, UnlearnedUntilEnoughSamplesCarryLight) {
    SelectionLearner l;
    l.reset(3);
    EXPECT_FLOAT_EQ(l.selection(0), -1.f);
    EXPECT_EQ(l.bytes(), 0u);  // nothing allocated before the first samples
    l.beginPass(1);
    feed(l, 0, 0, Problem{0.5}, 0.5, 10, 1);  // too few
    // Samples that carry no light, or are not finite, teach nothing.
    SelectionSample zero{0.f, 1.f, 1.f, 1.f, 1.f}, nan{NAN, 1.f, 1.f, 1.f, 1.f};
    for (int i = 0; i < 1000; ++i) {
        l.record(0, 1, zero);
        l.record(0, 1, nan);
    }
    // Out-of-range slots and regions are ignored.
    l.record(5, 0, SelectionSample{1.f, 1.f, 1.f, 1.f, 1.f});
    l.record(0, 7, SelectionSample{1.f, 1.f, 1.f, 1.f, 1.f});
    l.endPass();
    EXPECT_FLOAT_EQ(l.selection(0), -1.f);
    EXPECT_FLOAT_EQ(l.selection(1), -1.f);
    EXPECT_FLOAT_EQ(l.selection(99), -1.f);
    EXPECT_EQ(l.learnedRegions(), 0u);
    // Enough samples: learned; growing keeps it and adds unlearned regions.
    l.beginPass(1);
    feed(l, 0, 0, Problem{1.0}, 0.5, 1000, 2);
    l.endPass();
    EXPECT_FLOAT_EQ(l.selection(0), 0.9f);
    l.grow(5);
    EXPECT_FLOAT_EQ(l.selection(0), 0.9f);
    EXPECT_FLOAT_EQ(l.selection(4), -1.f);
}

TEST(SelectionLearner, OlderPassesDecay) {
    // A region first fed BSDF-like samples, then guide-like ones: the newer passes win.
    SelectionLearner l;
    l.reset(1);
    l.beginPass(1);
    feed(l, 0, 0, Problem{0.0}, 0.5, 2000, 3);
    l.endPass();
    EXPECT_FLOAT_EQ(l.selection(0), 0.f);
    for (int pass = 0; pass < 6; ++pass) {  // the first pass keeps weight 1/64
        l.beginPass(1);
        feed(l, 0, 0, Problem{1.0}, 0.5, 2000, 4u + uint32_t(pass));
        l.endPass();
    }
    EXPECT_FLOAT_EQ(l.selection(0), 0.9f);
}

TEST(SelectionLearner, MergesSlotsInSlotOrder) {
    // The same samples in the same slots give bit-identical sums, whatever the order in which
    // the slots were filled (threads fill them concurrently).
    auto run = [](bool reversed) {
        SelectionLearner l;
        l.reset(1);
        l.beginPass(3);
        for (int k = 0; k < 3; ++k) {
            const int slot = reversed ? 2 - k : k;
            feed(l, slot, 0, Problem{0.37}, 0.5, 300, 20u + uint32_t(slot));
        }
        l.endPass();
        return l.selection(0);
    };
    EXPECT_EQ(run(false), run(true));
}
