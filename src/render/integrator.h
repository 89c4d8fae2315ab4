// The one path-tracing integrator (pbrt-v3 `path` semantics: maxdepth, Russian roulette after
// bounce 3, next-event estimation with power-heuristic MIS). The direction-sampling step is a
// seam (sampleDirection / directionPdf) where a guiding backend plugs in later.
#pragma once

#include <cstdint>
#include <memory>

#include "render/light_sampler.h"
#include "render/ray.h"
#include "render/scene.h"

namespace rlpbrt {

// Per-thread counters, summed after rendering.
struct PathStats {
    uint64_t paths = 0;
    uint64_t rays = 0;               // closest-hit and shadow rays
    uint64_t vertices = 0;           // surface scattering vertices (path length sum)
    uint64_t zeroRadiancePaths = 0;  // camera paths that carried no light
    uint64_t nonFinite = 0;          // samples dropped because they were NaN/Inf
    void add(const PathStats& o) {
        paths += o.paths;
        rays += o.rays;
        vertices += o.vertices;
        zeroRadiancePaths += o.zeroRadiancePaths;
        nonFinite += o.nonFinite;
    }
};

class PathIntegrator {
public:
    explicit PathIntegrator(const Scene& scene);
    // Radiance arriving along a camera ray; consumes dimensions of `sampler`.
    Spectrum Li(const Ray& ray, Sampler& sampler, PathStats& stats) const;

private:
    Spectrum sampleLight(const SurfaceInteraction& si, const BSDF& bsdf, Sampler& sampler,
                         PathStats& stats) const;

    const Scene& scene_;
    std::unique_ptr<LightSampler> lights_;
    int maxDepth_;
    float rrThreshold_;
};

// Moves p off a surface with unit normal n (oriented towards the side the ray leaves on),
// by a few float ULPs: robust at any scene scale (Wachter and Binder 2019).
Vec3 offsetRayOrigin(const Vec3& p, const Vec3& n);

}  // namespace rlpbrt
