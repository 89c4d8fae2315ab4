// PassMoments (render/efficiency.h): the per-sample relative variance of a pass from its own
// samples, normalised by the median of earlier passes' neighbouring pixel means.
#include "render/efficiency.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace rlpbrt
