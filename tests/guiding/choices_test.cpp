// Learned choices of the hemi backend (GuidingField::enableChoices/choice/recordChoice, the
// integrator's light selection): per region the running mean of each option's value, a CDF
// proportional to the means, a weight that grows with the region's records, learning that
// stops at kChoiceFull records per option, and the choices in a saved state.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "guiding/hemi.h"
#include "guiding/test_scenes.h"

namespace rlpbrt::guiding {
namespace {

std::unique_ptr<HemiField> makeHemi() {
    return test::makeField<HemiField>("hemi", test::planeScene(), {{"points", "8"}});
}

// One pass of `perOption` records of option k with value means[k] (+- noise) at region r.
void recordPass(HemiField& f, int r, const std::vector<float>& means, int perOption,
                std::mt19937_64& rng) {
    std::uniform_real_distribution<float> u(0.5f, 1.5f);
    f.beginPass(2);
    for (int i = 0; i < perOption; ++i)
        for (size_t k = 0; k < means.size(); ++k)
            f.recordChoice(i % 2, r, int(k), means[k] * u(rng));
    f.endPass();
}

TEST(HemiChoices, OnlyForTwoToMaxChoicesOptions) {
    auto f = makeHemi();
    EXPECT_FALSE(f->enableChoices(1));
    EXPECT_FALSE(f->enableChoices(GuidingField::kMaxChoices + 1));
    EXPECT_TRUE(f->enableChoices(2));
    // Without enableChoices the field answers none and ignores records.
    auto g = makeHemi();
    g->beginPass(1);
    g->recordChoice(0, 1, 0, 1.f);
    g->endPass();
    const GuidingField::Choice c = g->choice(1);
    EXPECT_EQ(c.cdf, nullptr);
    EXPECT_FALSE(c.learning);
}

TEST(HemiChoices, CdfFollowsTheMeansOnceTheRegionHasRecords) {
    auto f = makeHemi();
    ASSERT_TRUE(f->enableChoices(3));
    const int r = 3;
    // Untrained: no distribution, learning, every region alike; invalid regions: none.
    for (int q : {0, r, f->numRegions() - 1}) {
        const GuidingField::Choice c = f->choice(q);
        EXPECT_EQ(c.cdf, nullptr);
        EXPECT_EQ(c.weight, 0.f);
        EXPECT_TRUE(c.learning);
    }
    EXPECT_FALSE(f->choice(-1).learning);
    EXPECT_FALSE(f->choice(f->numRegions()).learning);
    std::mt19937_64 rng(7);
    // Option 1 is hidden (always 0): it gets no share of the learned CDF.
    const std::vector<float> means = {2.f, 0.f, 6.f};
    // A few records (below the minimum weight): still no distribution.
    recordPass(*f, r, means, 2, rng);
    EXPECT_EQ(f->choice(r).cdf, nullptr);
    double weight = 0.0;
    for (int pass = 0; pass < 4; ++pass) {
        recordPass(*f, r, means, 40, rng);
        const GuidingField::Choice c = f->choice(r);
        ASSERT_NE(c.cdf, nullptr);
        EXPECT_EQ(c.cdf[0], 0.f);
        EXPECT_EQ(c.cdf[3], 1.f);
        EXPECT_EQ(c.cdf[2] - c.cdf[1], 0.f);  // the hidden option
        // The shares follow the means (2 : 6 up to the noise of 40 x pass records).
        EXPECT_NEAR(c.cdf[1], 0.25, 0.05);
        // The weight grows with the records: records / (records + 16 x 3).
        const double records = 3.0 * (2 + 40 * (pass + 1));
        EXPECT_NEAR(c.weight, records / (records + 48.0), 1e-6);
        EXPECT_GT(c.weight, weight);
        weight = c.weight;
        EXPECT_TRUE(c.learning);
    }
    // Other regions did not learn.
    EXPECT_EQ(f->choice(r + 1).cdf, nullptr);
}

TEST(HemiChoices, BadValuesAreRejectedAndLearningStopsWhenFull) {
    auto f = makeHemi();
    ASSERT_TRUE(f->enableChoices(2));
    const int r = 5;
    std::mt19937_64 rng(9);
    f->beginPass(1);
    for (int i = 0; i < 100; ++i) {
        f->recordChoice(0, r, 0, -1.f);
        f->recordChoice(0, r, 1, std::numeric_limits<float>::quiet_NaN());
        f->recordChoice(0, r, 2, 1.f);   // no such option
        f->recordChoice(0, r, -1, 1.f);  // nor this
    }
    f->endPass();
    EXPECT_EQ(f->choice(r).cdf, nullptr);
    // kChoiceFull (1024) records per option: the region stops learning, the CDF stays.
    recordPass(*f, r, {1.f, 3.f}, 1000, rng);
    EXPECT_TRUE(f->choice(r).learning);
    recordPass(*f, r, {1.f, 3.f}, 100, rng);
    const GuidingField::Choice c = f->choice(r);
    ASSERT_NE(c.cdf, nullptr);
    EXPECT_FALSE(c.learning);
    EXPECT_NEAR(c.cdf[1], 0.25, 0.02);
}

TEST(HemiChoices, SavedStateRestoresTheChoices) {
    auto f = makeHemi();
    ASSERT_TRUE(f->enableChoices(4));
    std::mt19937_64 rng(11);
    recordPass(*f, 2, {1.f, 0.f, 2.f, 5.f}, 50, rng);
    recordPass(*f, 7, {0.f, 3.f, 0.f, 1.f}, 80, rng);
    std::string state, error;
    ASSERT_TRUE(f->saveState(&state, &error)) << error;
    auto g = makeHemi();
    ASSERT_TRUE(g->enableChoices(4));
    ASSERT_TRUE(g->loadState(state, &error)) << error;
    for (int r = 0; r < f->numRegions(); ++r) {
        const GuidingField::Choice a = f->choice(r), b = g->choice(r);
        EXPECT_EQ(a.weight, b.weight);
        EXPECT_EQ(a.learning, b.learning);
        ASSERT_EQ(a.cdf == nullptr, b.cdf == nullptr) << r;
        if (a.cdf) {
            for (int k = 0; k <= 4; ++k) EXPECT_EQ(a.cdf[k], b.cdf[k]);
        }
    }
    // Both learn on alike.
    for (HemiField* h : {f.get(), g.get()}) {
        std::mt19937_64 same(13);
        recordPass(*h, 2, {4.f, 1.f, 0.f, 0.f}, 30, same);
    }
    for (int k = 0; k <= 4; ++k) EXPECT_EQ(f->choice(2).cdf[k], g->choice(2).cdf[k]);
    // Another number of options is refused; a field without choices ignores them; one with
    // choices that loads a state without them starts them empty.
    auto other = makeHemi();
    ASSERT_TRUE(other->enableChoices(3));
    EXPECT_FALSE(other->loadState(state, &error));
    EXPECT_NE(error.find("options"), std::string::npos) << error;
    auto plain = makeHemi();
    EXPECT_TRUE(plain->loadState(state, &error)) << error;
    EXPECT_EQ(plain->choice(2).cdf, nullptr);
    std::string plainState;
    ASSERT_TRUE(plain->saveState(&plainState, &error)) << error;
    auto fresh = makeHemi();
    ASSERT_TRUE(fresh->enableChoices(4));
    EXPECT_TRUE(fresh->loadState(plainState, &error)) << error;
    EXPECT_EQ(fresh->choice(2).cdf, nullptr);
    EXPECT_TRUE(fresh->choice(2).learning);
}

}  // namespace
}  // namespace rlpbrt::guiding
