// Tests of the perspective and orthographic cameras: raster conventions, field of view,
// screen window, thin lens, transforms and the factory.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "parser/params.h"
#include "render/camera.h"

namespace rlpbrt {
namespace {

Param floatParam(const std::string& name, std::vector<double> values) {
    Param p;
    p.type = ParamType::Float;
    p.name = name;
    p.numbers = std::move(values);
    return p;
}

FilmParams film(int xres, int yres) {
    FilmParams fp;
    fp.xResolution = xres;
    fp.yResolution = yres;
    return fp;
}

std::unique_ptr<Camera> makeCamera(const std::string& name, const ParamList& ps, int xres,
                                   int yres, const Mat4& worldFromCamera = Mat4(1.f)) {
    std::string err;
    auto cam = createCamera(name, ps, worldFromCamera, film(xres, yres), &err);
    EXPECT_TRUE(cam) << err;
    return cam;
}

std::unique_ptr<Camera> perspective(float fov, int xres, int yres,
                                    const Mat4& worldFromCamera = Mat4(1.f)) {
    ParamList ps;
    ps.add(floatParam("fov", {fov}));
    return makeCamera("perspective", ps, xres, yres, worldFromCamera);
}

Vec3 dir(const Camera& cam, Vec2 pFilm) { return cam.generateRay(pFilm, Vec2(0.5f)).ray.d; }

float angleDeg(Vec3 a, Vec3 b) { return degrees(safeAcos(glm::dot(a, b))); }

TEST(PerspectiveCamera, CentreRayLooksDownZ) {
    auto cam = perspective(90.f, 200, 200);
    CameraRay cr = cam->generateRay(Vec2(100.f, 100.f), Vec2(0.3f, 0.7f));
    EXPECT_EQ(cr.weight, 1.f);
    EXPECT_NEAR(glm::length(cr.ray.o), 0.f, 1e-6f);
    EXPECT_NEAR(cr.ray.d.x, 0.f, 1e-6f);
    EXPECT_NEAR(cr.ray.d.y, 0.f, 1e-6f);
    EXPECT_NEAR(cr.ray.d.z, 1.f, 1e-6f);
    EXPECT_EQ(cam->position(), Vec3(0.f));
    EXPECT_EQ(cam->forward(), Vec3(0.f, 0.f, 1.f));
    EXPECT_STREQ(cam->name(), "perspective");
}

TEST(PerspectiveCamera, RasterYIsDownScreenYIsUp) {
    auto cam = perspective(60.f, 200, 200);
    EXPECT_GT(dir(*cam, Vec2(100.f, 0.f)).y, 0.1f);    // top row looks up
    EXPECT_LT(dir(*cam, Vec2(100.f, 200.f)).y, -0.1f);  // bottom row looks down
    EXPECT_GT(dir(*cam, Vec2(200.f, 100.f)).x, 0.1f);   // right column: +x
    EXPECT_LT(dir(*cam, Vec2(0.f, 100.f)).x, -0.1f);
}

TEST(PerspectiveCamera, FovSpansSquareImage) {
    for (float fov : {30.f, 60.f, 90.f, 120.f}) {
        auto cam = perspective(fov, 200, 200);
        EXPECT_NEAR(angleDeg(dir(*cam, {0.f, 100.f}), dir(*cam, {200.f, 100.f})), fov, 1e-3f);
        EXPECT_NEAR(angleDeg(dir(*cam, {100.f, 0.f}), dir(*cam, {100.f, 200.f})), fov, 1e-3f);
        EXPECT_NEAR(angleDeg(dir(*cam, {100.f, 100.f}), dir(*cam, {200.f, 100.f})), fov / 2,
                    1e-3f);
    }
}

TEST(PerspectiveCamera, FovAppliesToShorterAxis) {
    const float t = std::tan(radians(30.f));  // fov 60
    // Landscape 400 x 200: vertical extent is the fov, horizontal tan doubles.
    auto wide = perspective(60.f, 400, 200);
    EXPECT_NEAR(angleDeg(dir(*wide, {200.f, 0.f}), dir(*wide, {200.f, 200.f})), 60.f, 1e-3f);
    Vec3 right = dir(*wide, {400.f, 100.f});
    EXPECT_NEAR(right.x / right.z, 2 * t, 1e-5f);
    // Portrait 200 x 400: horizontal extent is the fov.
    auto tall = perspective(60.f, 200, 400);
    EXPECT_NEAR(angleDeg(dir(*tall, {0.f, 200.f}), dir(*tall, {200.f, 200.f})), 60.f, 1e-3f);
    Vec3 top = dir(*tall, {100.f, 0.f});
    EXPECT_NEAR(top.y / top.z, 2 * t, 1e-5f);
}

TEST(PerspectiveCamera, FrameAspectRatioScreenWindowAndHalfFov) {
    const float t = std::tan(radians(30.f));
    ParamList frame;
    frame.add(floatParam("fov", {60.0}));
    frame.add(floatParam("frameaspectratio", {1.0}));
    auto a = makeCamera("perspective", frame, 400, 200);
    Vec3 r = dir(*a, {400.f, 100.f});
    EXPECT_NEAR(r.x / r.z, t, 1e-5f);  // screen [-1,1]^2 stretched over 400 pixels

    ParamList sw;
    sw.add(floatParam("screenwindow", {-0.5, 0.5, -0.25, 0.75}));
    auto b = makeCamera("perspective", sw, 100, 100);  // fov 90: tan = 1
    Vec3 corner = dir(*b, {0.f, 0.f});                    // top-left: (x0, y1)
    EXPECT_NEAR(corner.x / corner.z, -0.5f, 1e-5f);
    EXPECT_NEAR(corner.y / corner.z, 0.75f, 1e-5f);
    Vec3 br = dir(*b, {100.f, 100.f});  // bottom-right: (x1, y0)
    EXPECT_NEAR(br.x / br.z, 0.5f, 1e-5f);
    EXPECT_NEAR(br.y / br.z, -0.25f, 1e-5f);

    ParamList half;
    half.add(floatParam("fov", {90.0}));
    half.add(floatParam("halffov", {30.0}));
    auto c = makeCamera("perspective", half, 100, 100);
    EXPECT_NEAR(angleDeg(dir(*c, {0.f, 50.f}), dir(*c, {100.f, 50.f})), 60.f, 1e-3f);
}

TEST(PerspectiveCamera, CropDoesNotChangeProjection) {
    FilmParams fp = film(200, 100);
    fp.cropMin = Vec2(0.2f, 0.1f);
    fp.cropMax = Vec2(0.5f, 0.6f);
    ParamList ps;
    std::string err;
    auto cropped = createCamera("perspective", ps, Mat4(1.f), fp, &err);
    auto full = perspective(90.f, 200, 100);
    ASSERT_TRUE(cropped);
    EXPECT_EQ(dir(*cropped, {37.f, 81.f}), dir(*full, {37.f, 81.f}));
}

TEST(PerspectiveCamera, WorldTransform) {
    // Camera at (1, 2, 3) looking along world -x (camera +z rotated about y by -90 degrees).
    Mat4 m = glm::translate(Mat4(1.f), Vec3(1.f, 2.f, 3.f)) *
             glm::rotate(Mat4(1.f), radians(-90.f), Vec3(0.f, 1.f, 0.f));
    auto cam = perspective(45.f, 64, 64, m);
    EXPECT_NEAR(glm::distance(cam->position(), Vec3(1.f, 2.f, 3.f)), 0.f, 1e-5f);
    EXPECT_NEAR(glm::distance(cam->forward(), Vec3(-1.f, 0.f, 0.f)), 0.f, 1e-5f);
    CameraRay cr = cam->generateRay(Vec2(32.f, 32.f), Vec2(0.5f));
    EXPECT_NEAR(glm::distance(cr.ray.o, cam->position()), 0.f, 1e-5f);
    EXPECT_NEAR(glm::distance(cr.ray.d, cam->forward()), 0.f, 1e-5f);
    CameraRay off = cam->generateRay(Vec2(5.f, 60.f), Vec2(0.5f));
    EXPECT_NEAR(glm::length(off.ray.d), 1.f, 1e-6f);
    // Scale -1 1 1 (handedness flip, as in many pbrt scenes) mirrors the image horizontally.
    auto flipped = perspective(45.f, 64, 64, glm::scale(Mat4(1.f), Vec3(-1.f, 1.f, 1.f)));
    EXPECT_LT(dir(*flipped, {64.f, 32.f}).x, -0.1f);
    EXPECT_NEAR(glm::length(dir(*flipped, {64.f, 32.f})), 1.f, 1e-6f);
}

// Point where the ray crosses the world plane z = zPlane.
Vec3 atDepth(const Ray& r, float zPlane) { return r((zPlane - r.o.z) / r.d.z); }

TEST(PerspectiveCamera, ThinLensRaysMeetOnFocalPlane) {
    ParamList ps;
    ps.add(floatParam("fov", {50.0}));
    ps.add(floatParam("lensradius", {0.2}));
    ps.add(floatParam("focaldistance", {5.0}));
    auto cam = makeCamera("perspective", ps, 120, 80);
    auto pin = perspective(50.f, 120, 80);
    for (Vec2 pFilm : {Vec2(60.f, 40.f), Vec2(3.5f, 70.25f), Vec2(119.f, 1.f)}) {
        Vec3 focus = atDepth(pin->generateRay(pFilm, Vec2(0.5f)).ray, 5.f);
        float maxLensOffset = 0.f;
        for (Vec2 u : {Vec2(0.1f, 0.2f), Vec2(0.9f, 0.5f), Vec2(0.4f, 0.95f), Vec2(0.5f)}) {
            Ray r = cam->generateRay(pFilm, u).ray;
            EXPECT_NEAR(glm::length(r.d), 1.f, 1e-5f);
            EXPECT_EQ(r.o.z, 0.f);
            EXPECT_LE(std::hypot(r.o.x, r.o.y), 0.2f + 1e-6f);
            maxLensOffset = std::max(maxLensOffset, std::hypot(r.o.x, r.o.y));
            EXPECT_NEAR(glm::distance(atDepth(r, 5.f), focus), 0.f, 1e-4f);
        }
        EXPECT_GT(maxLensOffset, 0.05f);  // the lens samples really move the origin
    }
}

TEST(OrthographicCamera, RaysAreParallelAndOriginsFollowScreenWindow) {
    auto cam = makeCamera("orthographic", ParamList(), 200, 100);
    EXPECT_STREQ(cam->name(), "orthographic");
    // Default screen window for aspect 2: [-2, 2] x [-1, 1].
    Ray tl = cam->generateRay(Vec2(0.f, 0.f), Vec2(0.5f)).ray;
    Ray br = cam->generateRay(Vec2(200.f, 100.f), Vec2(0.5f)).ray;
    Ray c = cam->generateRay(Vec2(100.f, 50.f), Vec2(0.5f)).ray;
    EXPECT_NEAR(glm::distance(tl.o, Vec3(-2.f, 1.f, 0.f)), 0.f, 1e-6f);
    EXPECT_NEAR(glm::distance(br.o, Vec3(2.f, -1.f, 0.f)), 0.f, 1e-6f);
    EXPECT_NEAR(glm::distance(c.o, Vec3(0.f)), 0.f, 1e-6f);
    for (const Ray& r : {tl, br, c}) EXPECT_EQ(r.d, Vec3(0.f, 0.f, 1.f));

    ParamList sw;
    sw.add(floatParam("screenwindow", {0.0, 4.0, -1.0, 1.0}));
    Mat4 m = glm::translate(Mat4(1.f), Vec3(0.f, 0.f, -3.f));
    std::string err;
    auto cam2 = createCamera("orthographic", sw, m, film(100, 100), &err);
    ASSERT_TRUE(cam2) << err;
    Ray r = cam2->generateRay(Vec2(25.f, 75.f), Vec2(0.5f)).ray;
    EXPECT_NEAR(glm::distance(r.o, Vec3(1.f, -0.5f, -3.f)), 0.f, 1e-6f);
}

TEST(OrthographicCamera, ThinLensFocusesOnPlane) {
    ParamList ps;
    ps.add(floatParam("lensradius", {0.1}));
    ps.add(floatParam("focaldistance", {2.0}));
    auto cam = makeCamera("orthographic", ps, 100, 100);
    Vec2 pFilm(30.f, 80.f);  // screen (-0.4, -0.6)
    Vec3 focus(-0.4f, -0.6f, 2.f);
    for (Vec2 u : {Vec2(0.1f, 0.2f), Vec2(0.9f, 0.5f), Vec2(0.4f, 0.95f)}) {
        Ray r = cam->generateRay(pFilm, u).ray;
        EXPECT_NEAR(glm::distance(atDepth(r, 2.f), focus), 0.f, 1e-5f);
        EXPECT_GT(glm::distance(Vec2(r.o), Vec2(-0.4f, -0.6f)), 0.01f);
        EXPECT_LE(glm::distance(Vec2(r.o), Vec2(-0.4f, -0.6f)), 0.1f + 1e-6f);
    }
}

TEST(CameraFactory, UnsupportedAndInvalid) {
    std::string err;
    for (const char* name : {"realistic", "environment", "fisheye"}) {
        err.clear();
        EXPECT_FALSE(createCamera(name, ParamList(), Mat4(1.f), film(10, 10), &err));
        EXPECT_NE(err.find(name), std::string::npos) << err;
    }
    ParamList sw;
    sw.add(floatParam("screenwindow", {0.0, 1.0, 0.0}));
    err.clear();
    EXPECT_FALSE(createCamera("perspective", sw, Mat4(1.f), film(10, 10), &err));
    EXPECT_NE(err.find("screenwindow"), std::string::npos);
    ParamList fov;
    fov.add(floatParam("fov", {180.0}));
    err.clear();
    EXPECT_FALSE(createCamera("perspective", fov, Mat4(1.f), film(10, 10), &err));
    EXPECT_FALSE(err.empty());
    // All pbrt-v3 parameters are read (marked used).
    ParamList all;
    for (const char* n : {"fov", "lensradius", "focaldistance", "frameaspectratio",
                          "shutteropen", "shutterclose", "halffov"})
        all.add(floatParam(n, {0.5}));
    all.add(floatParam("screenwindow", {-1, 1, -1, 1}));
    err.clear();
    EXPECT_TRUE(createCamera("perspective", all, Mat4(1.f), film(10, 10), &err)) << err;
    for (const Param& p : all.params()) EXPECT_TRUE(p.used) << p.name;
}

}  // namespace
}  // namespace rlpbrt
