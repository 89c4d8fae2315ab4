// Header-only Pearson chi-square goodness-of-fit helpers for tests of sampling routines:
// a generic test on observed/expected cell counts, and a spherical test that compares
// directions drawn by a sampling routine with the integral of its claimed pdf over a
// theta/phi grid (in the spirit of Nori's and Mitsuba's chi2 tests). Reusable for BSDFs,
// lights and guiding distributions.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "render/math.h"

namespace rlpbrt::chi2 {

// Regularised upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a), a > 0, x >= 0.
// Power series of P for x < a + 1, otherwise a continued fraction (modified Lentz).
inline double regularizedGammaQ(double a, double x) {
    if (!(x > 0.0)) return 1.0;
    if (!(a > 0.0)) return 0.0;
    double logPrefactor = -x + a * std::log(x) - std::lgamma(a);
    if (x < a + 1.0) {
        double term = 1.0 / a, sum = term, ap = a;
        for (int n = 0; n < 10000; ++n) {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if (std::abs(term) < std::abs(sum) * 1e-16) break;
        }
        return std::max(0.0, 1.0 - sum * std::exp(logPrefactor));
    }
    constexpr double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 10000; ++i) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (std::abs(d) < tiny) d = tiny;
        c = b + an / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        double delta = d * c;
        h *= delta;
        if (std::abs(delta - 1.0) < 1e-16) break;
    }
    return std::min(1.0, std::exp(logPrefactor) * h);
}

// Upper-tail probability of the chi-square distribution with dof degrees of freedom.
inline double chi2PValue(double statistic, int dof) {
    return regularizedGammaQ(0.5 * dof, 0.5 * statistic);
}

// Per-test significance that keeps the family-wise error rate at `significance` over
// numTests independent tests (Sidak correction).
inline double correctedSignificance(double significance, int numTests) {
    return 1.0 - std::pow(1.0 - significance, 1.0 / std::max(1, numTests));
}

struct Result {
    bool passed = false;
    double statistic = 0.0;
    int dof = 0;
    double pValue = 0.0;
    double threshold = 0.0;  // corrected significance level the p-value is compared with
    std::string message;
};

// Chi-square test of observed counts against expected counts (same total). Cells whose
// expectation is below minExpected are pooled (smallest first) until the pool reaches it.
// Fails outright if a cell with zero expectation received more than 1e-5 of all samples.
inline Result testCounts(const std::vector<double>& observed, const std::vector<double>& expected,
                         double significance = 0.01, int numTests = 1,
                         double minExpected = 5.0) {
    Result r;
    r.threshold = correctedSignificance(significance, numTests);
    size_t n = observed.size();
    double total = std::accumulate(observed.begin(), observed.end(), 0.0);
    std::ostringstream msg;
    for (size_t i = 0; i < n; ++i) {
        if (expected[i] <= 0.0 && observed[i] > 1e-5 * total) {
            msg << "cell " << i << " has expectation " << expected[i] << " but received "
                << observed[i] << " samples";
            r.message = msg.str();
            return r;
        }
    }
    std::vector<size_t> order(n);
    std::iota(order.begin(), order.end(), size_t(0));
    std::sort(order.begin(), order.end(),
              [&](size_t a, size_t b) { return expected[a] < expected[b]; });
    std::vector<double> obs, exp;
    double poolObs = 0.0, poolExp = 0.0;
    for (size_t k = 0; k < n; ++k) {
        size_t i = order[k];
        if (expected[i] < minExpected) {
            poolObs += observed[i];
            poolExp += expected[i];
            if (poolExp >= minExpected) {
                obs.push_back(poolObs);
                exp.push_back(poolExp);
                poolObs = poolExp = 0.0;
            }
        } else {
            obs.push_back(observed[i]);
            exp.push_back(expected[i]);
        }
    }
    if (poolExp > 0.0 || poolObs > 0.0) {
        if (exp.empty()) {
            obs.push_back(poolObs);
            exp.push_back(poolExp);
        } else {  // merge the leftover pool into the smallest emitted cell
            size_t smallest = size_t(std::min_element(exp.begin(), exp.end()) - exp.begin());
            obs[smallest] += poolObs;
            exp[smallest] += poolExp;
        }
    }
    for (size_t i = 0; i < obs.size(); ++i) {
        if (exp[i] > 0.0) r.statistic += (obs[i] - exp[i]) * (obs[i] - exp[i]) / exp[i];
    }
    r.dof = static_cast<int>(obs.size()) - 1;
    if (r.dof < 1) {
        r.passed = true;
        r.pValue = 1.0;
        r.message = "fewer than two cells after pooling; test is vacuous";
        return r;
    }
    r.pValue = chi2PValue(r.statistic, r.dof);
    r.passed = r.pValue >= r.threshold;
    msg << "chi2 = " << r.statistic << ", dof = " << r.dof << ", p = " << r.pValue
        << ", threshold = " << r.threshold;
    r.message = msg.str();
    return r;
}

