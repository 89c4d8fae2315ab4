// Participating media with pbrt-v3's semantics: the Henyey-Greenstein phase function,
// `homogeneous` (closed-form free flights and transmittance, one RGB channel chosen per
// flight with the single-sample spectral MIS pdf of pbrt-v3), `heterogeneous` (pbrt-v3's
// inline density grid: delta tracking for free flights, ratio tracking for transmittance,
// against per-cell majorants), and rlpbrt's `vdbvolume` (the same trackers over an OpenVDB grid,
// media_vdb.cpp). createMedium holds the family's only name switch.
//
// All distances are along unit world-space directions. The integrator keeps one Rng per
// path for the tracking decisions (their number varies from path to path, so they do not
// come from the pixel sampler's dimensions).
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "parser/diagnostics.h"
#include "render/math.h"
#include "render/scene_desc.h"

namespace rlpbrt {

// PCG32 (O'Neill): a small, fast generator for tracking decisions.
class Rng {
public:
    Rng() = default;
    explicit Rng(uint64_t seed, uint64_t stream = 1) { setSeed(seed, stream); }
    void setSeed(uint64_t seed, uint64_t stream = 1) {
        state_ = 0u;
        inc_ = (stream << 1u) | 1u;
        next();
        state_ += seed;
        next();
    }
    uint32_t next() {
        uint64_t old = state_;
        state_ = old * 0x5851f42d4c957f2dULL + inc_;
        uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = uint32_t(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
    }
    // Uniform in [0, 1).
    float uniform() { return float(next() >> 8) * 0x1p-24f; }

private:
    uint64_t state_ = 0x853c49e6748fea9bULL, inc_ = 0xda3e39cb94b95bdbULL;
};

// pbrt-v3's Henyey-Greenstein phase function. Both directions point away from the
// scattering point, so cosTheta = dot(wo, wi) is -1 for forward scattering; g > 0 scatters
// forward (pbrt-v3's PhaseHG(Dot(wo, wi), g)).
inline float henyeyGreenstein(float cosTheta, float g) {
    float denom = 1.f + g * g + 2.f * g * cosTheta;
    return Inv4Pi * (1.f - g * g) / (denom * std::sqrt(std::max(denom, 1e-12f)));
}
// Samples wi with density henyeyGreenstein(dot(wo, wi), g) (solid angle); returns wi and
// sets *pdf (equal to the phase value, so the sample weight p / pdf is 1).
Vec3 sampleHenyeyGreenstein(const Vec3& wo, float g, Vec2 u, float* pdf);

// The outcome of sampling a free flight along a ray segment.
struct MediumSample {
    Spectrum weight{1.f};    // factor for the path throughput
    float t = 0.f;           // distance of the scattering event (when scattered)
    bool scattered = false;  // a real collision before the segment's end
};

class Medium {
public:
    virtual ~Medium();
    // Free flight along o + t d (d unit), t in (0, tMax]: a scattering event or passage.
    // u: two of the pixel sampler's dimensions, used by media whose flights take a fixed
    // number of decisions (homogeneous: the channel, then the distance, as pbrt-v3's
    // HomogeneousMedium::Sample draws two 1D samples); tracking media use rng.
    virtual MediumSample sample(const Vec3& o, const Vec3& d, float tMax, Vec2 u,
                                Rng& rng) const = 0;
    // Unbiased estimate of the transmittance of the segment o + t d, t in (0, tMax].
    virtual Spectrum tr(const Vec3& o, const Vec3& d, float tMax, Rng& rng) const = 0;
    float g() const { return g_; }
    // A world-space box outside which the medium cannot scatter (*lo > *hi when it never
    // does); false when it fills all space (homogeneous media).
    virtual bool worldBounds(Vec3* lo, Vec3* hi) const;

protected:
    float g_ = 0.f;
};

class HomogeneousMedium final : public Medium {
public:
    HomogeneousMedium(const Spectrum& sigmaA, const Spectrum& sigmaS, float g);
    MediumSample sample(const Vec3& o, const Vec3& d, float tMax, Vec2 u,
                        Rng& rng) const override;
    Spectrum tr(const Vec3& o, const Vec3& d, float tMax, Rng& rng) const override;

private:
    Spectrum sigmaS_, sigmaT_;
};

// A medium whose extinction is sigma_t * density(p) inside a box of its local space (zero
// outside). Free flights and transmittance are tracked cell by cell through a coarse grid
// of majorants over the box (3D DDA): each cell bounds the density anywhere in it, so
// empty and thin regions cost few null collisions. Subclasses supply the density through
// DensityMediumT (static dispatch: the trackers are the hot loop): Derived::densityLookup()
// returns a callable float(const Vec3& pLocal), made once per tracking call.
class DensityMediumBase : public Medium {
public:
    // sigma_t must be spectrally uniform (pbrt-v3 uses its first channel, as here).
    DensityMediumBase(const Spectrum& sigmaA, const Spectrum& sigmaS, float g,
                      const Mat4& worldFromLocal, const Vec3& boxMin, const Vec3& boxMax);
    float maxDensity() const { return maxDensity_; }
    // The world box of the majorant cells with a non-zero bound.
    bool worldBounds(Vec3* lo, Vec3* hi) const override;
    float sigmaT() const { return sigmaT_; }
    // The majorant grid: resolution and the bound of one cell.
    glm::ivec3 majorantResolution() const { return res_; }
    float majorant(int x, int y, int z) const {
        return majorants_[(size_t(z) * size_t(res_.y) + size_t(y)) * size_t(res_.x) + size_t(x)];
    }

protected:
    // The parametric range [*t0, *t1] of o + t d (world) inside the box, clipped to
    // [0, tMax]; also returns the local-space ray. False when the ray misses it.
    bool clip(const Vec3& o, const Vec3& d, float tMax, Vec3* oL, Vec3* dL, float* t0,
              float* t1) const;
    // Majorant grid set-up: a resolution, then every density value v that can be seen in
    // the local box [lo, hi] (its filter support), then finish().
    void initMajorants(const glm::ivec3& res);
    void addMajorant(const Vec3& lo, const Vec3& hi, float v);
    void finishMajorants();
    // Calls f(tA, tB, majorant density) for the cells along oL + t dL, t in [t0, t1], in
    // order, until f returns false.
    template <typename F>
    void traverse(const Vec3& oL, const Vec3& dL, float t0, float t1, F&& f) const;

