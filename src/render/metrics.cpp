#include "render/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace rlpbrt {

namespace {

void checkPair(const Image& test, const Image& ref, const char* what) {
    if (test.width <= 0 || test.height <= 0 || test.empty() || ref.empty())
        throw std::invalid_argument(std::string(what) + ": empty image");
    if (test.width != ref.width || test.height != ref.height) {
        throw std::invalid_argument(std::string(what) + ": image sizes differ (" +
                                    std::to_string(test.width) + "x" +
                                    std::to_string(test.height) + " vs " +
                                    std::to_string(ref.width) + "x" +
                                    std::to_string(ref.height) + ")");
    }
    if (test.channels < 3 || ref.channels < 3)
        throw std::invalid_argument(std::string(what) + ": images need at least 3 channels");
    size_t n = size_t(test.width) * test.height;
    if (test.pixels.size() != n * test.channels || ref.pixels.size() != n * ref.channels)
        throw std::invalid_argument(std::string(what) + ": pixel buffer size mismatch");
}

// The trimmed mean of e_p = mean over R,G,B of (x - y)^2 / (r^2 + 0.01), dropping the
// `renders` x floor(N / 1000) largest values; NaN if any e_p is not finite.
double trimmedWeightedSquares(const Image& x, const Image& y, const Image& r, size_t renders) {
    const size_t n = size_t(x.width) * x.height;
    std::vector<double> e(n);
    for (size_t i = 0; i < n; ++i) {
        double sum = 0;
        for (int c = 0; c < 3; ++c) {
            const double a = x.pixels[i * x.channels + c];
            const double b = y.pixels[i * y.channels + c];
            const double w = r.pixels[i * r.channels + c];
            sum += (a - b) * (a - b) / (w * w + 0.01);
        }
        e[i] = sum / 3;
    }
    // NaNs would break the ordering below; a non-finite input has no meaningful error.
    for (double v : e)
        if (!std::isfinite(v)) return std::numeric_limits<double>::quiet_NaN();
    const size_t drop = std::min(n - 1, renders * (n / 1000));
    const size_t keep = n - drop;
    // Move the `keep` smallest values to the front.
    if (drop > 0) std::nth_element(e.begin(), e.begin() + (keep - 1), e.end());
    double sum = 0;
    for (size_t i = 0; i < keep; ++i) sum += e[i];
    return sum / double(keep);
}

}  // namespace

double relMseTrimmed(const Image& test, const Image& ref) {
    checkPair(test, ref, "relMseTrimmed");
    return trimmedWeightedSquares(test, ref, ref, 1);
}

double pairRelMse(const Image& a, const Image& b, const Image& ref) {
    checkPair(a, b, "pairRelMse");
    checkPair(a, ref, "pairRelMse");
    return 0.5 * trimmedWeightedSquares(a, b, ref, 2);
}

double blockBias(const Image& test, const Image& ref, int block) {
    checkPair(test, ref, "blockBias");
    if (block <= 0) throw std::invalid_argument("blockBias: block size must be positive");
    const int w = ref.width, h = ref.height;

    double total = 0;
    for (size_t i = 0; i < size_t(w) * h; ++i)
        for (int c = 0; c < 3; ++c) total += ref.pixels[i * ref.channels + c];
    const double imageMean = total / (3.0 * w * h);

    std::vector<double> dev;
    for (int by = 0; by + block <= h; by += block) {
        for (int bx = 0; bx + block <= w; bx += block) {
            double st = 0, sr = 0;
            for (int y = by; y < by + block; ++y) {
                for (int x = bx; x < bx + block; ++x) {
                    for (int c = 0; c < 3; ++c) {
                        st += test.at(x, y, c);
                        sr += ref.at(x, y, c);
                    }
                }
            }
            const double count = 3.0 * block * block;
            const double mT = st / count, mR = sr / count;
            if (mR > 0.05 * imageMean) dev.push_back(std::abs(mT / mR - 1));
        }
    }
    if (dev.empty()) return std::numeric_limits<double>::quiet_NaN();
    const size_t m = dev.size() / 2;
    std::nth_element(dev.begin(), dev.begin() + m, dev.end());
    const double upper = dev[m];
    if (dev.size() % 2 == 1) return upper;
    const double lower = *std::max_element(dev.begin(), dev.begin() + m);
    return 0.5 * (lower + upper);
}

bool hasNonFinite(const Image& img) {
    for (float v : img.pixels)
        if (!std::isfinite(v)) return true;
    return false;
}

}  // namespace rlpbrt
