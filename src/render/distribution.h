// Piecewise-constant 1D and 2D distributions over [0,1] and [0,1]^2, for environment-map
// importance sampling and light selection (pbrt-v3's Distribution1D / Distribution2D semantics).
#pragma once

#include <vector>

#include "render/math.h"

namespace rlpbrt {

// Piecewise-constant density over [0,1] proportional to n non-negative function values.
// Negative or non-finite values are treated as 0. If every value is 0 the distribution falls
// back to uniform sampling (integral() still reports 0).
class Distribution1D {
  public:
    // Empty; must be assigned a built distribution before sampling.
    Distribution1D() = default;
    // Builds from n >= 1 values; f[i] covers [i/n, (i+1)/n).
    Distribution1D(const float* f, int n);
    // Builds from all values of f (non-empty).
    explicit Distribution1D(const std::vector<float>& f)
        : Distribution1D(f.data(), static_cast<int>(f.size())) {}

    // Number of pieces.
    int count() const { return static_cast<int>(func_.size()); }
    // Integral of the (sanitised) function over [0,1]: (1/n) * sum f[i].
    float integral() const { return funcInt_; }
    // Function value of piece i (after sanitising).
    float func(int i) const { return func_[i]; }
    // The CDF: n + 1 non-decreasing values from 0 to 1; piece i covers [cdf[i], cdf[i + 1]).
    const std::vector<float>& cdf() const { return cdf_; }

    // Samples x in [0,1) from uniform u in [0,1); *pdf receives the density w.r.t. x on [0,1]
    // and *offset the piece index.
    float sampleContinuous(float u, float* pdf = nullptr, int* offset = nullptr) const;
    // Samples a piece index with probability f[i] / sum f; *pmf receives that probability and
    // *uRemapped the position of u inside the chosen piece's CDF interval, in [0,1).
    int sampleDiscrete(float u, float* pmf = nullptr, float* uRemapped = nullptr) const;
    // Probability of choosing piece i in sampleDiscrete.
    float discretePmf(int i) const;
    // Density w.r.t. x on [0,1] of sampleContinuous at x (0 outside [0,1]).
    float pdf(float x) const;

  private:
    // Index of the piece whose CDF interval contains u: the largest i with cdf[i] <= u,
    // clamped to a piece. From the bucket table where there is one, else by binary search
    // over the whole CDF; both give the same index.
    int findInterval(float u) const;
    // The largest i in [lo, hi] with cdf_[i] <= u, given cdf_[lo] <= u (else lo).
    int searchCdf(float u, int lo, int hi) const;

    // Tables of at least kBucketMin pieces also keep, for each of n / kPiecesPerBucket equal
    // buckets of [0,1), the index the search finds at the bucket's start: a sample's search
    // runs within its bucket's range, about kPiecesPerBucket + 1 pieces on average (one or
    // two cache lines), instead of log2(n) dependent reads over the whole CDF that miss the
    // caches for an environment map's rows. The answer is checked against the CDF and found
    // by the full search where rounding put u outside its bucket's range, so both give the
    // same index. A bucket per piece was no faster and takes 16 times the memory.
    static constexpr int kBucketMin = 64;
    static constexpr int kPiecesPerBucket = 16;
    std::vector<int> bucketStart_;  // one entry per bucket and the end (n), or none
    // Density of piece i relative to the unit interval (uniform fallback when all zero).
    float pieceDensity(int i) const { return uniform_ ? 1.f : func_[i] / funcInt_; }

    std::vector<float> func_;
    std::vector<float> cdf_;  // n+1 entries, cdf_[0] = 0, cdf_[n] = 1
    float funcInt_ = 0.f;
    bool uniform_ = true;
};

// Piecewise-constant density over [0,1]^2 from an nu x nv grid of non-negative values stored
// row by row (value (iu, iv) at f[iv * nu + iu]); u is the fast (column) coordinate.
class Distribution2D {
  public:
    // Empty; must be assigned a built distribution before sampling.
    Distribution2D() = default;
    // Builds from nu * nv values (nu, nv >= 1).
    Distribution2D(const float* f, int nu, int nv);

    // Number of columns (u resolution).
    int countU() const { return conditional_.empty() ? 0 : conditional_[0].count(); }
    // Number of rows (v resolution).
    int countV() const { return static_cast<int>(conditional_.size()); }
    // Integral of the function over [0,1]^2.
    float integral() const { return marginal_.integral(); }

    // Samples a point in [0,1)^2 from uniform u; *pdf receives the density w.r.t. area on
    // [0,1]^2. v is chosen from the marginal with u.y, then u from the row's conditional with u.x.
    Vec2 sampleContinuous(Vec2 u, float* pdf) const;
    // Density w.r.t. area on [0,1]^2 at point p.
    float pdf(Vec2 p) const;

  private:
    std::vector<Distribution1D> conditional_;
    Distribution1D marginal_;
};

}  // namespace rlpbrt
