// PassMoments (render/efficiency.h): the per-sample relative variance of a pass from its own
// samples, normalised by the median of earlier passes' neighbouring pixel means.
#include "render/efficiency.h"

#include <gtest/gtest.h>

#include <deque>
#include <vector>

#include "render/distributed.h"

namespace rlpbrt {
namespace {

const Bounds2i kBounds(glm::ivec2(0, 0), glm::ivec2(30, 10));

// Every pixel of `pass` gets the two samples 1 - s and 1 + s per channel (per-sample variance
// 2 s^2); every pixel of `reference` the mean 1.
void fill(PassMoments* pass, PassMoments* reference, double s) {
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 30; ++x) {
            PixelMoments m;
            m.add(Spectrum(float(1.0 - s)));
            m.add(Spectrum(float(1.0 + s)));
            pass->set(x, y, m.n, m.sum, m.sumSq);
            const double one[3] = {1.0, 1.0, 1.0};
            reference->accumulate(x, y, 1, one);
        }
}

TEST(PassMoments, RelativeVarianceOfKnownSamples) {
    PassMoments pass(kBounds), reference(kBounds);
    EXPECT_EQ(pass.relativeVariance(reference), -1.0);  // nothing set
    fill(&pass, &reference, 0.5);
    EXPECT_NEAR(pass.relativeVariance(reference), 2.0 * 0.25 / 1.01, 1e-6);
}

TEST(PassMoments, OneExtremePixelMovesOneGroupOnly) {
    PassMoments pass(kBounds), reference(kBounds);
    fill(&pass, &reference, 0.5);
    PixelMoments m;
    m.add(Spectrum(0.f));
    m.add(Spectrum(1e6f));
    pass.set(7, 3, m.n, m.sum, m.sumSq);  // a firefly in this pass
    EXPECT_NEAR(pass.relativeVariance(reference), 2.0 * 0.25 / 1.01, 1e-6);
    // An outlier among the earlier passes' means does not hide the pixel's variance either:
    // the reference is the median of five neighbours in the row.
    PassMoments clean(kBounds);
    fill(&clean, &reference, 0.5);
    const double big[3] = {1e6, 1e6, 1e6};
    reference.accumulate(12, 4, 1, big);  // now (1 + 1e6) / 2
    EXPECT_NEAR(clean.relativeVariance(reference), 2.0 * 0.25 / 1.01, 1e-6);
}

TEST(PassMoments, AccumulatesMeansOverPasses) {
    PassMoments pass(kBounds), reference(kBounds);
    fill(&pass, &reference, 0.5);  // reference means 1 from one sample each
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 30; ++x) {
            const double three[3] = {9.0, 9.0, 9.0};
            reference.accumulate(x, y, 3, three);  // three more samples of 3: mean 2.5
        }
    EXPECT_NEAR(pass.relativeVariance(reference), 2.0 * 0.25 / (2.5 * 2.5 + 0.01), 1e-6);
}

TEST(PassMoments, LargeFilmsTrackEveryKthRow) {
    const Bounds2i big(glm::ivec2(-4, -4), glm::ivec2(996, 996));  // 1e6 pixels
    PassMoments pass(big, 100000);
    EXPECT_LE(pass.trackedPixels(), 110000u);
    EXPECT_GE(pass.trackedPixels(), 90000u);
    EXPECT_TRUE(pass.tracked(-4, -4));
    EXPECT_FALSE(pass.tracked(-4, -3));
    EXPECT_FALSE(pass.tracked(996, -4));  // outside
    PassMoments other(kBounds);
    EXPECT_EQ(pass.relativeVariance(other), -1.0);  // different rectangles
}

// A pass measured in two parts: the pooled moments of all its samples.
TEST(PassMoments, PartsAddUpToTheWholePass) {
    PassMoments whole(kBounds), parts(kBounds), reference(kBounds);
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 30; ++x) {
            PixelMoments all, a, b;
            for (int i = 0; i < 9; ++i) {
                const Spectrum L(float((x * 7 + i * i) % 5), float(y + i), float(i == 4) * 9.f);
                all.add(L);
                (i < 2 ? a : b).add(L);
            }
            whole.set(x, y, all.n, all.sum, all.sumSq);
            parts.add(x, y, a.n, a.sum, a.sumSq);  // the first part: as set()
            parts.add(x, y, b.n, b.sum, b.sumSq);
            const double one[3] = {1.0, 1.0, 1.0};
            reference.accumulate(x, y, 1, one);
        }
    EXPECT_NEAR(parts.relativeVariance(reference), whole.relativeVariance(reference),
                1e-5 * whole.relativeVariance(reference));
    EXPECT_GT(whole.relativeVariance(reference), 0.0);
}

