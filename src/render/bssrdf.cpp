#include "render/bssrdf.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <utility>

#include "render/bxdfs.h"
#include "render/fourier_bsdf.h"

namespace rlpbrt {

float fresnelMoment1(float eta) {
    const float e2 = eta * eta, e3 = e2 * eta, e4 = e3 * eta, e5 = e4 * eta;
    if (eta < 1.f)
        return 0.45966f - 1.73965f * eta + 3.37668f * e2 - 3.904945f * e3 + 2.49277f * e4 -
               0.68441f * e5;
    return -4.61686f + 11.1136f * eta - 10.4646f * e2 + 5.11455f * e3 - 1.27198f * e4 +
           0.12746f * e5;
}

float fresnelMoment2(float eta) {
    const float e2 = eta * eta, e3 = e2 * eta, e4 = e3 * eta, e5 = e4 * eta;
    if (eta < 1.f)
        return 0.27614f - 0.87350f * eta + 1.12077f * e2 - 0.65095f * e3 + 0.07883f * e4 +
               0.04860f * e5;
    const float r = 1.f / eta, r2 = r * r, r3 = r2 * r;
    return -547.033f + 45.3087f * r3 - 218.725f * r2 + 458.843f * r + 404.557f * eta -
           189.519f * e2 + 54.9327f * e3 - 9.00603f * e4 + 0.63942f * e5;
}

namespace {
constexpr int kBeamSamples = 100;
constexpr float kInv4Pi = 0.07957747154594767f;

float phaseHG(float cosTheta, float g) {
    const float denom = 1.f + g * g + 2.f * g * cosTheta;
    return kInv4Pi * (1.f - g * g) / (denom * std::sqrt(denom));
}
}  // namespace

float beamDiffusionMS(float sigmaS, float sigmaA, float g, float eta, float r) {
    // Reduced coefficients, the non-classical diffusion coefficient D (Grosjean) and the
    // effective transport coefficient; the extrapolated boundary at depth ze (above the
    // surface, negative) and the exitance weights of fluence and flux.
    const float sps = sigmaS * (1.f - g), spt = sigmaA + sps, rhop = sps / spt;
    const float D = (2.f * sigmaA + sps) / (3.f * spt * spt);
    const float str = std::sqrt(sigmaA / D);
    const float fm1 = fresnelMoment1(eta), fm2 = fresnelMoment2(eta);
    const float ze = -2.f * D * (1.f + 3.f * fm2) / (1.f - 2.f * fm1);
    const float cPhi = 0.25f * (1.f - 2.f * fm1), cE = 0.5f * (1.f - 3.f * fm2);
    float sum = 0.f;
    for (int i = 0; i < kBeamSamples; ++i) {
        // Real sources at depths distributed as the beam's first scattering (stratified).
        const float zr = -std::log(1.f - (float(i) + 0.5f) / kBeamSamples) / spt;
        const float zv = 2.f * ze - zr;
        const float dr = std::sqrt(r * r + zr * zr), dv = std::sqrt(r * r + zv * zv);
        const float er = std::exp(-str * dr), ev = std::exp(-str * dv);
        const float phi = kInv4Pi / D * (er / dr - ev / dv);
        const float edn = kInv4Pi * (zr * (1.f + str * dr) * er / (dr * dr * dr) -
                                     zv * (1.f + str * dv) * ev / (dv * dv * dv));
        const float kappa = 1.f - std::exp(-2.f * spt * (dr + zr));
        sum += kappa * rhop * rhop * (phi * cPhi + edn * cE);
    }
    return sum / kBeamSamples;
}

float beamDiffusionSS(float sigmaS, float sigmaA, float g, float eta, float r) {
    // Single scattering along the refracted beam, below the depth where the connection to the
    // exit is beyond the critical angle.
    const float st = sigmaA + sigmaS, rho = sigmaS / st;
    const float tCrit = r * std::sqrt(std::max(0.f, eta * eta - 1.f));
    float sum = 0.f;
    for (int i = 0; i < kBeamSamples; ++i) {
        const float t = tCrit - std::log(1.f - (float(i) + 0.5f) / kBeamSamples) / st;
        const float d = std::sqrt(r * r + t * t), cosO = t / d;
        sum += rho * std::exp(-st * (d + tCrit)) / (d * d) * phaseHG(cosO, g) *
               (1.f - frDielectric(-cosO, 1.f, eta)) * std::abs(cosO);
    }
    return sum / kBeamSamples;
}

void computeBeamDiffusionTable(float g, float eta, BSSRDFTable* t) {
    t->nRho = 100;
    t->nRadius = 64;
    t->rho.assign(size_t(t->nRho), 0.f);
    t->radius.assign(size_t(t->nRadius), 0.f);
    t->profile.assign(size_t(t->nRho * t->nRadius), 0.f);
    t->cdf.assign(t->profile.size(), 0.f);
    t->rhoEff.assign(size_t(t->nRho), 0.f);
    t->radius[1] = 2.5e-3f;
    for (int i = 2; i < t->nRadius; ++i) t->radius[size_t(i)] = t->radius[size_t(i - 1)] * 1.2f;
    for (int i = 0; i < t->nRho; ++i)
        t->rho[size_t(i)] = (1.f - std::exp(-8.f * float(i) / float(t->nRho - 1))) /
                            (1.f - std::exp(-8.f));
    for (int i = 0; i < t->nRho; ++i) {
        float* row = &t->profile[size_t(i * t->nRadius)];
        const float rho = t->rho[size_t(i)];
        for (int j = 0; j < t->nRadius; ++j) {
            const float r = t->radius[size_t(j)];
            row[j] = 2.f * Pi * r *
                     (beamDiffusionSS(rho, 1.f - rho, g, eta, r) +
                      beamDiffusionMS(rho, 1.f - rho, g, eta, r));
        }
        t->rhoEff[size_t(i)] =
            integrateCatmullRom(t->nRadius, t->radius.data(), row, &t->cdf[size_t(i * t->nRadius)]);
    }
}

std::shared_ptr<const BSSRDFTable> beamDiffusionTable(float g, float eta) {
    static std::mutex mutex;
    static std::map<std::pair<float, float>, std::weak_ptr<const BSSRDFTable>> cache;
    std::lock_guard<std::mutex> lock(mutex);
    auto& slot = cache[{g, eta}];
    if (auto t = slot.lock()) return t;
    auto t = std::make_shared<BSSRDFTable>();
    computeBeamDiffusionTable(g, eta, t.get());
    slot = t;
    return t;
}

namespace {
// The Catmull-Rom spline through (nodes, values) at x (0 outside the nodes).
float splineAt(int n, const float* nodes, const float* values, float x) {
    int offset;
    float w[4];
    if (!catmullRomWeights(n, nodes, x, &offset, w)) return 0.f;
    float v = 0.f;
    for (int i = 0; i < 4; ++i)
        if (w[i] != 0.f) v += w[i] * values[offset + i];
    return v;
}
}  // namespace

void subsurfaceFromDiffuse(const BSSRDFTable& t, const Spectrum& rhoEff, const Spectrum& mfp,
                           Spectrum* sigmaA, Spectrum* sigmaS) {
    for (int c = 0; c < 3; ++c) {
        // rhoEff grows with rho: bisection on the spline (clamped to the table's range).
        const float y = rhoEff[c];
        float rho;
        if (!(y > t.rhoEff.front())) {
            rho = t.rho.front();
        } else if (y >= t.rhoEff.back()) {
            rho = t.rho.back();
        } else {
            float lo = t.rho.front(), hi = t.rho.back();
            for (int it = 0; it < 40; ++it) {
                const float mid = 0.5f * (lo + hi);
                if (splineAt(t.nRho, t.rho.data(), t.rhoEff.data(), mid) < y) lo = mid;
                else hi = mid;
            }
            rho = 0.5f * (lo + hi);
        }
        (*sigmaS)[c] = rho / mfp[c];
        (*sigmaA)[c] = (1.f - rho) / mfp[c];
    }
}

namespace {
struct Measured {
    const char* name;
    float sps[3], sa[3];  // sigma'_s, sigma_a in mm^-1
};
// The published measurements pbrt-v3 tabulates (values from the papers).
const Measured kMeasured[] = {
    {"Apple", {2.29f, 2.39f, 1.97f}, {0.0030f, 0.0034f, 0.046f}},
    {"Chicken1", {0.15f, 0.21f, 0.38f}, {0.015f, 0.077f, 0.19f}},
    {"Chicken2", {0.19f, 0.25f, 0.32f}, {0.018f, 0.088f, 0.20f}},
    {"Cream", {7.38f, 5.47f, 3.15f}, {0.0002f, 0.0028f, 0.0163f}},
    {"Ketchup", {0.18f, 0.07f, 0.03f}, {0.061f, 0.97f, 1.45f}},
    {"Marble", {2.19f, 2.62f, 3.00f}, {0.0021f, 0.0041f, 0.0071f}},
    {"Potato", {0.68f, 0.70f, 0.55f}, {0.0024f, 0.0090f, 0.12f}},
    {"Skimmilk", {0.70f, 1.22f, 1.90f}, {0.0014f, 0.0025f, 0.0142f}},
    {"Skin1", {0.74f, 0.88f, 1.01f}, {0.032f, 0.17f, 0.48f}},
    {"Skin2", {1.09f, 1.59f, 1.79f}, {0.013f, 0.070f, 0.145f}},
    {"Spectralon", {11.6f, 20.4f, 14.9f}, {0.00f, 0.00f, 0.00f}},
    {"Wholemilk", {2.55f, 3.21f, 3.77f}, {0.0011f, 0.0024f, 0.014f}},
    {"Lowfat Milk", {0.89187f, 1.5136f, 2.532f}, {0.002875f, 0.00575f, 0.0115f}},
    {"Reduced Milk", {2.4858f, 3.1669f, 4.5214f}, {0.0025556f, 0.0051111f, 0.012778f}},
    {"Regular Milk", {4.5513f, 5.8294f, 7.136f}, {0.0015333f, 0.0046f, 0.019933f}},
    {"Espresso", {0.72378f, 0.84557f, 1.0247f}, {4.7984f, 6.5751f, 8.8493f}},
    {"Mint Mocha Coffee", {0.31602f, 0.38538f, 0.48131f}, {3.772f, 5.8228f, 7.82f}},
    {"Lowfat Soy Milk", {0.30576f, 0.34233f, 0.61664f}, {0.0014375f, 0.0071875f, 0.035937f}},
    {"Regular Soy Milk", {0.59223f, 0.73866f, 1.4693f}, {0.0019167f, 0.0095833f, 0.065167f}},
    {"Lowfat Chocolate Milk", {0.64925f, 0.83916f, 1.1057f}, {0.0115f, 0.0368f, 0.1564f}},
    {"Regular Chocolate Milk", {1.4585f, 2.1289f, 2.9527f}, {0.010063f, 0.043125f, 0.14375f}},
    {"Coke", {8.9053e-05f, 8.372e-05f, 0.f}, {0.10014f, 0.16503f, 0.2468f}},
    {"Pepsi", {6.1697e-05f, 4.2564e-05f, 0.f}, {0.091641f, 0.14158f, 0.20729f}},
    {"Sprite", {6.0306e-06f, 6.4139e-06f, 6.5504e-06f}, {0.001886f, 0.0018308f, 0.0020025f}},
    {"Gatorade", {0.0024574f, 0.003007f, 0.0037325f}, {0.024794f, 0.019289f, 0.008878f}},
    {"Chardonnay", {1.7982e-05f, 1.3758e-05f, 1.2023e-05f}, {0.010782f, 0.011855f, 0.023997f}},
    {"White Zinfandel", {1.7501e-05f, 1.9069e-05f, 1.288e-05f}, {0.012072f, 0.016184f, 0.019843f}},
    {"Merlot", {2.1129e-05f, 0.f, 0.f}, {0.11632f, 0.25191f, 0.29434f}},
    {"Budweiser Beer", {2.4356e-05f, 2.4079e-05f, 1.0564e-05f}, {0.011492f, 0.024911f, 0.057786f}},
    {"Coors Light Beer", {5.0922e-05f, 4.301e-05f, 0.f}, {0.006164f, 0.013984f, 0.034983f}},
    {"Clorox", {0.0024035f, 0.0031373f, 0.003991f}, {0.0033542f, 0.014892f, 0.026297f}},
    {"Apple Juice", {0.00013612f, 0.00015836f, 0.000227f}, {0.012957f, 0.023741f, 0.052184f}},
    {"Cranberry Juice", {0.00010402f, 0.00011646f, 7.8139e-05f}, {0.039437f, 0.094223f, 0.12426f}},
    {"Grape Juice", {5.382e-05f, 0.f, 0.f}, {0.10404f, 0.23958f, 0.29325f}},
    {"Ruby Grapefruit Juice", {0.011002f, 0.010927f, 0.011036f}, {0.085867f, 0.18314f, 0.25262f}},
    {"White Grapefruit Juice", {0.22826f, 0.23998f, 0.32748f}, {0.0138f, 0.018831f, 0.056781f}},
    {"Shampoo", {0.0007176f, 0.0008303f, 0.0009016f}, {0.014107f, 0.045693f, 0.061717f}},
    {"Strawberry Shampoo", {0.00015671f, 0.00015947f, 1.518e-05f}, {0.01449f, 0.05796f, 0.075823f}},
    {"Head & Shoulders Shampoo", {0.023805f, 0.028804f, 0.034306f}, {0.084621f, 0.15688f, 0.20365f}},
    {"Lemon Tea Powder", {0.040224f, 0.045264f, 0.051081f}, {2.4288f, 4.5757f, 7.2127f}},
    {"Orange Powder", {0.00015617f, 0.00017482f, 0.0001762f}, {0.001449f, 0.003441f, 0.007863f}},
    {"Pink Lemonade Powder", {0.00012103f, 0.00013073f, 0.00012528f}, {0.001165f, 0.002366f, 0.003195f}},
    {"Cappuccino Powder", {1.8436f, 2.5851f, 2.1662f}, {35.844f, 49.547f, 61.084f}},
    {"Salt Powder", {0.027333f, 0.032451f, 0.031979f}, {0.28415f, 0.3257f, 0.34148f}},
    {"Sugar Powder", {0.00022272f, 0.00025513f, 0.000271f}, {0.012638f, 0.031051f, 0.050124f}},
    {"Suisse Mocha Powder", {2.7979f, 3.5452f, 4.3365f}, {17.502f, 27.004f, 35.433f}},
    {"Pacific Ocean Surface Water", {0.0001764f, 0.00032095f, 0.00019617f}, {0.031845f, 0.031324f, 0.030147f}},
};
}  // namespace

bool measuredSubsurface(const std::string& name, Spectrum* sigmaA, Spectrum* sigmaPrimeS) {
    for (const Measured& m : kMeasured) {
        if (name != m.name) continue;
        *sigmaA = Spectrum(m.sa[0], m.sa[1], m.sa[2]);
        *sigmaPrimeS = Spectrum(m.sps[0], m.sps[1], m.sps[2]);
        return true;
    }
    return false;
}

SeparableBSSRDF SeparableBSSRDF::tabulated(const BSSRDFTable* table, const Spectrum& sigmaA,
                                           const Spectrum& sigmaS, float eta) {
    SeparableBSSRDF b;
    b.kind_ = Kind::Tabulated;
    b.table_ = table;
    b.sigmaT_ = sigmaA + sigmaS;
    for (int c = 0; c < 3; ++c) b.rho_[c] = b.sigmaT_[c] != 0.f ? sigmaS[c] / b.sigmaT_[c] : 0.f;
    b.eta_ = eta;
    return b;
}

SeparableBSSRDF SeparableBSSRDF::disney(const Spectrum& R, const Spectrum& sd, float eta) {
    SeparableBSSRDF b;
    b.kind_ = Kind::Disney;
    b.r_ = R;
    b.d_ = 0.2f * sd;  // pbrt-v3's factor
    b.eta_ = eta;
    return b;
}

Spectrum SeparableBSSRDF::sr(float r) const {
    Spectrum out(0.f);
    if (kind_ == Kind::Disney) {
        r = std::max(r, 1e-6f);
        for (int c = 0; c < 3; ++c) {
            const float d = d_[c];
            if (!(d > 0.f)) continue;
            out[c] = r_[c] * (std::exp(-r / d) + std::exp(-r / (3.f * d))) / (8.f * Pi * d * r);
        }
        return glm::max(out, Spectrum(0.f));
    }
    const BSSRDFTable& t = *table_;
    for (int c = 0; c < 3; ++c) {
        // The table is in optical units (sigma_t = 1): scale the radius in and the area
        // density out.
        const float rOpt = r * sigmaT_[c];
        int oRho, oRad;
        float wRho[4], wRad[4];
        if (!catmullRomWeights(t.nRho, t.rho.data(), rho_[c], &oRho, wRho) ||
            !catmullRomWeights(t.nRadius, t.radius.data(), rOpt, &oRad, wRad))
            continue;
        float v = 0.f;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j)
                if (wRho[i] * wRad[j] != 0.f) v += wRho[i] * wRad[j] * t.at(oRho + i, oRad + j);
        if (rOpt != 0.f) v /= 2.f * Pi * rOpt;  // the table holds 2 pi r Sr
        out[c] = v * sigmaT_[c] * sigmaT_[c];
    }
    return glm::max(out, Spectrum(0.f));
}