    Spectrum sigmaS_;
    float sigmaT_ = 0.f;
    Mat4 localFromWorld_{1.f}, worldFromLocal_{1.f};
    Vec3 boxMin_{0.f}, boxMax_{1.f};
    float maxDensity_ = 0.f;
    glm::ivec3 res_{1, 1, 1};
    Vec3 cellSize_{1.f};
    std::vector<float> majorants_{0.f};
};

template <typename F>
void DensityMediumBase::traverse(const Vec3& oL, const Vec3& dL, float t0, float t1,
                                 F&& f) const {
    Vec3 p = oL + t0 * dL;
    glm::ivec3 cell, step;
    Vec3 tNext, tDelta;
    for (int a = 0; a < 3; ++a) {
        int c = int(std::floor((p[a] - boxMin_[a]) / cellSize_[a]));
        cell[a] = clamp(c, 0, res_[a] - 1);
        if (dL[a] == 0.f) {
            step[a] = 0;
            tNext[a] = Infinity;
            tDelta[a] = Infinity;
        } else {
            step[a] = dL[a] > 0.f ? 1 : -1;
            float edge = boxMin_[a] + float(cell[a] + (dL[a] > 0.f ? 1 : 0)) * cellSize_[a];
            tNext[a] = (edge - oL[a]) / dL[a];
            tDelta[a] = cellSize_[a] / std::abs(dL[a]);
        }
    }
    float t = t0;
    for (;;) {
        int a = tNext.x < tNext.y ? (tNext.x < tNext.z ? 0 : 2) : (tNext.y < tNext.z ? 1 : 2);
        float tEnd = std::min(tNext[a], t1);
        if (tEnd > t && !f(t, tEnd, majorant(cell.x, cell.y, cell.z))) return;
        t = std::max(t, tEnd);
        if (tEnd >= t1) return;
        cell[a] += step[a];
        if (cell[a] < 0 || cell[a] >= res_[a]) return;
        tNext[a] += tDelta[a];
    }
}

template <typename Derived>
class DensityMediumT : public DensityMediumBase {
public:
    using DensityMediumBase::DensityMediumBase;

