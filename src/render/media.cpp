#include "render/media.h"

#include <algorithm>

#include "render/bssrdf.h"
#include "render/sampling.h"
#include "render/spectrum.h"
#include "render/transform.h"

namespace rlpbrt {

Vec3 sampleHenyeyGreenstein(const Vec3& wo, float g, Vec2 u, float* pdf) {
    // cosTheta is measured from the forward direction -wo.
    float cosTheta;
    if (std::abs(g) < 1e-3f) {
        cosTheta = 1.f - 2.f * u.x;
    } else {
        float sqrTerm = (1.f - g * g) / (1.f - g + 2.f * g * u.x);
        cosTheta = (1.f + g * g - sqrTerm * sqrTerm) / (2.f * g);
    }
    cosTheta = clamp(cosTheta, -1.f, 1.f);
    float sinTheta = safeSqrt(1.f - cosTheta * cosTheta);
    Frame f = Frame::fromZ(-wo);
    Vec3 wi = f.toWorld(sphericalDirection(sinTheta, cosTheta, 2.f * Pi * u.y));
    *pdf = henyeyGreenstein(-cosTheta, g);
    return wi;
}

Medium::~Medium() = default;

bool Medium::worldBounds(Vec3*, Vec3*) const { return false; }

// ------------------------------------------------------------------------------------------
// Homogeneous.

HomogeneousMedium::HomogeneousMedium(const Spectrum& sigmaA, const Spectrum& sigmaS, float g)
    : sigmaS_(sigmaS), sigmaT_(sigmaA + sigmaS) {
    g_ = g;
}

namespace {
Spectrum expNeg(const Spectrum& sigmaT, float t) {
    t = std::min(t, std::numeric_limits<float>::max());
    return Spectrum(std::exp(-sigmaT.x * t), std::exp(-sigmaT.y * t), std::exp(-sigmaT.z * t));
}
}  // namespace

Spectrum HomogeneousMedium::tr(const Vec3&, const Vec3&, float tMax, Rng&) const {
    return expNeg(sigmaT_, tMax);
}

MediumSample HomogeneousMedium::sample(const Vec3&, const Vec3&, float tMax, Vec2 u,
                                       Rng&) const {
    // pbrt-v3: pick a channel uniformly (u.x), sample exp(-sigma_t[c] t) (u.y), and divide
    // by the average over channels of the per-channel densities (single-sample spectral
    // MIS). Both come from the pixel sampler, stratified like pbrt-v3's two Get1D() calls.
    int channel = std::min(int(u.x * 3.f), 2);
    float dist = -std::log(1.f - u.y) / sigmaT_[channel];
    float t = std::min(dist, tMax);
    MediumSample ms;
    ms.scattered = t < tMax;
    Spectrum T = expNeg(sigmaT_, t);
    Spectrum density = ms.scattered ? sigmaT_ * T : T;
    float pdf = (density.x + density.y + density.z) / 3.f;
    if (pdf == 0.f) pdf = 1.f;
    ms.t = t;
    ms.weight = ms.scattered ? T * sigmaS_ / pdf : T / pdf;
    return ms;
}

// ------------------------------------------------------------------------------------------
// Density media.

DensityMediumBase::DensityMediumBase(const Spectrum& sigmaA, const Spectrum& sigmaS, float g,
                                     const Mat4& worldFromLocal, const Vec3& boxMin,
                                     const Vec3& boxMax)
    : sigmaS_(sigmaS), sigmaT_((sigmaA + sigmaS).x), localFromWorld_(glm::inverse(worldFromLocal)),
      worldFromLocal_(worldFromLocal), boxMin_(boxMin), boxMax_(boxMax) {
    g_ = g;
}

bool DensityMediumBase::worldBounds(Vec3* lo, Vec3* hi) const {
    *lo = Vec3(Infinity);
    *hi = Vec3(-Infinity);
    if (!(sigmaT_ > 0.f) || !(maxComponent(sigmaS_) > 0.f)) return true;
    glm::ivec3 a(res_), b(-1);  // range of cells with a non-zero majorant
    for (int z = 0; z < res_.z; ++z)
        for (int y = 0; y < res_.y; ++y)
            for (int x = 0; x < res_.x; ++x)
                if (majorant(x, y, z) > 0.f) {
                    a = glm::min(a, glm::ivec3(x, y, z));
                    b = glm::max(b, glm::ivec3(x, y, z));
                }
    if (b.x < 0) return true;
    const Vec3 l = boxMin_ + Vec3(a) * cellSize_, h = boxMin_ + Vec3(b + 1) * cellSize_;
    for (int c = 0; c < 8; ++c) {
        Vec3 corner((c & 1) ? h.x : l.x, (c & 2) ? h.y : l.y, (c & 4) ? h.z : l.z);
        Vec3 w = transformPoint(worldFromLocal_, corner);
        *lo = glm::min(*lo, w);
        *hi = glm::max(*hi, w);
    }
    return true;
}

bool DensityMediumBase::clip(const Vec3& o, const Vec3& d, float tMax, Vec3* oL, Vec3* dL,
                             float* t0, float* t1) const {
    *oL = transformPoint(localFromWorld_, o);
    *dL = transformVector(localFromWorld_, d);
    float a = 0.f, b = tMax;
    for (int i = 0; i < 3; ++i) {
        float inv = 1.f / (*dL)[i];
        float tNear = (boxMin_[i] - (*oL)[i]) * inv, tFar = (boxMax_[i] - (*oL)[i]) * inv;
        if (tNear > tFar) std::swap(tNear, tFar);
        // NaN (origin on a slab plane with d parallel to it) keeps the current range.
        tFar *= 1.f + 6e-7f;  // conservative, as pbrt-v3's gamma(3)
        a = tNear > a ? tNear : a;
        b = tFar < b ? tFar : b;
        if (a > b) return false;
    }
    *t0 = a;
    *t1 = b;
    return true;
}

void DensityMediumBase::initMajorants(const glm::ivec3& res) {
    res_ = glm::max(res, glm::ivec3(1));
    cellSize_ = (boxMax_ - boxMin_) / Vec3(res_);
    majorants_.assign(size_t(res_.x) * size_t(res_.y) * size_t(res_.z), 0.f);
    maxDensity_ = 0.f;
}

void DensityMediumBase::addMajorant(const Vec3& lo, const Vec3& hi, float v) {
    if (!(v > 0.f)) return;
    glm::ivec3 a, b;
    for (int i = 0; i < 3; ++i) {
        // Conservative cell range (a little slack for rounding at cell borders).
        float fa = (lo[i] - boxMin_[i]) / cellSize_[i], fb = (hi[i] - boxMin_[i]) / cellSize_[i];
        a[i] = clamp(int(std::floor(fa - 1e-3f)), 0, res_[i] - 1);
        b[i] = clamp(int(std::floor(fb + 1e-3f)), 0, res_[i] - 1);
        if (fb < 0.f || fa > float(res_[i])) return;
    }
    for (int z = a.z; z <= b.z; ++z)
        for (int y = a.y; y <= b.y; ++y)
            for (int x = a.x; x <= b.x; ++x) {
                float& m = majorants_[(size_t(z) * size_t(res_.y) + size_t(y)) * size_t(res_.x) +
                                      size_t(x)];
                m = std::max(m, v);
            }
    maxDensity_ = std::max(maxDensity_, v);
}

void DensityMediumBase::finishMajorants() {
    maxDensity_ = 0.f;
    for (float m : majorants_) maxDensity_ = std::max(maxDensity_, m);
}

GridMedium::GridMedium(const Spectrum& sigmaA, const Spectrum& sigmaS, float g,
                       const Mat4& worldFromLocal, int nx, int ny, int nz,
                       std::vector<float> density)
    : DensityMediumT<GridMedium>(sigmaA, sigmaS, g, worldFromLocal, Vec3(0.f), Vec3(1.f)),
      nx_(nx), ny_(ny), nz_(nz), density_(std::move(density)) {
    // About 4 samples per majorant cell along each axis. Sample (i, j, k) is seen by the
    // trilinear filter within one sample spacing of its position (i + 0.5) / n.
    auto cells = [](int n) { return std::min(64, (n + 3) / 4); };
    initMajorants(glm::ivec3(cells(nx), cells(ny), cells(nz)));
    Vec3 inv(1.f / float(nx), 1.f / float(ny), 1.f / float(nz));
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                Vec3 c = (Vec3(float(i), float(j), float(k)) + 0.5f) * inv;
                addMajorant(c - inv, c + inv, D(i, j, k));
            }
    finishMajorants();
}

