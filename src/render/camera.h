// Cameras with pbrt-v3's conventions: raster space is the full film in pixels (x right, y down);
// screen space is the image plane spanned by the screen window (y up); camera space looks down
// +z (left-handed, as pbrt). Rays are returned in world space with unit directions.
#pragma once

#include <memory>
#include <string>

#include "render/film.h"
#include "render/math.h"
#include "render/ray.h"

namespace rlpbrt {

class ParamList;

// A camera ray and its weight (1 for the projective cameras).
struct CameraRay {
    Ray ray;
    float weight = 1.f;
};

// Screen-window rectangle [x0, x1] x [y0, y1] on the image plane.
struct ScreenWindow {
    float x0 = -1.f, x1 = 1.f, y0 = -1.f, y1 = 1.f;
};

class Camera {
public:
    explicit Camera(const Mat4& worldFromCamera);
    virtual ~Camera() = default;
    // Ray through raster position pFilm (pixels of the full image, y down) using lens sample
    // uLens in [0,1)^2; world-space origin and unit direction.
    virtual CameraRay generateRay(Vec2 pFilm, Vec2 uLens) const = 0;
    // pbrt-v3 camera type name.
    virtual const char* name() const = 0;

    const Mat4& worldFromCamera() const { return worldFromCamera_; }
    // Camera-space origin in world space.
    Vec3 position() const { return position_; }
    // World-space unit viewing direction (camera +z).
    Vec3 forward() const { return forward_; }

protected:
    // Camera-space point / direction to world space (directions are normalised).
    Vec3 pointToWorld(const Vec3& p) const;
    Vec3 directionToWorld(const Vec3& d) const;

private:
    Mat4 worldFromCamera_;
    Vec3 position_, forward_;
};

// Shared parts of the perspective and orthographic cameras: the raster -> screen mapping over
// the full resolution and the thin lens.
class ProjectiveCamera : public Camera {
public:
    ProjectiveCamera(const Mat4& worldFromCamera, const ScreenWindow& screen, int xResolution,
                     int yResolution, float lensRadius, float focalDistance);
    // Screen-space position of raster point pFilm.
    Vec2 rasterToScreen(Vec2 pFilm) const;
    const ScreenWindow& screenWindow() const { return screen_; }
    float lensRadius() const { return lensRadius_; }
    float focalDistance() const { return focalDistance_; }

protected:
    // Camera-space thin-lens ray from the pinhole ray (o, d): origin moves to a lens point
    // (relative to `lensCentre`), the ray still passes the pinhole ray's point at depth
    // focalDistance. Returns (o, d) unchanged for lensRadius 0.
    void applyThinLens(Vec2 uLens, const Vec3& lensCentre, Vec3* o, Vec3* d) const;

private:
    ScreenWindow screen_;
    Vec2 resolution_;
    float lensRadius_, focalDistance_;
};

// Pinhole / thin-lens perspective projection; fov spans the shorter screen-window axis.
class PerspectiveCamera : public ProjectiveCamera {
public:
    PerspectiveCamera(const Mat4& worldFromCamera, const ScreenWindow& screen, int xResolution,
                      int yResolution, float lensRadius, float focalDistance, float fovDegrees);
    CameraRay generateRay(Vec2 pFilm, Vec2 uLens) const override;
    const char* name() const override { return "perspective"; }
    float fov() const { return fovDegrees_; }

private:
    float fovDegrees_, tanHalfFov_;
};

// Parallel projection: screen space equals camera-space x, y on the plane z = 0.
class OrthographicCamera : public ProjectiveCamera {
public:
    using ProjectiveCamera::ProjectiveCamera;
    CameraRay generateRay(Vec2 pFilm, Vec2 uLens) const override;
    const char* name() const override { return "orthographic"; }
};

// Creates the Camera `name` ("perspective", "orthographic") from its parameters with
// pbrt-v3's defaults. worldFromCamera is the inverse of the CTM at the Camera directive; the
// film parameters give the full resolution (the crop window does not change the projection).
// Returns null and sets *error for unknown or unsupported types ("realistic", "environment")
// and invalid parameters.
std::unique_ptr<Camera> createCamera(const std::string& name, const ParamList& params,
                                     const Mat4& worldFromCamera, const FilmParams& film,
                                     std::string* error);

}  // namespace rlpbrt
