#include "render/path_recorder.h"

#include <algorithm>
#include <cmath>

#include "render/bxdfs.h"
#include "render/integrator.h"

namespace rlpbrt {

PathRecorder::PathRecorder(const GuideSettings& guide, int slot)
    : learn_(guide.field && guide.learn && guide.field->active()),
      learnSelection_(learn_ && guide.learnMix),
      // Training targets of surface vertices: the path's returns, or Eq. 1 bootstrapped at
      // the next vertex (pending). Medium vertices always bootstrap: in a lossless medium the
      // noisy returns made a pure policy's phase / pdf weights heavy-tailed over the many
      // vertices of a thick medium (vdb, mix 1: mean 0.53 +- 0.04 of an exact 1 at 64 spp).
      bootstrap_(learn_ && !guide.pathTarget), returns_(learn_ && guide.pathTarget),
      sampledTarget_(guide.sampledTarget) {
    if (learn_) slot_ = guide.field->slot(slot);
    spots_ = returns_ && guide.field->learnsSpots();
}

void PathRecorder::mediumScattered(const guiding::VertexGuide& guide, const DirectionSample& ds) {
    if (!learn_) return;
    spotPending_ = false;  // the last return vertex's direction ended in the medium
    // Eq. 1 for the previous vertex, with the one-sample estimate of the light scattered
    // here: Q(p, w') phase(w') / pdf(w').
    if (pending_.active() && guide.valid() && ds.pdf > 0.f) {
        const float est = guide.radiance(ds.wi, ds.bin) * ds.f.x / ds.pdf;
        flush(std::isfinite(est) ? est : 0.f);
    }
    pending_ = PendingRecord();
    if (guide.valid() && ds.pdf > 0.f) {
        pending_.guide = guide;
        pending_.w = ds.wi;
        pending_.bin = ds.bin;
    }
}

bool PathRecorder::completePending(const SurfaceInteraction& si, const BSDF& bsdf,
                                   const guiding::VertexGuide& guide, bool canGuide, int lobes,
                                   float emitted, bool lastVertex) {
    // Eq. 1 target for the previous guided vertex: Le(y) + the learned light scattered at y,
    // carried unchanged through delta vertices.
    const float scattered = guide.valid() ? scatteredTarget(si, bsdf, guide, si.wo) : 0.f;
    if (guide.valid() && scattered < 0.f && !lastVertex)
        return true;  // completed by surfaceSampled with the direction sampled at y
    if (guide.valid())
        flush(emitted + std::max(scattered, 0.f));
    else if (canGuide || lobes == 0)
        pending_ = PendingRecord();  // no data at y: nothing to learn from
    else
        pending_.target += pending_.weight * emitted;  // delta y: continue the chain
    return false;
}

void PathRecorder::completeDeferred(const SurfaceInteraction& si,
                                    const guiding::VertexGuide& guide, const DirectionSample& ds,
                                    float emitted) {
    // One-sample estimate of the Eq. 1 sum: Q(y, w') f(w') cos / pdf(w').
    float est = 0.f;
    if (ds.pdf > 0.f && !ds.transmission)
        est = guide.radiance(ds.wi, ds.bin) * luminance(ds.f) *
              std::abs(glm::dot(ds.wi, si.ns)) / ds.pdf;
    flush(emitted + (std::isfinite(est) ? est : 0.f));
}

float PathRecorder::scatteredTarget(const SurfaceInteraction& si, const BSDF& bsdf,
                                    const guiding::VertexGuide& guide, const Vec3& woY) const {
    Vec3 n = glm::dot(si.ns, woY) >= 0.f ? si.ns : -si.ns;
    // Lambertian y: the sum is rho/pi times the learned irradiance (no BSDF evaluations).
    Spectrum albedo(0.f);
    bool lambertian = true;
    for (int i = 0; i < bsdf.numComponents() && lambertian; ++i) {
        if (const auto* l = bsdf.component(i).get<LambertianReflection>()) albedo += l->r;
        else lambertian = false;
    }
    if (lambertian) return luminance(albedo) * InvPi * guide.irradianceEstimate(n);
    if (sampledTarget_) return -1.f;  // estimated with the direction sampled at y
    struct Ctx {
        const BSDF& bsdf;
        Vec3 wo, n;
    } ctx{bsdf, woY, n};
    const Ctx* c = &ctx;  // one captured pointer: no allocation in std::function
    return guide.scatteredEstimate([c](const glm::vec3& wj) {
        float cosj = glm::dot(wj, c->n);
        return cosj > 0.f ? luminance(c->bsdf.f(c->wo, wj)) * cosj : 0.f;
    });
}

void PathRecorder::spotReached(const Vec3& p, const Spectrum& L) {
    spotPending_ = false;
    const ReturnVertex& v = ret_.v[numRet_ - 1];
    const Spectrum d = L - v.L;
    Spectrum li(0.f);
    for (int c = 0; c < 3; ++c) li[c] = v.beta[c] > 0.f ? d[c] / v.beta[c] : 0.f;
    const float light = luminance(li);
    if (light > 0.f && std::isfinite(light)) slot_.recordSpot(v.guide, v.w, p, light, v.bin);
}

void PathRecorder::recordReturns(const Spectrum& L, int base) {
    for (int i = std::max(base, 0); i < numRet_; ++i) {
        const ReturnVertex& v = ret_.v[i];
        const Spectrum d = L - v.L;
        Spectrum li(0.f);
        for (int c = 0; c < 3; ++c) li[c] = v.beta[c] > 0.f ? d[c] / v.beta[c] : 0.f;
        slot_.record(v.guide, v.w, std::max(luminance(li), 0.f), v.bin);
    }
    numRet_ = std::min(numRet_, std::max(base, 0));
}

void PathRecorder::finish(const Spectrum& L) {
    recordReturns(L, 0);
    if (numSel_ > 0) {
        const float lumL = luminance(L);
        for (int i = 0; i < numSel_; ++i) {
            SelectionVertex& v = sel_.v[i];
            v.s.integrand = (lumL - v.lumL) / v.lumBeta * v.s.pdf;
            slot_.recordSelection(v.guide, v.s);
        }
    }
}

}  // namespace rlpbrt
