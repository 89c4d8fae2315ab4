#include "render/fourier_bsdf.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "render/bxdfs.h"

namespace rlpbrt {

namespace {

constexpr char kMagic[8] = {'S', 'C', 'A', 'T', 'F', 'U', 'N', '\x01'};
constexpr int kHeaderBytes = 64;
constexpr int kMaxMu = 4096;
constexpr int kMaxOrder = 1024;  // coefficients per channel (stack scratch in the lobe)

uint32_t readLE32(const unsigned char* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
int32_t readInt(const unsigned char* p) { return int32_t(readLE32(p)); }
float readFloat(const unsigned char* p) {
    uint32_t u = readLE32(p);
    float f;
    std::memcpy(&f, &u, 4);
    return f;
}
void putLE32(std::string* out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out->push_back(char((v >> (8 * i)) & 0xff));
}
void putFloat(std::string* out, float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    putLE32(out, u);
}

// The largest i in [0, size - 2] with pred(i) true (0 if none): pbrt-v3's FindInterval.
template <typename Pred>
int findInterval(int size, Pred pred) {
    int first = 0, len = size;
    while (len > 0) {
        int half = len >> 1, middle = first + half;
        if (pred(middle)) {
            first = middle + 1;
            len -= half + 1;
        } else {
            len = half;
        }
    }
    return std::max(0, std::min(first - 1, size - 2));
}

// The Hermite segment i of a Catmull-Rom spline: values f0, f1 and derivatives d0, d1 scaled to
// the segment's width (pbrt-v3's finite differences, one-sided at the ends). get(j) = value j.
template <typename Get>
void segment(int n, const float* x, Get get, int i, float* f0, float* f1, float* d0, float* d1) {
    *f0 = get(i);
    *f1 = get(i + 1);
    float width = x[i + 1] - x[i];
    *d0 = i > 0 ? width * (*f1 - get(i - 1)) / (x[i + 1] - x[i - 1]) : *f1 - *f0;
    *d1 = i + 2 < n ? width * (get(i + 2) - *f0) / (x[i + 2] - x[i]) : *f1 - *f0;
}

}  // namespace

bool readFourierTable(const std::string& path, FourierTable* t, std::string* error) {
    auto fail = [&](const std::string& m) {
        if (error) *error = "tabulated BSDF \"" + path + "\": " + m;
        return false;
    };
    std::ifstream in(path, std::ios::binary);
    if (!in) return fail("cannot open the file");
    std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto* p = reinterpret_cast<const unsigned char*>(data.data());
    if (data.size() < size_t(kHeaderBytes) || std::memcmp(p, kMagic, 8) != 0)
        return fail("not a pbrt-v3 .bsdf file (no \"SCATFUN\\x01\" header)");
    int flags = readInt(p + 8), nCoeffs = readInt(p + 16), nBases = readInt(p + 28);
    t->nMu = readInt(p + 12);
    t->mMax = readInt(p + 20);
    t->nChannels = readInt(p + 24);
    t->eta = readFloat(p + 44);
    if (flags != 1 || nBases != 1 || (t->nChannels != 1 && t->nChannels != 3))
        return fail("unsupported variant (flags " + std::to_string(flags) + ", " +
                    std::to_string(t->nChannels) + " channels, " + std::to_string(nBases) +
                    " bases; pbrt-v3 reads flags 1, 1 or 3 channels, 1 basis)");
    if (t->nMu < 2 || t->nMu > kMaxMu || t->mMax < 1 || t->mMax > kMaxOrder || nCoeffs < 0 ||
        !(t->eta > 0.f) || !std::isfinite(t->eta))
        return fail("bad header values");
    const size_t n2 = size_t(t->nMu) * t->nMu;
    const size_t need = kHeaderBytes + 4 * (size_t(t->nMu) + n2 * 3 + size_t(nCoeffs));
    if (data.size() < need)
        return fail("truncated (" + std::to_string(data.size()) + " bytes, the header needs " +
                    std::to_string(need) + ")");
    p += kHeaderBytes;
    t->mu.resize(size_t(t->nMu));
    for (float& v : t->mu) v = readFloat(p), p += 4;
    t->cdf.resize(n2);
    for (float& v : t->cdf) v = readFloat(p), p += 4;
    t->aOffset.resize(n2);
    t->m.resize(n2);
    for (size_t i = 0; i < n2; ++i, p += 8) {
        t->aOffset[i] = readInt(p);
        t->m[i] = readInt(p + 4);
    }
    t->a.resize(size_t(nCoeffs));
    for (float& v : t->a) v = readFloat(p), p += 4;
    for (int i = 0; i < t->nMu; ++i)
        if (!std::isfinite(t->mu[size_t(i)]) || t->mu[size_t(i)] < -1.f ||
            t->mu[size_t(i)] > 1.f || (i > 0 && !(t->mu[size_t(i)] > t->mu[size_t(i) - 1])))
            return fail("the mu nodes must increase within [-1, 1]");
    for (float v : t->cdf)
        if (!std::isfinite(v)) return fail("a cdf value is not finite");
    for (float v : t->a)
        if (!std::isfinite(v)) return fail("a coefficient is not finite");
    t->a0.resize(n2);
    for (size_t i = 0; i < n2; ++i) {
        long long end = (long long)t->aOffset[i] + (long long)t->m[i] * t->nChannels;
        if (t->aOffset[i] < 0 || t->m[i] < 0 || t->m[i] > t->mMax || end > nCoeffs)
            return fail("coefficient block " + std::to_string(i) + " is out of range");
        t->a0[i] = t->m[i] > 0 ? t->a[size_t(t->aOffset[i])] : 0.f;
    }
    return true;
}

bool writeFourierTable(const std::string& path, const FourierTable& t, std::string* error) {
    std::string out(kMagic, 8);
    for (int v : {1, t.nMu, int(t.a.size()), t.mMax, t.nChannels, 1, 0, 0, 0}) putLE32(&out, uint32_t(v));
    putFloat(&out, t.eta);
    for (int i = 0; i < 4; ++i) putLE32(&out, 0);
    for (float v : t.mu) putFloat(&out, v);
    for (float v : t.cdf) putFloat(&out, v);
    for (size_t i = 0; i < t.aOffset.size(); ++i) {
        putLE32(&out, uint32_t(t.aOffset[i]));
        putLE32(&out, uint32_t(t.m[i]));
    }
    for (float v : t.a) putFloat(&out, v);
    std::ofstream f(path, std::ios::binary);
    f.write(out.data(), std::streamsize(out.size()));
    if (!f) {
        if (error) *error = "cannot write \"" + path + "\"";
        return false;
    }
    return true;
}

bool catmullRomWeights(int size, const float* nodes, float x, int* offset, float w[4]) {
    if (!(x >= nodes[0] && x <= nodes[size - 1])) return false;
    int i = findInterval(size, [&](int k) { return nodes[k] <= x; });
    *offset = i - 1;
    float x0 = nodes[i], x1 = nodes[i + 1];
    float t = (x - x0) / (x1 - x0), t2 = t * t, t3 = t2 * t;
    // Hermite basis: h00 f0 + h01 f1 + h10 d0 + h11 d1, with d0, d1 the finite differences.
    float h10 = t3 - 2 * t2 + t, h11 = t3 - t2;
    w[0] = 0.f;
    w[1] = 2 * t3 - 3 * t2 + 1;
    w[2] = -2 * t3 + 3 * t2;
    w[3] = 0.f;
    if (i > 0) {
        float s = h10 * (x1 - x0) / (x1 - nodes[i - 1]);  // d0 = (f1 - f_-1) scaled
        w[0] -= s;
        w[2] += s;
    } else {  // d0 = f1 - f0
        w[1] -= h10;
        w[2] += h10;
    }
    if (i + 2 < size) {
        float s = h11 * (x1 - x0) / (nodes[i + 2] - x0);  // d1 = (f2 - f0) scaled
        w[3] += s;
        w[1] -= s;
    } else {  // d1 = f1 - f0
        w[1] -= h11;
        w[2] += h11;
    }
    return true;
}

float integrateCatmullRom(int n, const float* x, const float* values, float* cdf) {
    float sum = 0.f;
    cdf[0] = 0.f;
    auto get = [&](int j) { return values[j]; };
    for (int i = 0; i + 1 < n; ++i) {
        float f0, f1, d0, d1;
        segment(n, x, get, i, &f0, &f1, &d0, &d1);
        // Integral of the Hermite segment over t in [0, 1], times the width.
        sum += ((d0 - d1) / 12.f + (f0 + f1) * 0.5f) * (x[i + 1] - x[i]);
        cdf[i + 1] = sum;
    }
    return sum;
}

float sampleCatmullRom2D(int size1, int size2, const float* nodes1, const float* nodes2,
                         const float* values, const float* cdf, float alpha, float u,
                         float* pdf) {
    int offset;
    float w[4];
    if (!catmullRomWeights(size1, nodes1, alpha, &offset, w)) {
        *pdf = 0.f;
        return 0.f;
    }
    auto interp = [&](const float* array, int idx) {
        float v = 0.f;
        for (int i = 0; i < 4; ++i)
            if (w[i] != 0.f) v += array[size_t(offset + i) * size2 + idx] * w[i];
        return v;
    };
    const float total = interp(cdf, size2 - 1);
    u *= total;
    int idx = findInterval(size2, [&](int i) { return interp(cdf, i) <= u; });
    float f0, f1, d0, d1;
    segment(size2, nodes2, [&](int j) { return interp(values, j); }, idx, &f0, &f1, &d0, &d1);
    const float x0 = nodes2[idx], width = nodes2[idx + 1] - x0;
    u = (u - interp(cdf, idx)) / width;
    // Invert the segment's integral F(t) = u by Newton steps safeguarded by bisection, from
    // the inverse of the linear interpolant's integral.
    float t = f0 != f1 ? (f0 - std::sqrt(std::max(0.f, f0 * f0 + 2 * u * (f1 - f0)))) / (f0 - f1)
                       : u / f0;
    float a = 0.f, b = 1.f, F, fv;
    for (int iter = 0; iter < 100; ++iter) {
        if (!(t >= a && t <= b)) t = 0.5f * (a + b);
        F = t * (f0 + t * (.5f * d0 + t * ((1.f / 3.f) * (-2 * d0 - d1) + f1 - f0 +
                                          t * (.25f * (d0 + d1) + .5f * (f0 - f1)))));
        fv = f0 + t * (d0 + t * (-2 * d0 - d1 + 3 * (f1 - f0) + t * (d0 + d1 + 2 * (f0 - f1))));
        if (std::abs(F - u) < 1e-6f || b - a < 1e-6f) break;
        if (F - u < 0) a = t;
        else b = t;
        t -= (F - u) / fv;
    }
    *pdf = total > 0.f ? fv / total : 0.f;
    return x0 + width * t;
}

float fourierSeries(const float* a, int m, double cosPhi) {
    // cos(k phi) by the Chebyshev recurrence cos((k+1) phi) = 2 cos phi cos(k phi) - cos((k-1) phi).
    double value = 0.0, prev = cosPhi, cur = 1.0;
    for (int k = 0; k < m; ++k) {
        value += a[k] * cur;
        double next = 2.0 * cosPhi * cur - prev;
        prev = cur;
        cur = next;
    }
    return float(value);
}

float sampleFourier(const float* a, int m, float u, float* pdf, float* phiOut) {
    // The series is even in phi: sample [0, pi] and mirror for u >= 1/2.
    bool flip = u >= 0.5f;
    u = flip ? 1.f - 2.f * (u - 0.5f) : 2.f * u;
    double lo = 0.0, hi = Pi, phi = 0.5 * Pi, F = 0.0, f = 0.0;
    for (int iter = 0; iter < 100; ++iter) {
        // F(phi) = a0 phi + sum_k a_k sin(k phi) / k - u a0 pi, f = F'.
        double c = std::cos(phi), s = std::sqrt(std::max(0.0, 1.0 - c * c));
        double cPrev = c, cCur = 1.0, sPrev = -s, sCur = 0.0;
        F = a[0] * phi;
        f = a[0];
        for (int k = 1; k < m; ++k) {
            double sNext = 2 * c * sCur - sPrev, cNext = 2 * c * cCur - cPrev;
            sPrev = sCur;
            sCur = sNext;
            cPrev = cCur;
            cCur = cNext;
            F += a[k] * sNext / k;
            f += a[k] * cNext;
        }
        F -= double(u) * a[0] * Pi;
        if (F > 0) hi = phi;
        else lo = phi;
        if (std::abs(F) < 1e-6 || hi - lo < 1e-6) break;
        phi -= F / f;
        if (!(phi > lo && phi < hi)) phi = 0.5 * (lo + hi);
    }
    if (flip) phi = 2.0 * Pi - phi;
    *pdf = float(f / (2.0 * Pi * a[0]));
    *phiOut = float(phi);
    return float(f);
}

// ---- The lobe ------------------------------------------------------------------------------

namespace {

// cos of the azimuth between a and b (1 if either is along the normal).
float cosDPhi(const Vec3& a, const Vec3& b) {
    float axy = a.x * a.x + a.y * a.y, bxy = b.x * b.x + b.y * b.y;
    if (axy == 0.f || bxy == 0.f) return 1.f;
    return clamp((a.x * b.x + a.y * b.y) / std::sqrt(axy * bxy), -1.f, 1.f);
}

// Interpolated Fourier coefficients at (muI, muO) of the first `channels` channels: blocks of
// t.mMax in ak; returns the largest order (0 if out of the table). *offO and wO: the mu_o
// spline's nodes and weights.
int interpolateCoefficients(const FourierTable& t, float muI, float muO, int channels,
                            float* ak, int* offO, float wO[4]) {
    int offI;
    float wI[4];
    if (!catmullRomWeights(t.nMu, t.mu.data(), muI, &offI, wI) ||
        !catmullRomWeights(t.nMu, t.mu.data(), muO, offO, wO))
        return 0;
    std::fill(ak, ak + size_t(t.mMax) * channels, 0.f);
    int mMax = 0;
    for (int b = 0; b < 4; ++b)
        for (int a = 0; a < 4; ++a) {
            float w = wI[a] * wO[b];
            if (w == 0.f) continue;
            int m;
            const float* ap = t.coefficients(offI + a, *offO + b, &m);
            mMax = std::max(mMax, m);
            for (int c = 0; c < channels; ++c)
                for (int k = 0; k < m; ++k) ak[c * t.mMax + k] += w * ap[c * m + k];
        }
    return mMax;
}

// The BSDF value from the luminance Y and the interpolated coefficients at cos phi.
Spectrum fourierValue(const FourierTable& t, TransportMode mode, const float* ak, int mMax,
                      float Y, float muI, float muO, float cosPhi) {
    float scale = muI != 0.f ? 1.f / std::abs(muI) : 0.f;
    // Radiance through the interface (mu_i and mu_o of one sign: -wi and wo on one side).
    if (mode == TransportMode::Radiance && muI * muO > 0.f) {
        float eta = muI > 0.f ? 1.f / t.eta : t.eta;
        scale *= eta * eta;
    }
    if (t.nChannels == 1) return Spectrum(Y * scale);
    float R = fourierSeries(ak + t.mMax, mMax, cosPhi);
    float B = fourierSeries(ak + 2 * t.mMax, mMax, cosPhi);
    float G = 1.39829f * Y - 0.100913f * B - 0.297375f * R;
    return glm::max(Spectrum(R, G, B) * scale, Spectrum(0.f));
}

}  // namespace

Spectrum FourierBSDF::f(const Vec3& wo, const Vec3& wi) const {
    const FourierTable& t = *table;
    float muI = -wi.z, muO = wo.z, cosPhi = cosDPhi(-wi, wo);
    float ak[3 * kMaxOrder], wO[4];
    int offO;
    int mMax = interpolateCoefficients(t, muI, muO, t.nChannels, ak, &offO, wO);
    if (mMax == 0) return Spectrum(0.f);
    float Y = std::max(0.f, fourierSeries(ak, mMax, cosPhi));
    return fourierValue(t, mode, ak, mMax, Y, muI, muO, cosPhi);
}

BxDFSample FourierBSDF::sampleF(const Vec3& wo, float, Vec2 u) const {
    const FourierTable& t = *table;
    float muO = wo.z, pdfMu;
    float muI = sampleCatmullRom2D(t.nMu, t.nMu, t.mu.data(), t.mu.data(), t.a0.data(),
                                   t.cdf.data(), muO, u.y, &pdfMu);
    float ak[3 * kMaxOrder], wO[4];
    int offO;
    int mMax = interpolateCoefficients(t, muI, muO, t.nChannels, ak, &offO, wO);
    if (mMax == 0 || !(ak[0] > 0.f)) return BxDFSample();
    float phi, pdfPhi;
    float Y = sampleFourier(ak, mMax, u.x, &pdfPhi, &phi);
    BxDFSample s;
    s.pdf = std::max(0.f, pdfPhi * pdfMu);
    if (!(s.pdf > 0.f) || !std::isfinite(s.pdf)) return BxDFSample();
    // -wi has cos theta muI and azimuth phi from wo's.
    float sin2ThetaI = std::max(0.f, 1.f - muI * muI);
    float sin2ThetaO = wo.x * wo.x + wo.y * wo.y;
    float norm = sin2ThetaO > 0.f ? std::sqrt(sin2ThetaI / sin2ThetaO) : 0.f;
    float sinPhi = std::sin(phi), cosPhi = std::cos(phi);
    Vec3 wi = -Vec3(norm * (cosPhi * wo.x - sinPhi * wo.y), norm * (sinPhi * wo.x + cosPhi * wo.y),
                    muI);
    if (sin2ThetaO == 0.f) {  // wo along the normal: phi is the azimuth of -wi itself
        float sinThetaI = std::sqrt(sin2ThetaI);
        wi = -Vec3(sinThetaI * cosPhi, sinThetaI * sinPhi, muI);
    }
    s.wi = glm::normalize(wi);
    s.f = fourierValue(t, mode, ak, mMax, std::max(0.f, Y), muI, muO, cosPhi);
    s.flags = BxDFFlags::Glossy |
              (s.wi.z * wo.z > 0.f ? BxDFFlags::Reflection : BxDFFlags::Transmission);
    return s;
}

float FourierBSDF::pdf(const Vec3& wo, const Vec3& wi) const {
    const FourierTable& t = *table;
    float muI = -wi.z, muO = wo.z, cosPhi = cosDPhi(-wi, wo);
    float ak[kMaxOrder], wO[4];
    int offO;
    int mMax = interpolateCoefficients(t, muI, muO, 1, ak, &offO, wO);  // luminance only
    if (mMax == 0) return 0.f;
    // rho: the integral of the luminance over the sphere at muO (2 pi x the a0 spline's
    // integral, interpolated in muO as sampleCatmullRom2D does).
    float rho = 0.f;
    for (int o = 0; o < 4; ++o)
        if (wO[o] != 0.f) rho += wO[o] * t.cdf[size_t(offO + o) * t.nMu + t.nMu - 1] * 2.f * Pi;
    float Y = fourierSeries(ak, mMax, cosPhi);
    return rho > 0.f && Y > 0.f ? Y / rho : 0.f;
}

}  // namespace rlpbrt