// Adaptive Simpson quadrature of f over [a, b] to absolute tolerance eps.
template <typename F>
double adaptiveSimpson(const F& f, double a, double b, double eps, int maxDepth = 10) {
    struct Rec {
        const F& f;
        double step(double a, double b, double fa, double fm, double fb, double whole,
                    double eps, int depth) const {
            double m = 0.5 * (a + b);
            double lm = 0.5 * (a + m), rm = 0.5 * (m + b);
            double flm = f(lm), frm = f(rm);
            double left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
            double right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
            double delta = left + right - whole;
            if (depth <= 0 || std::abs(delta) <= 15.0 * eps) return left + right + delta / 15.0;
            return step(a, m, fa, flm, fm, left, 0.5 * eps, depth - 1) +
                   step(m, b, fm, frm, fb, right, 0.5 * eps, depth - 1);
        }
    } rec{f};
    // Start from four panels so that narrow peaks are not missed by the first estimate.
    constexpr int panels = 4;
    double h = (b - a) / panels, sum = 0.0;
    for (int p = 0; p < panels; ++p) {
        double a0 = a + p * h, b0 = a0 + h, m0 = 0.5 * (a0 + b0);
        double fa = f(a0), fm = f(m0), fb = f(b0);
        double whole = h / 6.0 * (fa + 4.0 * fm + fb);
        sum += rec.step(a0, b0, fa, fm, fb, whole, eps / panels, maxDepth);
    }
    return sum;
}

// One draw of a direction sampler: a direction (need not be exactly unit length) and the pdf
// the sampler claims for it (solid angle). pdf <= 0 or non-finite means "no sample".
struct SphereSample {
    Vec3 dir{0.f};
    float pdf = 0.f;
};

struct SphereOptions {
    int thetaRes = 10;             // bins in theta over [0, pi]
    int phiRes = 20;               // bins in phi over [0, 2 pi)
    long long sampleCount = 1000000;
    uint64_t seed = 1;
    double significance = 0.01;    // family-wise level over numTests tests
    int numTests = 1;
    double minExpected = 5.0;      // pooling threshold for cells
    double integrationEps = 1e-7;  // absolute quadrature tolerance per bin (pdf mass units)
    double pdfRelTolerance = 1e-2;        // sample pdf vs pdf(dir) agreement
    double maxPdfMismatchFraction = 1e-3; // allowed fraction of disagreeing samples
};

struct SphereResult : Result {
    double pdfIntegral = 0.0;  // integral of pdf over the sphere (valid-sample probability)
    long long invalidSamples = 0;
    long long pdfMismatches = 0;
};