float SeparableBSSRDF::sampleSr(int ch, float u) const {
    if (kind_ == Kind::Disney) {
        const float d = d_[ch];
        if (!(d > 0.f)) return -1.f;
        // One exponential with probability 1/4, the other (3 d) with 3/4.
        if (u < 0.25f) {
            u = std::min(u * 4.f, OneMinusEpsilon);
            return d * std::log(1.f / (1.f - u));
        }
        u = std::min((u - 0.25f) / 0.75f, OneMinusEpsilon);
        return 3.f * d * std::log(1.f / (1.f - u));
    }
    if (sigmaT_[ch] == 0.f) return -1.f;
    const BSSRDFTable& t = *table_;
    float pdf;
    return sampleCatmullRom2D(t.nRho, t.nRadius, t.rho.data(), t.radius.data(),
                              t.profile.data(), t.cdf.data(), rho_[ch], u, &pdf) /
           sigmaT_[ch];
}

float SeparableBSSRDF::pdfSr(int ch, float r) const {
    if (kind_ == Kind::Disney) {
        const float d = d_[ch];
        if (!(d > 0.f)) return 0.f;
        r = std::max(r, 1e-6f);
        return 0.25f * std::exp(-r / d) / (2.f * Pi * d * r) +
               0.75f * std::exp(-r / (3.f * d)) / (6.f * Pi * d * r);
    }
    const BSSRDFTable& t = *table_;
    const float st = sigmaT_[ch], rOpt = r * st;
    int oRho, oRad;
    float wRho[4], wRad[4];
    if (!catmullRomWeights(t.nRho, t.rho.data(), rho_[ch], &oRho, wRho) ||
        !catmullRomWeights(t.nRadius, t.radius.data(), rOpt, &oRad, wRad))
        return 0.f;
    float v = 0.f, eff = 0.f;
    for (int i = 0; i < 4; ++i) {
        if (wRho[i] == 0.f) continue;
        eff += wRho[i] * t.rhoEff[size_t(oRho + i)];
        for (int j = 0; j < 4; ++j)
            if (wRad[j] != 0.f) v += wRho[i] * wRad[j] * t.at(oRho + i, oRad + j);
    }
    if (rOpt != 0.f) v /= 2.f * Pi * rOpt;
    if (!(eff > 0.f)) return 0.f;
    return std::max(0.f, v * st * st / eff);
}

