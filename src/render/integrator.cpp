#include "render/integrator.h"

#include <cstring>

#include "render/sampling.h"

namespace rlpbrt {

Vec3 offsetRayOrigin(const Vec3& p, const Vec3& n) {
    constexpr float kOrigin = 1.f / 32.f, kFloatScale = 1.f / 65536.f, kIntScale = 256.f;
    Vec3 out;
    for (int i = 0; i < 3; ++i) {
        int32_t offset = int32_t(kIntScale * n[i]);
        int32_t bits;
        std::memcpy(&bits, &p[i], sizeof(float));
        bits += (p[i] < 0.f) ? -offset : offset;
        float moved;
        std::memcpy(&moved, &bits, sizeof(float));
        out[i] = std::abs(p[i]) < kOrigin ? p[i] + kFloatScale * n[i] : moved;
    }
    return out;
}

PathIntegrator::PathIntegrator(const Scene& scene)
    : scene_(scene),
      lights_(createLightSampler(scene.integrator.lightSampleStrategy, scene.lights,
                                 scene.boundsMin(), scene.boundsMax(), nullptr)),
      maxDepth_(scene.integrator.maxDepth), rrThreshold_(scene.integrator.rrThreshold) {}

namespace {
// Offsets a ray origin to the side of the surface that direction w leaves on.
Vec3 spawnOrigin(const SurfaceInteraction& si, const Vec3& w) {
    return offsetRayOrigin(si.p, glm::dot(w, si.ng) > 0.f ? si.ng : -si.ng);
}
}  // namespace

Spectrum PathIntegrator::sampleLight(const SurfaceInteraction& si, const BSDF& bsdf,
                                     Sampler& sampler, PathStats& stats) const {
    float uLight = sampler.get1D();
    Vec2 u = sampler.get2D();
    float pmf;
    int li = lights_->sample(si.p, uLight, &pmf);
    if (li < 0 || pmf == 0.f) return Spectrum(0.f);
    const Light& light = *scene_.lights[size_t(li)];
    LightSampleContext ctx{si.p, si.ng};
    LightSample ls;
    if (!light.sampleLi(ctx, u, &ls) || !ls.valid()) return Spectrum(0.f);
    Spectrum f = bsdf.f(si.wo, ls.wi) * std::abs(glm::dot(ls.wi, si.ns));
    if (isBlack(f)) return Spectrum(0.f);
    Vec3 o = spawnOrigin(si, ls.wi);
    float tMax = std::isinf(ls.dist) ? Infinity : ls.dist * (1.f - 1e-4f);
    ++stats.rays;
    if (scene_.occluded(o, ls.wi, tMax)) return Spectrum(0.f);
    if (ls.isDelta) return f * ls.L / (pmf * ls.pdf);
    float lightPdf = pmf * ls.pdf;
    float w = powerHeuristic(1, lightPdf, 1, bsdf.pdf(si.wo, ls.wi));
    return f * ls.L * (w / lightPdf);
}

Spectrum PathIntegrator::Li(const Ray& cameraRay, Sampler& sampler, PathStats& stats) const {
    Spectrum L(0.f), beta(1.f);
    Ray ray = cameraRay;
    bool specularBounce = false;
    float bsdfPdf = 0.f, etaScale = 1.f;
    LightSampleContext prev;
    int passThroughs = 0;
    BSDF bsdf;
    for (int bounces = 0;; ++bounces) {
        SurfaceInteraction si;
        ++stats.rays;
        bool found = scene_.intersect(ray, &si);
        // Emission reached by the previous scattering (or seen by the camera), weighted by
        // MIS against next-event estimation.
        if (!found) {
            for (int idx : scene_.infiniteLights) {
                const Light& light = *scene_.lights[size_t(idx)];
                Spectrum Le = light.Le(ray.d);
                if (isBlack(Le)) continue;
                if (bounces == 0 || specularBounce) {
                    L += beta * Le;
                } else {
                    float lightPdf = lights_->pmf(prev.p, idx) *
                                     light.pdfLi(prev, ray.d, Vec3(0.f), Vec3(0.f));
                    L += beta * Le * powerHeuristic(1, bsdfPdf, 1, lightPdf);
                }
            }
            break;
        }
        if (si.light >= 0) {
            const Light& light = *scene_.lights[size_t(si.light)];
            Spectrum Le = light.L(si.p, si.ng, si.uv, si.wo);
            if (!isBlack(Le)) {
                if (bounces == 0 || specularBounce) {
                    L += beta * Le;
                } else {
                    float lightPdf = lights_->pmf(prev.p, si.light) *
                                     light.pdfLi(prev, ray.d, si.p, si.ng);
                    L += beta * Le * powerHeuristic(1, bsdfPdf, 1, lightPdf);
                }
            }
        }
        if (bounces >= maxDepth_) break;
        // Medium boundaries without a surface: continue the ray unchanged.
        if (si.material < 0) {
            if (++passThroughs > 256) break;
            ray.o = spawnOrigin(si, ray.d);
            --bounces;
            continue;
        }
        ++stats.vertices;
        bsdf.clear();
        scene_.materials[size_t(si.material)]->computeBSDF(si, sampler.get1D(), &bsdf);
        // Next-event estimation at non-specular vertices.
        if (bsdf.numComponents(BxDFFlags::All & ~BxDFFlags::Specular) > 0)
            L += beta * sampleLight(si, bsdf, sampler, stats);
        // Sample the next direction (the guiding seam).
        float uc = sampler.get1D();
        Vec2 u = sampler.get2D();
        BSDFSample bs = bsdf.sampleF(si.wo, uc, u);
        if (!bs.valid() || isBlack(bs.f)) break;
        beta *= bs.f * std::abs(glm::dot(bs.wi, si.ns)) / bs.pdf;
        bsdfPdf = bs.pdf;
        specularBounce = bs.isSpecular();
        if (bs.isSpecular() && bs.isTransmission()) {
            float eta = bsdf.eta();
            etaScale *= glm::dot(si.wo, si.ng) > 0.f ? eta * eta : 1.f / (eta * eta);
        }
        prev = LightSampleContext{si.p, si.ng};
        ray.o = spawnOrigin(si, bs.wi);
        ray.d = bs.wi;
        ray.tMax = Infinity;
        if (!isFinite(beta)) break;
        // Russian roulette (pbrt-v3: after bounce 3, on beta scaled by the refraction eta).
        Spectrum rrBeta = beta * etaScale;
        if (maxComponent(rrBeta) < rrThreshold_ && bounces > 3) {
            float q = std::max(0.05f, 1.f - maxComponent(rrBeta));
            if (sampler.get1D() < q) break;
            beta /= 1.f - q;
        }
    }
    return L;
}

}  // namespace rlpbrt
