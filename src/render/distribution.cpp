#include "render/distribution.h"

#include <algorithm>
#include <cassert>

namespace rlpbrt {

Distribution1D::Distribution1D(const float* f, int n) {
    assert(n >= 1);
    func_.resize(n);
    cdf_.resize(n + 1);
    // Accumulate in double so that long, high-dynamic-range tables keep an accurate CDF.
    double total = 0.0;
    for (int i = 0; i < n; ++i) {
        float v = f[i];
        func_[i] = (std::isfinite(v) && v > 0.f) ? v : 0.f;
        total += func_[i];
    }
    funcInt_ = static_cast<float>(total / n);
    uniform_ = !(total > 0.0) || !(funcInt_ > 0.f);
    cdf_[0] = 0.f;
    double partial = 0.0;
    for (int i = 0; i < n; ++i) {
        partial += uniform_ ? 1.0 : func_[i];
        // Pieces after the last non-zero one get exactly 1, so they are never selected.
        cdf_[i + 1] = static_cast<float>(partial / (uniform_ ? n : total));
    }
    cdf_[n] = 1.f;
    if (n >= kBucketMin) {
        const int buckets = n / kPiecesPerBucket;
        bucketStart_.resize(size_t(buckets) + 1);
        for (int k = 0; k < buckets; ++k)
            bucketStart_[size_t(k)] = searchCdf(float(k) / float(buckets), 0, n);
        bucketStart_[size_t(buckets)] = n;
    }
}

int Distribution1D::searchCdf(float u, int lo, int hi) const {
    // A branchless binary search that loads both possible next probes ahead, since the CDFs
    // of large environment maps miss the caches.
    const float* b = cdf_.data() + lo;
    size_t len = size_t(hi - lo) + 1;
    while (len > 1) {
        const size_t half = len / 2;
        __builtin_prefetch(b + half / 2);
        __builtin_prefetch(b + half + half / 2);
        b = b[half] <= u ? b + half : b;
        len -= half;
    }
    return static_cast<int>(b - cdf_.data());
}

int Distribution1D::findInterval(float u) const {
    const int n = count();
    if (!bucketStart_.empty() && u >= 0.f && u < 1.f) {
        const int buckets = static_cast<int>(bucketStart_.size()) - 1;
        const int k = std::min(static_cast<int>(u * float(buckets)), buckets - 1);
        const int lo = bucketStart_[size_t(k)], hi = bucketStart_[size_t(k) + 1];
        // The answer i, if cdf[i] <= u < cdf[i + 1] (cdf_ has n + 1 entries).
        if (cdf_[size_t(lo)] <= u) {
            const int i = searchCdf(u, lo, hi);
            if (i == n || u < cdf_[size_t(i) + 1]) return std::min(i, n - 1);
        }
    }
    return clamp(searchCdf(u, 0, n), 0, n - 1);
}

float Distribution1D::sampleContinuous(float u, float* pdf, int* offset) const {
    int i = findInterval(u);
    if (offset) *offset = i;
    float du = u - cdf_[i];
    float width = cdf_[i + 1] - cdf_[i];
    if (width > 0.f) du /= width;
    du = clamp(du, 0.f, OneMinusEpsilon);
    if (pdf) *pdf = pieceDensity(i);
    return std::min((i + du) / count(), OneMinusEpsilon);
}

int Distribution1D::sampleDiscrete(float u, float* pmf, float* uRemapped) const {
    int i = findInterval(u);
    if (pmf) *pmf = discretePmf(i);
    if (uRemapped) *uRemapped = remapInInterval(u, cdf_[i], cdf_[i + 1]);
    return i;
}

float Distribution1D::discretePmf(int i) const {
    if (i < 0 || i >= count()) return 0.f;
    return pieceDensity(i) / count();
}

float Distribution1D::pdf(float x) const {
    if (!(x >= 0.f && x <= 1.f) || func_.empty()) return 0.f;
    int i = std::min(static_cast<int>(x * count()), count() - 1);
    return pieceDensity(i);
}

Distribution2D::Distribution2D(const float* f, int nu, int nv) {
    assert(nu >= 1 && nv >= 1);
    conditional_.reserve(nv);
    std::vector<float> rowIntegrals(nv);
    for (int v = 0; v < nv; ++v) {
        conditional_.emplace_back(f + static_cast<size_t>(v) * nu, nu);
        rowIntegrals[v] = conditional_.back().integral();
    }
    marginal_ = Distribution1D(rowIntegrals.data(), nv);
}

Vec2 Distribution2D::sampleContinuous(Vec2 u, float* pdf) const {
    float pdfV = 0.f, pdfU = 0.f;
    int v = 0;
    float y = marginal_.sampleContinuous(u.y, &pdfV, &v);
    float x = conditional_[v].sampleContinuous(u.x, &pdfU);
    if (pdf) *pdf = pdfU * pdfV;
    return Vec2(x, y);
}

float Distribution2D::pdf(Vec2 p) const {
    if (conditional_.empty()) return 0.f;
    float pdfV = marginal_.pdf(p.y);
    if (pdfV == 0.f) return 0.f;
    int v = std::min(static_cast<int>(clamp(p.y, 0.f, 1.f) * countV()), countV() - 1);
    return pdfV * conditional_[v].pdf(p.x);
}

}  // namespace rlpbrt
