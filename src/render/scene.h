// The renderable scene: geometry in Embree (the only place that talks to Embree is
// scene.cpp), materials, lights, camera, film, sampler, and the ray queries the integrator
// uses. Built from a SceneDesc by buildScene().
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "parser/diagnostics.h"
#include "render/camera.h"
#include "render/distribution.h"
#include "render/film.h"
#include "render/interaction.h"
#include "render/light_sampler.h"
#include "render/lights.h"
#include "render/materials.h"
#include "render/ray.h"
#include "render/sampler.h"
#include "render/scene_desc.h"
#include "render/shapes.h"

struct RTCDeviceTy;
struct RTCSceneTy;

namespace rlpbrt {

// One Shape directive's geometry with what it is made of.
struct Primitive {
    ShapeData shape;
    int material = -1;   // -1 = interface only
    int lightBase = -1;  // first light index (meshes: one light per triangle)
    int mediumInside = -1, mediumOutside = -1;  // indices into Scene::media (-1: vacuum)
};

// A set of primitives with their Embree scene: the world, or one object for instancing.
struct PrimitiveGroup {
    std::vector<Primitive> prims;  // indexed by Embree geomID
    RTCSceneTy* rtcScene = nullptr;
};

struct Instance {
    int group = -1;  // index into Scene::groups_
    Mat4 worldFromInstance{1.f}, instanceFromWorld{1.f};
};

struct SceneStats {
    size_t shapes = 0, triangles = 0, quadrics = 0, instances = 0, instancedTriangles = 0;
    size_t curves = 0;  // cubic Bezier segments of curve shapes
    size_t lights = 0, areaLights = 0, materials = 0, textures = 0;
};

// Integrator settings read from the Integrator directive.
struct IntegratorSettings {
    std::string name = "path";
    int maxDepth = 5;
    float rrThreshold = 1.f;
    std::string lightSampleStrategy = "spatial";
};

struct BuildOptions {
    int sppOverride = 0;     // > 0 replaces the sampler's pixelsamples
    uint64_t seed = 0;
    int nThreads = 0;
};

class Medium;
class Scene;
std::unique_ptr<Scene> buildScene(const SceneDesc& desc, const BuildOptions& options,
                                  Diagnostics& diag);

class Scene {
public:
    Scene();
    ~Scene();
    Scene(const Scene&) = delete;
    Scene& operator=(const Scene&) = delete;

    // Closest hit along the ray in (0, ray.tMax). Interface-only surfaces are reported too
    // (material == -1); the integrator continues through them.
    bool intersect(const Ray& ray, SurfaceInteraction* si) const;
    // True if anything blocks the segment from o along d (unit) up to distance tMax.
    bool occluded(const Vec3& o, const Vec3& d, float tMax) const;

    // A point drawn (approximately) uniformly over all surface area, with its unit geometric
    // normal; false if the scene has no surface. Instances count with their own transforms
    // (areas exact for similarity transforms). For placing guiding data, not for estimators.
    bool sampleSurface(const Vec3& u, Vec3* p, Vec3* n) const;
    double totalSurfaceArea() const;

    // The world's primitives, indexed by SurfaceInteraction::primitive (SurfacePatches).
    const std::vector<Primitive>& worldPrimitives() const;

    Vec3 boundsMin() const { return bMin_; }
    Vec3 boundsMax() const { return bMax_; }

    std::vector<std::unique_ptr<Material>> materials;
    std::vector<std::unique_ptr<Light>> lights;
    std::vector<int> infiniteLights;  // indices into lights
    // The lights by emitter (one area-light shape's triangles are one group): the options of
    // the learned light choice (render/light_sampler.h).
    LightGroups lightGroups;
    // Participating media (empty unless the scene has media and its Integrator handles them,
    // as pbrt-v3's volpath does; `path` ignores media as in pbrt-v3). Surfaces whose two
    // media differ are medium boundaries; rays start in cameraMedium.
    std::vector<std::unique_ptr<Medium>> media;
    int cameraMedium = -1;
    bool hasMedia() const { return !media.empty(); }
    // A box bounding where the media can scatter (the scene bounds for media that fill all
    // space); false when nothing scatters.
    bool mediaBounds(Vec3* lo, Vec3* hi) const;
    std::unique_ptr<Camera> camera;
    std::shared_ptr<const Filter> filter;
    FilmParams filmParams;
    std::unique_ptr<Sampler> sampler;
    std::string samplerName;
    IntegratorSettings integrator;
    SceneStats stats;

private:
    friend class SceneAssembler;
    friend std::unique_ptr<Scene> buildScene(const SceneDesc&, const BuildOptions&, Diagnostics&);
    void hitDetails(const Primitive& prim, unsigned primID, float u, float v, const Ray& ray,
                    float t, const Instance* inst, SurfaceInteraction* si) const;

    RTCDeviceTy* device_ = nullptr;
    RTCSceneTy* top_ = nullptr;
    std::vector<PrimitiveGroup> groups_;  // 0 = world; others = objects
    std::vector<Instance> instances_;     // indexed by the instance geomID in the top scene
    // Surface sampling (built on first use): areas of world primitives and instances, and
    // per group the areas of its primitives' triangles/quadrics.
    struct AreaTable {
        Distribution1D prims;                     // over the group's primitives
        std::vector<Distribution1D> triangles;    // per mesh primitive, over its triangles
        double area = 0.0;
    };
    void buildAreaTables() const;
    bool sampleGroup(int group, const Vec3& u, Vec3* p, Vec3* n) const;
    mutable std::once_flag areaOnce_;
    mutable std::vector<AreaTable> groupAreas_;
    mutable Distribution1D topLevel_;  // world group (entry 0) + one entry per instance
    mutable double totalArea_ = 0.0;
    Vec3 bMin_{0.f}, bMax_{0.f};
};

// Makes the render objects from a scene description. Errors are reported with locations;
// returns null if any error occurred.
std::unique_ptr<Scene> buildScene(const SceneDesc& desc, const BuildOptions& options,
                                  Diagnostics& diag);

}  // namespace rlpbrt
