// Light sources with pbrt-v3's semantics: point, spot, goniometric, projection, distant,
// infinite (constant or environment map, importance sampled) and diffuse area lights on
// triangles and quadrics. One factory (createLight / createAreaLights) holds the family's
// only name switch.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "parser/diagnostics.h"
#include "parser/params.h"
#include "render/math.h"
#include "render/shapes.h"

namespace rlpbrt {

// The receiving point of a light query. n is the unit geometric normal at a surface point,
// or zero for a point in a medium.
struct LightSampleContext {
    Vec3 p{0.f};
    Vec3 n{0.f};
};

struct LightSample {
    Spectrum L{0.f};   // incident radiance (delta lights: intensity / distance^2, etc.)
    Vec3 wi{0.f};      // unit direction from the receiving point towards the light
    float pdf = 0.f;   // solid-angle density of wi (delta lights: 1, with isDelta set)
    float dist = 0.f;  // distance to the sampled light point (Infinity for distant/infinite)
    bool isDelta = false;
    bool valid() const { return pdf > 0.f && !isBlack(L); }
};

enum class LightKind { DeltaPosition, DeltaDirection, Area, Infinite };

class Light {
public:
    virtual ~Light();
    virtual LightKind kind() const = 0;
    bool isDelta() const {
        return kind() == LightKind::DeltaPosition || kind() == LightKind::DeltaDirection;
    }
    // Samples an incident direction at ctx. False when the light cannot reach ctx.p.
    virtual bool sampleLi(const LightSampleContext& ctx, Vec2 u, LightSample* s) const = 0;
    // Solid-angle pdf with which sampleLi would choose wi at ctx, given that the ray along wi
    // hits this light at pLight with unit geometric normal nLight (area lights) or escapes
    // (infinite lights: pLight/nLight unused). Zero for delta lights.
    virtual float pdfLi(const LightSampleContext& ctx, const Vec3& wi, const Vec3& pLight,
                        const Vec3& nLight) const = 0;
    // Area lights: radiance leaving the light's surface point (unit normal n, surface uv)
    // in direction w (unit, pointing away from the surface).
    virtual Spectrum L(const Vec3& p, const Vec3& n, const Vec2& uv, const Vec3& w) const;
    // Infinite lights: radiance arriving along a ray that escapes the scene in direction
    // `dir` (unit, pointing away from the scene).
    virtual Spectrum Le(const Vec3& dir) const;
    // Total emitted power (W, RGB), for power-proportional light selection.
    virtual Spectrum power() const = 0;
    // A cheap, deterministic estimate of the light's unshadowed contribution at p (luminance
    // of radiance times subtended solid angle), used to build spatial light-selection
    // distributions; negative = not available (the caller estimates with sampleLi).
    virtual float approxContribution(const Vec3& p) const { return -1.f; }
    // Called once the scene bounds are known (distant and infinite lights need them).
    virtual void preprocess(const Vec3& sceneCenter, float sceneRadius) {}
};

// Creates a LightSource. Unknown types are errors; reports at e.loc. Null on error.
std::unique_ptr<Light> createLight(const std::string& type, const ParamList& params,
                                   const Mat4& worldFromLight, const FileLoc& loc,
                                   Diagnostics& diag);

// Creates the diffuse area lights of an AreaLightSource bound to a shape: one per triangle of
// a mesh (as pbrt-v3), one for a quadric. `mesh`/`quadric` must outlive the lights.
bool createAreaLights(const std::string& type, const ParamList& params, const ShapeData& shape,
                      const FileLoc& loc, Diagnostics& diag,
                      std::vector<std::unique_ptr<Light>>* out);

}  // namespace rlpbrt
