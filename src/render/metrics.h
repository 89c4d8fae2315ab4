// Error measures of a rendered image against a reference, as defined in
// shared/references/README.md. Both images must have the same width and height and at least
// 3 channels; only the first three (R, G, B) are used, so RGBA references work as they are.
// Mismatched or empty images throw std::invalid_argument. Sums are in double precision.
#pragma once

#include "render/image.h"

namespace rlpbrt {

// Trimmed relative mean squared error. Per pixel p: e_p = mean over R,G,B of
// (x - r)^2 / (r^2 + 0.01), with x from `test` and r from `ref`. The k = floor(N / 1000)
// pixels with the largest e_p are dropped (N = width * height; integer division, so an image
// of fewer than 1000 pixels drops none, 40000 pixels drop 40); the result is the mean of the
// remaining N - k values. Returns NaN when any e_p is not finite (e.g. a NaN or infinite
// pixel in either image; check with hasNonFinite). Dimensionless.
double relMseTrimmed(const Image& test, const Image& ref);

// The error of one render without a reference's own noise, from two renders of the same
// estimator with independent seeds: half the trimmed mean of e_p = mean over R,G,B of
// (a - b)^2 / (r^2 + 0.01), r from `ref` (only its weights; its noise does not enter),
// dropping the 2 x floor(N / 1000) largest e_p: the difference carries both renders'
// outliers, and relMseTrimmed drops one render's 0.1%. For unbiased renders
// E[(a - b)^2] = Var a + Var b, so this estimates each one's relMseTrimmed against the exact
// image, and relMseTrimmed(a, ref) minus it the reference's own error (docs/BENCHMARKS.md,
// "The references' own noise"). Heavy-tailed renders (fireflies that neither render drew)
// read low. NaN when a value is not finite; throws as relMseTrimmed for mismatched images.
double pairRelMse(const Image& a, const Image& b, const Image& ref);

// Median block deviation. Both images are split into block x block pixel tiles starting at
// the top-left corner; partial tiles at the right and bottom edges (when the size is not a
// multiple of `block`) are ignored. For each tile, mT and mR are the means over its pixels
// and the R, G, B channels of test and ref. Over the tiles with mR > 0.05 * M, where M is
// the mean of ref over all its pixels and R, G, B channels (edges included), the result is
// the median of |mT / mR - 1| (for an even count, the mean of the two middle values).
// Returns NaN when no tile qualifies. Dimensionless.
double blockBias(const Image& test, const Image& ref, int block = 16);

// True when any pixel value (all channels) is NaN or infinite.
bool hasNonFinite(const Image& img);

}  // namespace rlpbrt
