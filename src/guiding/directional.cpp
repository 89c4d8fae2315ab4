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

int sampleStrataCdf(const float* cdf, int n, float u) {
    // First entry of cdf[1..n] strictly greater than u; zero-width strata are skipped.
    const float* it = std::upper_bound(cdf + 1, cdf + n + 1, u);
    int j = static_cast<int>(it - (cdf + 1));
    if (j < n) return j;
    j = n - 1;  // u >= 1 (outside the contract): the last stratum of non-zero probability
    while (j > 0 && !(cdf[j + 1] > cdf[j])) --j;
    return j;
}

int sampleStrataCdf2D(const float* cdf, int cols, int rows, glm::vec2 u, glm::vec2* cell) {
    // The row: the first whose end exceeds u.x (rows of zero probability are skipped).
    int lo = 0, hi = rows - 1;
    while (lo < hi) {
        const int mid = (lo + hi) / 2;
        if (cdf[(mid + 1) * cols] > u.x) hi = mid;
        else lo = mid + 1;
    }
    int row = lo;
    // u.x at or above the last row's end (only by rounding): the last row of non-zero
    // probability.
    while (row > 0 && !(cdf[(row + 1) * cols] > cdf[row * cols])) --row;
    const float* c = cdf + row * cols;
    const float r0 = c[0], pr = c[cols] - c[0];
    const float fx = pr > 0.f ? (u.x - r0) / pr : 0.f;
    // The column: within the row's share of the CDF, at the fraction u.y of it.
    const float t = r0 + u.y * pr;
    lo = 0;
    hi = cols - 1;
    while (lo < hi) {
        const int mid = (lo + hi) / 2;
        if (c[mid + 1] > t) hi = mid;
        else lo = mid + 1;
    }
    int col = lo;
    while (col > 0 && !(c[col + 1] > c[col])) --col;
    const float pc = c[col + 1] - c[col];
    const float fy = pc > 0.f ? (t - c[col]) / pc : 0.f;
    cell->x = std::clamp(fx, 0.f, 0.99999994f);
    cell->y = std::clamp(fy, 0.f, 0.99999994f);
    return row * cols + col;
}

}  // namespace rlpbrt::guiding
