#include "render/efficiency.h"

#include <algorithm>
#include <cmath>

#include "guiding/field_io.h"
#include "render/distributed.h"

namespace rlpbrt {

PassMoments::PassMoments(const Bounds2i& bounds, size_t maxPixels) : bounds_(bounds) {
    width_ = bounds.width();
    const size_t pixels = size_t(bounds.area());
    maxPixels = std::max<size_t>(maxPixels, 1);
    rowStride_ = std::max(1L, long((pixels + maxPixels - 1) / maxPixels));
    const long rows = (long(bounds.height()) + rowStride_ - 1) / rowStride_;
    const size_t n = size_t(rows) * size_t(width_);
    mean_.assign(3 * n, 0.f);
    var_.assign(3 * n, 0.f);
    count_.assign(n, 0);
}

long PassMoments::slot(int x, int y) const {
    if (!bounds_.contains(glm::ivec2(x, y))) return -1;
    const long row = long(y - bounds_.pMin.y);
    return row % rowStride_ == 0 ? (row / rowStride_) * width_ + long(x - bounds_.pMin.x) : -1;
}

namespace {
// One part's mean and sum of squared deviations from it, from its n samples' sums.
void partMoments(int n, double sum, double sumSq, double* mean, double* ss) {
    *mean = sum / n;
    *ss = std::max(0.0, sumSq - sum * *mean);
}
}  // namespace

void PassMoments::set(int x, int y, int n, const double sum[3], const double sumSq[3]) {
    const long s = slot(x, y);
    if (s < 0 || n <= 0) return;
    count_[size_t(s)] = n;
    for (size_t c = 0; c < 3; ++c) {
        double m, ss;
        partMoments(n, sum[c], sumSq[c], &m, &ss);
        mean_[size_t(s) * 3 + c] = float(m);
        var_[size_t(s) * 3 + c] = n > 1 ? float(ss / (n - 1)) : 0.f;
    }
}

void PassMoments::add(int x, int y, int n, const double sum[3], const double sumSq[3]) {
    const long s = slot(x, y);
    if (s < 0 || n <= 0) return;
    const int before = count_[size_t(s)];
    if (before == 0) return set(x, y, n, sum, sumSq);
    // Pooled moments: the sums of squares about each part's mean, plus the spread of the means.
    const int total = before + n;
    count_[size_t(s)] = total;
    for (size_t c = 0; c < 3; ++c) {
        float& m = mean_[size_t(s) * 3 + c];
        float& v = var_[size_t(s) * 3 + c];
        double m2, ss2;
        partMoments(n, sum[c], sumSq[c], &m2, &ss2);
        const double m1 = double(m), ss1 = double(v) * (before - 1);
        const double d = m2 - m1;
        const double ss = ss1 + ss2 + d * d * double(before) * double(n) / total;
        m = float((m1 * before + sum[c]) / total);
        v = float(ss / (total - 1));
    }
}

void PassMoments::accumulate(int x, int y, int n, const double sum[3]) {
    const long s = slot(x, y);
    if (s < 0 || n <= 0) return;
    const int before = count_[size_t(s)];
    const int total = before + n;
    for (size_t c = 0; c < 3; ++c) {
        float& m = mean_[size_t(s) * 3 + c];
        m = float((double(m) * before + sum[c]) / total);
    }
    count_[size_t(s)] = total;
}

void PassMoments::sumAcross(Ranks& ranks) {
    // Each pixel is set on one rank and zero on the others: the sums are exact.
    ranks.sumDisjointFloats(mean_.data(), mean_.size(), true);
    ranks.sumDisjointFloats(var_.data(), var_.size(), true);
    std::vector<uint32_t> counts(count_.begin(), count_.end());
    ranks.sumCounts(counts.data(), counts.size());
    std::copy(counts.begin(), counts.end(), count_.begin());
}

void PassMoments::clear(const Bounds2i& rect) {
    for (int y = rect.pMin.y; y < rect.pMax.y; ++y)
        for (int x = rect.pMin.x; x < rect.pMax.x; ++x) {
            const long s = slot(x, y);
            if (s < 0) continue;
            count_[size_t(s)] = 0;
            std::fill_n(mean_.begin() + s * 3, 3, 0.f);
            std::fill_n(var_.begin() + s * 3, 3, 0.f);
        }
}

double PassMoments::relativeVariance(const PassMoments& reference) const {
    if (!(bounds_ == reference.bounds_) || rowStride_ != reference.rowStride_) return -1.0;
    std::vector<double> rv;
    rv.reserve(count_.size());
    for (size_t i = 0; i < count_.size(); ++i) {
        if (count_[i] < 2) continue;
        // The reference: median of the set means among the pixel and two neighbours on either
        // side in its row.
        const long x = long(i) % width_, rowStart = long(i) - x;
        float near[3][5];
        int k = 0;
        for (long dx = -2; dx <= 2; ++dx) {
            const long xx = x + dx;
            if (xx < 0 || xx >= width_ || reference.count_[size_t(rowStart + xx)] < 1) continue;
            for (size_t c = 0; c < 3; ++c) near[c][k] = reference.mean_[size_t(rowStart + xx) * 3 + c];
            ++k;
        }
        if (k == 0) continue;
        double sum = 0.0;
        for (size_t c = 0; c < 3; ++c) {
            std::nth_element(near[c], near[c] + k / 2, near[c] + k);
            const double m = double(near[c][k / 2]);
            sum += double(var_[i * 3 + c]) / (m * m + 0.01);
        }
        if (std::isfinite(sum)) rv.push_back(sum / 3.0);
    }
    if (rv.empty()) return -1.0;
    // Median of the means of kGroups interleaved pixel groups: a single extreme sample (which
    // a trimmed mean would drop with the pixel, and which would decide a plain mean) moves
    // one group; light that many pixels receive rarely still moves them all.
    constexpr size_t kGroups = 15;
    double sums[kGroups] = {}, means[kGroups] = {};
    size_t counts[kGroups] = {};
    for (size_t i = 0; i < rv.size(); ++i) {
        sums[i % kGroups] += rv[i];
        ++counts[i % kGroups];
    }
    size_t groups = 0;
    for (size_t g = 0; g < kGroups; ++g)
        if (counts[g] > 0) means[groups++] = sums[g] / double(counts[g]);
    std::nth_element(means, means + groups / 2, means + groups);
    return means[groups / 2];
}

std::string PassMoments::state() const {
    guiding::fieldio::Writer w;
    w.u64(count_.size());
    for (float v : mean_) w.f32(v);
    for (float v : var_) w.f32(v);
    for (int c : count_) w.u32(uint32_t(c));
    return std::move(w.data);
}

bool PassMoments::setState(const std::string& state) {
    guiding::fieldio::Reader r(state);
    const uint64_t n = r.u64();
    if (!r.ok() || n != count_.size() || r.remaining() != n * 28) return false;
    for (float& v : mean_) v = r.f32();
    for (float& v : var_) v = r.f32();
    for (int& c : count_) c = int(r.u32());
    return r.ok();
}

}  // namespace rlpbrt
