#include "render/camera.h"

#include "parser/params.h"
#include "render/sampling.h"

namespace rlpbrt {

Camera::Camera(const Mat4& worldFromCamera) : worldFromCamera_(worldFromCamera) {
    position_ = pointToWorld(Vec3(0.f));
    forward_ = directionToWorld(Vec3(0.f, 0.f, 1.f));
}

Vec3 Camera::pointToWorld(const Vec3& p) const {
    Vec4 q = worldFromCamera_ * Vec4(p, 1.f);
    return q.w == 1.f ? Vec3(q) : Vec3(q) / q.w;
}

Vec3 Camera::directionToWorld(const Vec3& d) const {
    return glm::normalize(Vec3(worldFromCamera_ * Vec4(d, 0.f)));
}

// ---------------------------------------------------------------------------------------------

ProjectiveCamera::ProjectiveCamera(const Mat4& worldFromCamera, const ScreenWindow& screen,
                                   int xResolution, int yResolution, float lensRadius,
                                   float focalDistance)
    : Camera(worldFromCamera),
      screen_(screen),
      resolution_(float(xResolution), float(yResolution)),
      lensRadius_(lensRadius),
      focalDistance_(focalDistance) {}

Vec2 ProjectiveCamera::rasterToScreen(Vec2 pFilm) const {
    // Raster x grows with screen x; raster y (down) runs from the window's top y1 to y0.
    return Vec2(screen_.x0 + pFilm.x / resolution_.x * (screen_.x1 - screen_.x0),
                screen_.y1 - pFilm.y / resolution_.y * (screen_.y1 - screen_.y0));
}

void ProjectiveCamera::applyThinLens(Vec2 uLens, const Vec3& lensCentre, Vec3* o,
                                     Vec3* d) const {
    if (!(lensRadius_ > 0.f)) return;
    Vec2 pLens = lensRadius_ * sampleUniformDiskConcentric(uLens);
    // Point of the pinhole ray on the plane of focus z = focalDistance.
    float ft = focalDistance_ / d->z;
    Vec3 pFocus = *o + ft * *d;
    *o = Vec3(lensCentre.x + pLens.x, lensCentre.y + pLens.y, 0.f);
    *d = glm::normalize(pFocus - *o);
}

// ---------------------------------------------------------------------------------------------

PerspectiveCamera::PerspectiveCamera(const Mat4& worldFromCamera, const ScreenWindow& screen,
                                     int xResolution, int yResolution, float lensRadius,
                                     float focalDistance, float fovDegrees)
    : ProjectiveCamera(worldFromCamera, screen, xResolution, yResolution, lensRadius,
                       focalDistance),
      fovDegrees_(fovDegrees),
      tanHalfFov_(std::tan(radians(fovDegrees) * 0.5f)) {}

CameraRay PerspectiveCamera::generateRay(Vec2 pFilm, Vec2 uLens) const {
    // Screen coordinates +-1 map to the edges of the field of view on the plane z = 1.
    Vec2 s = rasterToScreen(pFilm);
    Vec3 o(0.f);
    Vec3 d = glm::normalize(Vec3(s.x * tanHalfFov_, s.y * tanHalfFov_, 1.f));
    applyThinLens(uLens, Vec3(0.f), &o, &d);
    CameraRay cr;
    cr.ray = Ray(pointToWorld(o), directionToWorld(d));
    return cr;
}

CameraRay OrthographicCamera::generateRay(Vec2 pFilm, Vec2 uLens) const {
    Vec2 s = rasterToScreen(pFilm);
    Vec3 o(s.x, s.y, 0.f);
    Vec3 d(0.f, 0.f, 1.f);
    // The lens is centred on the ray's own origin (pbrt-v3 centres it on the camera origin).
    applyThinLens(uLens, o, &o, &d);
    CameraRay cr;
    cr.ray = Ray(pointToWorld(o), directionToWorld(d));
    return cr;
}

// ---------------------------------------------------------------------------------------------

namespace {

bool isInvertibleAffine(const Mat4& m) {
    float det = glm::determinant(m);
    return std::isfinite(det) && det != 0.f;
}

}  // namespace

std::unique_ptr<Camera> createCamera(const std::string& name, const ParamList& params,
                                     const Mat4& worldFromCamera, const FilmParams& film,
                                     std::string* error) {
    auto fail = [&](const std::string& msg) -> std::unique_ptr<Camera> {
        if (error) *error = msg;
        return nullptr;
    };
    if (name == "realistic" || name == "environment")
        return fail("camera \"" + name + "\" is not supported (use perspective or orthographic)");
    if (name != "perspective" && name != "orthographic")
        return fail("unknown camera \"" + name + "\"");
    if (!isInvertibleAffine(worldFromCamera))
        return fail("camera transform is singular");
    if (film.xResolution <= 0 || film.yResolution <= 0)
        return fail("camera: film resolution must be positive");

    // Motion blur is not supported: the shutter interval is read and ignored.
    params.getFloat("shutteropen", 0.f);
    params.getFloat("shutterclose", 1.f);
    float lensRadius = params.getFloat("lensradius", 0.f);
    float focalDistance = params.getFloat("focaldistance", 1e30f);
    if (lensRadius < 0.f) return fail("camera \"lensradius\" must not be negative");
    if (lensRadius > 0.f && !(focalDistance > 0.f))
        return fail("camera \"focaldistance\" must be positive");

    // Default screen window: [-1, 1] along the shorter image axis.
    float frame = params.getFloat("frameaspectratio",
                                  float(film.xResolution) / float(film.yResolution));
    if (!(frame > 0.f)) return fail("camera \"frameaspectratio\" must be positive");
    ScreenWindow screen;
    if (frame > 1.f) {
        screen = ScreenWindow{-frame, frame, -1.f, 1.f};
    } else {
        screen = ScreenWindow{-1.f, 1.f, -1.f / frame, 1.f / frame};
    }
    if (params.has("screenwindow")) {
        std::vector<float> sw = params.getFloats("screenwindow");
        if (sw.size() != 4) return fail("camera \"screenwindow\" should have four values");
        screen = ScreenWindow{sw[0], sw[1], sw[2], sw[3]};
        if (sw[0] == sw[1] || sw[2] == sw[3])
            return fail("camera \"screenwindow\" has zero area");
    }

    if (name == "orthographic") {
        return std::make_unique<OrthographicCamera>(worldFromCamera, screen, film.xResolution,
                                                    film.yResolution, lensRadius,
                                                    focalDistance);
    }
    float fov = params.getFloat("fov", 90.f);
    float halffov = params.getFloat("halffov", -1.f);
    if (halffov > 0.f) fov = 2.f * halffov;  // pbrt-v3: half of the full fov (structure synth)
    if (!(fov > 0.f && fov < 180.f)) return fail("camera \"fov\" must be in (0, 180) degrees");
    return std::make_unique<PerspectiveCamera>(worldFromCamera, screen, film.xResolution,
                                               film.yResolution, lensRadius, focalDistance, fov);
}

}  // namespace rlpbrt
