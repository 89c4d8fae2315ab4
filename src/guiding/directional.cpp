#include "guiding/directional.h"

#include <algorithm>

namespace rlpbrt::guiding {

StrataLayout::StrataLayout(int cols, int rows)
    : cols_(cols), rows_(rows), density_(static_cast<float>(cols * rows / (2.0 * PiDouble))) {
    octantShift_ = cols == 2 ? 2 : cols == 4 ? 1 : (cols == 8 || cols == 16) ? 0 : -1;
    centres_.resize(static_cast<size_t>(cols) * static_cast<size_t>(rows));
    for (int row = 0; row < rows; ++row) {
        // Centre in the map's coordinates: cos(theta) and phi at the middle of the cell.
        double z = (row + 0.5) / rows;
        double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        for (int col = 0; col < cols; ++col) {
            double phi = 2.0 * PiDouble * (col + 0.5) / cols;
            centres_[static_cast<size_t>(row * cols + col)] =
                glm::vec3(static_cast<float>(r * std::cos(phi)),
                          static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
        }
    }
}

std::vector<std::vector<uint32_t>> StrataLayout::quadtree() const {
    std::vector<std::vector<uint32_t>> levels;
    int c = cols_, r = rows_;
    do {
        const int pc = (c + 1) / 2, pr = (r + 1) / 2;
        std::vector<uint32_t> map(static_cast<size_t>(c) * static_cast<size_t>(r));
        for (int row = 0; row < r; ++row)
            for (int col = 0; col < c; ++col)
                map[static_cast<size_t>(row * c + col)] = uint32_t((row / 2) * pc + col / 2);
        levels.push_back(std::move(map));
        c = pc;
        r = pr;
    } while (c * r > 1);
    return levels;
}

std::vector<std::vector<uint32_t>> StrataLayout::sphereQuadtree() const {
    std::vector<std::vector<uint32_t>> levels = quadtree();
    for (std::vector<uint32_t>& map : levels) {
        uint32_t parents = 0;
        for (uint32_t p : map) parents = std::max(parents, p + 1);
        const size_t n = map.size();
        map.resize(2 * n);
        for (size_t i = 0; i < n; ++i) map[n + i] = map[i] + parents;
    }
    levels.push_back({0u, 0u});
    return levels;
}

void buildStrataCdf(const double* q, int n, double epsilon, float* cdf) {
    double sum = 0.0;
    for (int j = 0; j < n; ++j) sum += q[j];
    const bool uniform = !(sum > 0.0) || !std::isfinite(sum);
    const double floor = epsilon / n, scale = uniform ? 0.0 : (1.0 - epsilon) / sum;
    double acc = 0.0;
    cdf[0] = 0.f;
    for (int j = 0; j < n; ++j) {
        acc += uniform ? 1.0 / n : q[j] * scale + floor;
        cdf[j + 1] = static_cast<float>(std::min(acc, 1.0));
    }
    cdf[n] = 1.f;
}

double cosineSamplingVariance(const double* q, const StrataLayout& layout) {
    double qc = 0.0, q2c = 0.0, cs = 0.0;
    for (int j = 0; j < layout.count(); ++j) {
        const double c = double(layout.centre(j).z);
        qc += q[j] * c;
        q2c += q[j] * q[j] * c;
        cs += c;
    }
    const double v = q2c * cs / (qc * qc) - 1.0;
    return qc > 0.0 && std::isfinite(v) ? std::max(v, 0.0) : 0.0;
}

bool cosineSamplingSuffices(const double* q, const StrataLayout& layout, double prune,
                            float confidence) {
    return prune > 0.0 && confidence > 0.f && cosineSamplingVariance(q, layout) <= prune;
}

namespace {

// The piece of a CDF holding u: pieces i = 0..n-1 span [cdf[i * stride], cdf[(i + 1) * stride]);
// the first whose end exceeds u, so pieces of zero width are skipped. If none does (u at or
// above the last end: u >= 1, or a rounded position inside a row), the last piece of
// non-zero width.
int pieceAbove(const float* cdf, int n, int stride, float u) {
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        const int mid = (lo + hi) / 2;
        if (cdf[(mid + 1) * stride] > u) hi = mid;
        else lo = mid + 1;
    }
    // (A piece found by its end has start <= u < end: the loop only steps back from a last
    // piece not found.)
    while (lo > 0 && !(cdf[(lo + 1) * stride] > cdf[lo * stride])) --lo;
    return lo;
}

}  // namespace

int sampleStrataCdf(const float* cdf, int n, float u) { return pieceAbove(cdf, n, 1, u); }

int sampleStrataCdf2D(const float* cdf, int cols, int rows, glm::vec2 u, glm::vec2* cell) {
    // The row by the rows' marginal (a row's share is its end minus its start in the CDF).
    const int row = pieceAbove(cdf, rows, cols, u.x);
    const float* c = cdf + row * cols;
    // The column within the row's share of the CDF, at the fraction u.y of it.
    const float t = c[0] + u.y * (c[cols] - c[0]);
    const int col = pieceAbove(c, cols, 1, t);
    cell->x = remapInInterval(u.x, c[0], c[cols]);
    cell->y = remapInInterval(t, c[col], c[col + 1]);
    return row * cols + col;
}

}  // namespace rlpbrt::guiding