// Two ranks played in one process: the first records the buffers its rank puts into the
// collectives (as a rank whose partner has only zeros), the second adds those to its own, as
// the element-wise sums of two ranks would.
class TwoRanksInTurn final : public Ranks {
public:
    explicit TwoRanksInTurn(int rank) : rank_(rank) {}
    int rank() const override { return rank_; }
    int size() const override { return 2; }
    void sumDoubles(double*, size_t) override { ADD_FAILURE() << "not used"; }
    void sumCounts(uint32_t* data, size_t n) override {
        if (rank_ == 0) {
            counts_.emplace_back(data, data + n);
            return;
        }
        ASSERT_FALSE(counts_.empty());
        ASSERT_EQ(counts_.front().size(), n);
        for (size_t i = 0; i < n; ++i) data[i] += counts_.front()[i];
        counts_.pop_front();
    }
    void sumDisjointFloats(float* data, size_t n, bool everyone) override {
        EXPECT_TRUE(everyone);  // every rank takes the trial's decision
        if (rank_ == 0) {
            floats_.emplace_back(data, data + n);
            return;
        }
        ASSERT_FALSE(floats_.empty());
        ASSERT_EQ(floats_.front().size(), n);
        for (size_t i = 0; i < n; ++i) {
            EXPECT_TRUE(data[i] == 0.f || floats_.front()[i] == 0.f) << "not disjoint at " << i;
            data[i] += floats_.front()[i];
        }
        floats_.pop_front();
    }
    void gatherBytes(std::string&) override { ADD_FAILURE() << "not used"; }
    void broadcast(void*, size_t) override { ADD_FAILURE() << "not used"; }
    bool allOk(bool ok) override { return ok; }
    uint64_t bytesExchanged() const override { return 0; }
    double secondsExchanging() const override { return 0.0; }
    void pass(const TwoRanksInTurn& first) {
        floats_ = first.floats_;
        counts_ = first.counts_;
    }

private:
    int rank_;
    std::deque<std::vector<float>> floats_;
    std::deque<std::vector<uint32_t>> counts_;
};

// The auto trial on several ranks (render.cpp): each rank holds the moments of its own
// pixels; summed over the ranks they are the moments of one process that saw every pixel,
// and a resumed rank forgets the pixels of the tiles it does not render.
TEST(PassMoments, SummedAcrossRanksEqualOneProcess) {
    PassMoments whole(kBounds), wholeRef(kBounds);
    PassMoments left(kBounds), leftRef(kBounds), right(kBounds), rightRef(kBounds);
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 30; ++x) {
            PixelMoments m;
            m.add(Spectrum(float(x + 1), float(y + 1), 1.f));
            m.add(Spectrum(float(2 * x), float(y * y), 3.f));
            const double mean[3] = {double(x % 7), 2.0, double(y)};
            const bool mine = x < 12;  // the first rank's tile: x in [0, 12)
            whole.set(x, y, m.n, m.sum, m.sumSq);
            wholeRef.accumulate(x, y, 2, mean);
            (mine ? left : right).set(x, y, m.n, m.sum, m.sumSq);
            (mine ? leftRef : rightRef).accumulate(x, y, 2, mean);
        }
    TwoRanksInTurn first(0), second(1);
    left.sumAcross(first);
    leftRef.sumAcross(first);
    second.pass(first);
    right.sumAcross(second);
    rightRef.sumAcross(second);
    EXPECT_EQ(right.state(), whole.state());
    EXPECT_EQ(rightRef.state(), wholeRef.state());
    EXPECT_EQ(right.relativeVariance(rightRef), whole.relativeVariance(wholeRef));
    EXPECT_GT(whole.relativeVariance(wholeRef), 0.0);

    // clear(): the second rank's pixels only, as before the sum.
    PassMoments mineOnly(kBounds), mineFromWhole = whole;
    for (int y = 0; y < 10; ++y)
        for (int x = 12; x < 30; ++x) {
            PixelMoments m;
            m.add(Spectrum(float(x + 1), float(y + 1), 1.f));
            m.add(Spectrum(float(2 * x), float(y * y), 3.f));
            mineOnly.set(x, y, m.n, m.sum, m.sumSq);
        }
    mineFromWhole.clear(Bounds2i(glm::ivec2(0, 0), glm::ivec2(12, 10)));
    EXPECT_EQ(mineFromWhole.state(), mineOnly.state());
}

}  // namespace
}  // namespace rlpbrt
