// The efficiency of a render pass, measured from its own samples: the relative variance of
// one sample per pixel (normalised as relMseTrimmed normalises errors) times the time one
// sample took. The render loop compares a guided pass with a plain one this way and stops
// guiding where it does not pay (GuideSettings::autoSpp, the auto trial in render.cpp).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "render/film.h"
#include "render/spectrum.h"

namespace rlpbrt {

class Ranks;

// Per-pixel sample mean and variance of one pass over a pixel rectangle. At most about
// maxPixels pixels are tracked (every k-th row beyond that), so memory stays bounded for large
// films. set() and accumulate() are thread-safe for distinct pixels.
class PassMoments {
public:
    PassMoments(const Bounds2i& bounds, size_t maxPixels = size_t(1) << 17);
    // Whether pixel (x, y) is tracked (callers skip the accumulation otherwise).
    bool tracked(int x, int y) const { return slot(x, y) >= 0; }
    // The n samples of pixel (x, y) in this pass: their sums and sums of squares per channel.
    void set(int x, int y, int n, const double sum[3], const double sumSq[3]);
    // The same n samples added to those set before (a pass measured in parts); set() if none.
    void add(int x, int y, int n, const double sum[3], const double sumSq[3]);
    size_t trackedPixels() const { return mean_.size() / 3; }

    // Adds the n samples of pixel (x, y) to its running mean (pixel means over several
    // passes; the variance is not kept).
    void accumulate(int x, int y, int n, const double sum[3]);

    // The relative variance of one sample: over the tracked pixels, the median of the means
    // of 15 interleaved pixel groups of (1/3) sum_c var_c / (m_c^2 + 0.01), var_c the
    // per-sample variance in this pass, m_c the median of `reference`'s means (earlier
    // passes) of the pixel and its two neighbours on either side in its row (relMseTrimmed's
    // normalisation). An n-sample estimate of the pixels has about this relMSE / n. -1 if
    // nothing was set or the rectangles differ. Why so: a mean from the pass's own samples
    // would cancel a pixel's outliers against themselves, and the median keeps an outlier of
    // the earlier passes from hiding this pass's variance; the trimmed mean of relMseTrimmed
    // drops exactly the pixels where a pass of few samples caught rare light (it judged
    // plain rendering better on veach-bidir and breakfast, where guiding wins), and a plain
    // mean is decided by single samples (docs/BENCHMARKS_HISTORY.md, session 5, "A guided-or-plain trial").
    double relativeVariance(const PassMoments& reference) const;

    // Several ranks (render/distributed.h): each sets or accumulates the pixels of its own
    // tiles; sumAcross() gives every rank all pixels (a collective: every rank calls it), and
    // clear() forgets the pixels of a rectangle (a resumed rank keeps its own tiles').
    void sumAcross(Ranks& ranks);
    void clear(const Bounds2i& rect);

    // The tracked pixels' means, variances and counts as bytes (a resumed render's auto
    // trial, render/resume.h), and their restoring into moments over the same rectangle
    // (false, and nothing changed, if the sizes do not match).
    std::string state() const;
    bool setState(const std::string& state);

private:
    long slot(int x, int y) const;
    Bounds2i bounds_;
    long width_ = 0;
    long rowStride_ = 1;
    std::vector<float> mean_, var_;  // 3 per tracked pixel
    std::vector<int> count_;         // samples per tracked pixel (0 = not set)
};

// Accumulates one pixel's samples in double precision for PassMoments::set.
struct PixelMoments {
    int n = 0;
    double sum[3] = {0.0, 0.0, 0.0}, sumSq[3] = {0.0, 0.0, 0.0};
    void add(const Spectrum& L) {
        ++n;
        for (int c = 0; c < 3; ++c) {
            sum[c] += double(L[c]);
            sumSq[c] += double(L[c]) * double(L[c]);
        }
    }
};

}  // namespace rlpbrt