// ------------------------------------------------------------------------------------------
// Factory.

std::unique_ptr<Medium> createMedium(const MediumEntity& e, Diagnostics& diag) {
    const ParamList& ps = e.params;
    // pbrt-v3's defaults, or a "preset" from its table of measured media (the subsurface
    // materials' table: sigma_a and the reduced sigma'_s, taken as sigma_s as pbrt-v3 does);
    // an unknown name keeps the defaults with a warning, as pbrt-v3.
    Spectrum sigA(.0011f, .0024f, .014f), sigS(2.55f, 3.21f, 3.77f);
    std::string preset = ps.getString("preset", "");
    if (!preset.empty() && !measuredSubsurface(preset, &sigA, &sigS))
        diag.substituted(ps.find("preset")->loc, "medium preset \"" + preset +
                                                 "\" is not a measured medium pbrt-v3 knows; "
                                                 "using the default sigma_a and sigma_s");
    float scale = ps.getFloat("scale", 1.f);
    float g = ps.getFloat("g", 0.f);
    if (const Param* p = ps.getSpectral("sigma_a")) sigA = spectrumFromParam(*p);
    if (const Param* p = ps.getSpectral("sigma_s")) sigS = spectrumFromParam(*p);
    sigA *= scale;
    sigS *= scale;
    const std::string name = "medium \"" + e.name + "\"";
    if (!(g > -1.f && g < 1.f)) {
        diag.error(ps.find("g")->loc, name + ": g must be in (-1, 1)");
        return nullptr;
    }
    if (!(glm::all(glm::greaterThanEqual(sigA, Vec3(0.f))) &&
          glm::all(glm::greaterThanEqual(sigS, Vec3(0.f))) && isFinite(sigA) && isFinite(sigS))) {
        diag.error(e.loc, name + ": sigma_a and sigma_s must be finite and non-negative");
        return nullptr;
    }
    std::unique_ptr<Medium> m;
    if (e.type == "homogeneous") {
        m = std::make_unique<HomogeneousMedium>(sigA, sigS, g);
    } else if (e.type == "heterogeneous" || e.type == "vdbvolume") {
        Spectrum sigT = sigA + sigS;
        if (sigT.y != sigT.x || sigT.z != sigT.x)
            diag.warning(e.loc, name + ": a density medium needs a spectrally uniform sigma_a + "
                                       "sigma_s; its first channel is used (as pbrt-v3)");
        if (e.type == "vdbvolume") {
            m = createVdbMedium(e, sigA, sigS, g, diag);
            if (!m) return nullptr;
        } else {
            const Param* dp = ps.find("density");
            std::vector<float> density = ps.getFloats("density");
            if (!dp || density.empty()) {
                diag.error(e.loc, name + ": no \"density\" values for a heterogeneous medium");
                return nullptr;
            }
            int nx = ps.getInt("nx", 1), ny = ps.getInt("ny", 1), nz = ps.getInt("nz", 1);
            if (nx < 1 || ny < 1 || nz < 1) {
                diag.error(e.loc, name + ": nx, ny and nz must be positive");
                return nullptr;
            }
            size_t expected = size_t(nx) * size_t(ny) * size_t(nz);
            if (density.size() != expected) {
                diag.error(dp->loc, name + " has " + std::to_string(density.size()) +
                                        " density values; expected nx*ny*nz = " +
                                        std::to_string(expected));
                return nullptr;
            }
            for (float v : density)
                if (!std::isfinite(v)) {
                    diag.error(dp->loc, name + ": density values must be finite");
                    return nullptr;
                }
            Float3 p0 = ps.getPoint3("p0", {0.f, 0.f, 0.f});
            Float3 p1 = ps.getPoint3("p1", {1.f, 1.f, 1.f});
            Vec3 a(p0[0], p0[1], p0[2]), b(p1[0], p1[1], p1[2]);
            if (a.x == b.x || a.y == b.y || a.z == b.z) {
                diag.error(e.loc, name + ": p0 and p1 span an empty box");
                return nullptr;
            }
            Mat4 worldFromLocal = e.worldFromMedium * translateMatrix(a) * scaleMatrix(b - a);
            m = std::make_unique<GridMedium>(sigA, sigS, g, worldFromLocal, nx, ny, nz,
                                             std::move(density));
        }
    } else {
        diag.error(e.loc, "unknown medium type \"" + e.type + "\" for medium \"" + e.name +
                              "\" (expected homogeneous, heterogeneous or vdbvolume)");
        ps.markAllUsed();
        return nullptr;
    }
    ps.getString("type", "");
    ps.reportUnused(name);
    return m;
}

}  // namespace rlpbrt