    // Delta tracking (pbrt-v3 GridDensityMedium::Sample, with a majorant per cell).
    MediumSample sample(const Vec3& o, const Vec3& d, float tMax, Vec2,
                        Rng& rng) const override {
        MediumSample ms;
        Vec3 oL, dL;
        float t0, t1;
        if (maxDensity_ <= 0.f || sigmaT_ <= 0.f || !clip(o, d, tMax, &oL, &dL, &t0, &t1))
            return ms;
        auto density = static_cast<const Derived&>(*this).densityLookup();
        traverse(oL, dL, t0, t1, [&](float tA, float tB, float maj) {
            if (maj <= 0.f) return true;
            const float invMajorant = 1.f / (sigmaT_ * maj), invMax = 1.f / maj;
            for (float t = tA;;) {
                t -= std::log(1.f - rng.uniform()) * invMajorant;
                if (t >= tB) return true;
                if (density(oL + t * dL) * invMax > rng.uniform()) {
                    ms.scattered = true;
                    ms.t = t;
                    ms.weight = sigmaS_ / sigmaT_;
                    return false;
                }
            }
        });
        return ms;
    }
    // Ratio tracking with pbrt-v3's Russian roulette below 0.1.
    Spectrum tr(const Vec3& o, const Vec3& d, float tMax, Rng& rng) const override {
        Vec3 oL, dL;
        float t0, t1;
        if (maxDensity_ <= 0.f || sigmaT_ <= 0.f || !clip(o, d, tMax, &oL, &dL, &t0, &t1))
            return Spectrum(1.f);
        auto density = static_cast<const Derived&>(*this).densityLookup();
        float T = 1.f;
        traverse(oL, dL, t0, t1, [&](float tA, float tB, float maj) {
            if (maj <= 0.f) return true;
            const float invMajorant = 1.f / (sigmaT_ * maj), invMax = 1.f / maj;
            for (float t = tA;;) {
                t -= std::log(1.f - rng.uniform()) * invMajorant;
                if (t >= tB) return true;
                T *= 1.f - std::max(0.f, density(oL + t * dL) * invMax);
                if (T < 0.1f) {
                    float q = std::max(0.05f, 1.f - T);
                    if (rng.uniform() < q) {
                        T = 0.f;
                        return false;
                    }
                    T /= 1.f - q;
                }
            }
        });
        return Spectrum(T);
    }
};

// pbrt-v3's `heterogeneous` medium: nx*ny*nz densities (x fastest) sampled at the cell
// centres (i + 0.5) / n of [0,1]^3, trilinear in between, zero beyond the outer samples
// (samples outside the grid read as 0). Local space [0,1]^3 maps to the world through
// CTM * Translate(p0) * Scale(p1 - p0).
class GridMedium final : public DensityMediumT<GridMedium> {
public:
    GridMedium(const Spectrum& sigmaA, const Spectrum& sigmaS, float g, const Mat4& worldFromLocal,
               int nx, int ny, int nz, std::vector<float> density);
    struct Lookup {
        const GridMedium* m;
        float operator()(const Vec3& p) const { return m->density(p); }
    };
    Lookup densityLookup() const { return Lookup{this}; }
    float density(const Vec3& p) const {
        float x = p.x * float(nx_) - .5f, y = p.y * float(ny_) - .5f, z = p.z * float(nz_) - .5f;
        float fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
        int ix = int(fx), iy = int(fy), iz = int(fz);
        float dx = x - fx, dy = y - fy, dz = z - fz;
        float d00 = lerp(dx, D(ix, iy, iz), D(ix + 1, iy, iz));
        float d10 = lerp(dx, D(ix, iy + 1, iz), D(ix + 1, iy + 1, iz));
        float d01 = lerp(dx, D(ix, iy, iz + 1), D(ix + 1, iy, iz + 1));
        float d11 = lerp(dx, D(ix, iy + 1, iz + 1), D(ix + 1, iy + 1, iz + 1));
        return lerp(dz, lerp(dy, d00, d10), lerp(dy, d01, d11));
    }
    // The grid sample (ix, iy, iz); 0 outside the grid.
    float D(int ix, int iy, int iz) const {
        if (unsigned(ix) >= unsigned(nx_) || unsigned(iy) >= unsigned(ny_) ||
            unsigned(iz) >= unsigned(nz_))
            return 0.f;
        return density_[(size_t(iz) * size_t(ny_) + size_t(iy)) * size_t(nx_) + size_t(ix)];
    }

private:
    int nx_, ny_, nz_;
    std::vector<float> density_;
};

// Creates a MakeNamedMedium's medium (pbrt-v3 parameters: sigma_a, sigma_s, scale, g,
// preset; heterogeneous: nx ny nz density p0 p1; vdbvolume: filename, grid). Errors and
// warnings at the entity's parameters; null on error.
std::unique_ptr<Medium> createMedium(const MediumEntity& e, Diagnostics& diag);

// media_vdb.cpp: the `vdbvolume` medium (density from a float grid of an OpenVDB file).
std::unique_ptr<Medium> createVdbMedium(const MediumEntity& e, const Spectrum& sigmaA,
                                        const Spectrum& sigmaS, float g, Diagnostics& diag);

}  // namespace rlpbrt