// Draws sampleCount directions with sample(u) (u: three uniforms in [0,1)), bins them in
// (theta, phi) and compares with sampleCount times the integral of pdf(dir) over each bin; an
// extra cell compares the number of "no sample" draws with sampleCount * (1 - integral).
// Also checks that the pdf reported with each sample agrees with pdf(dir).
template <typename SampleFn, typename PdfFn>
SphereResult testSphere(const SampleFn& sample, const PdfFn& pdf, const SphereOptions& opt) {
    SphereResult res;
    const int nT = opt.thetaRes, nP = opt.phiRes;
    const size_t nCells = size_t(nT) * nP;
    std::vector<double> observed(nCells + 1, 0.0), expected(nCells + 1, 0.0);

    std::mt19937_64 rng(opt.seed);
    auto uniform = [&rng]() { return float(rng() >> 40) * 0x1p-24f; };
    for (long long i = 0; i < opt.sampleCount; ++i) {
        Vec3 u(uniform(), uniform(), uniform());
        SphereSample s = sample(u);
        float len = glm::length(s.dir);
        if (!(s.pdf > 0.f) || !std::isfinite(s.pdf) || !(len > 0.f) || !std::isfinite(len)) {
            ++res.invalidSamples;
            observed[nCells] += 1.0;
            continue;
        }
        Vec3 d = s.dir / len;
        float p = pdf(d);
        if (std::abs(p - s.pdf) > opt.pdfRelTolerance * std::max(p, s.pdf)) ++res.pdfMismatches;
        double theta = std::acos(clamp(double(d.z), -1.0, 1.0));
        double phi = std::atan2(double(d.y), double(d.x));
        if (phi < 0.0) phi += 2.0 * Pi;
        int it = clamp(int(theta / Pi * nT), 0, nT - 1);
        int ip = clamp(int(phi / (2.0 * Pi) * nP), 0, nP - 1);
        observed[size_t(it) * nP + ip] += 1.0;
    }

    double integral = 0.0;
    for (int it = 0; it < nT; ++it) {
        double t0 = Pi * it / nT, t1 = Pi * (it + 1) / nT;
        for (int ip = 0; ip < nP; ++ip) {
            double p0 = 2.0 * Pi * ip / nP, p1 = 2.0 * Pi * (ip + 1) / nP;
            auto inner = [&](double theta) {
                double st = std::sin(theta), ct = std::cos(theta);
                auto g = [&](double phi) {
                    Vec3 w(float(st * std::cos(phi)), float(st * std::sin(phi)), float(ct));
                    return double(pdf(w)) * st;
                };
                return adaptiveSimpson(g, p0, p1, opt.integrationEps, 8);
            };
            double mass = adaptiveSimpson(inner, t0, t1, opt.integrationEps, 8);
            integral += mass;
            expected[size_t(it) * nP + ip] = mass * double(opt.sampleCount);
        }
    }
    res.pdfIntegral = integral;
    expected[nCells] = std::max(0.0, 1.0 - integral) * double(opt.sampleCount);

    std::ostringstream msg;
    if (integral > 1.0 + 1e-3) {
        msg << "pdf integrates to " << integral << " > 1";
        res.message = msg.str();
        return res;
    }
    if (res.pdfMismatches > opt.maxPdfMismatchFraction * double(opt.sampleCount)) {
        msg << res.pdfMismatches << " samples report a pdf that differs from pdf(dir)";
        res.message = msg.str();
        return res;
    }
    Result r = testCounts(observed, expected, opt.significance, opt.numTests, opt.minExpected);
    static_cast<Result&>(res) = r;
    msg << r.message << "; pdf integral = " << integral << ", invalid samples = "
        << res.invalidSamples << " (expected " << expected[nCells] << ")";
    if (!r.passed) {
        // Observed/expected table by theta row, to see where the mismatch is.
        msg << "\nobserved/expected per (theta row, phi column):\n";
        for (int it = 0; it < nT; ++it) {
            for (int ip = 0; ip < nP; ++ip) {
                size_t c = size_t(it) * nP + ip;
                msg << int(observed[c]) << "/" << int(expected[c] + 0.5) << " ";
            }
            msg << "\n";
        }
    }
    res.message = msg.str();
    return res;
}

}  // namespace rlpbrt::chi2