bool sampleProbe(const SeparableBSSRDF& b, const Frame& f, const Vec3& po, float u1, Vec2 u2,
                 BSSRDFProbe* probe) {
    // The probe axis vz and the plane (vx, vy) the radius is sampled in.
    Vec3 vx, vy, vz;
    if (u1 < 0.5f) {
        vx = f.s, vy = f.t, vz = f.n;
        u1 *= 2.f;
    } else if (u1 < 0.75f) {
        vx = f.t, vy = f.n, vz = f.s;
        u1 = (u1 - 0.5f) * 4.f;
    } else {
        vx = f.n, vy = f.s, vz = f.t;
        u1 = (u1 - 0.75f) * 4.f;
    }
    const int ch = std::min(int(u1 * 3.f), 2);
    probe->uPick = std::min(u1 * 3.f - float(ch), OneMinusEpsilon);
    const float r = b.sampleSr(ch, u2.x);
    if (r < 0.f) return false;
    const float rMax = b.rMax(ch);
    if (!(r < rMax)) return false;
    const float phi = 2.f * Pi * u2.y;
    const float l = 2.f * std::sqrt(rMax * rMax - r * r);
    probe->start = po + r * (vx * std::cos(phi) + vy * std::sin(phi)) - 0.5f * l * vz;
    probe->end = probe->start + l * vz;
    return true;
}

float pdfSp(const SeparableBSSRDF& b, const Frame& f, const Vec3& po, const Vec3& pi,
            const Vec3& ni) {
    const Vec3 d = f.toLocal(po - pi), n = f.toLocal(ni);
    const float rProj[3] = {std::sqrt(d.y * d.y + d.z * d.z), std::sqrt(d.z * d.z + d.x * d.x),
                            std::sqrt(d.x * d.x + d.y * d.y)};
    const float axisProb[3] = {0.25f, 0.25f, 0.5f};
    float pdf = 0.f;
    for (int axis = 0; axis < 3; ++axis)
        for (int ch = 0; ch < 3; ++ch)
            pdf += b.pdfSr(ch, rProj[axis]) * std::abs(n[axis]) * axisProb[axis] / 3.f;
    return pdf;
}

}  // namespace rlpbrt
