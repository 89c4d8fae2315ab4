// Tests of the light sources: pbrt-v3 parameter semantics, delta-light values (inverse
// square law, spot falloff, goniometric/projection map lookups), pdf consistency between
// sampleLi and pdfLi, Monte Carlo irradiance from area lights against analytic values, and
// environment-map importance sampling (normalisation, chi-square, integral of Le).
#include "render/lights.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "chi2.h"
#include "render/quadrics.h"
#include "render/sampling.h"
#include "render/transform.h"

namespace rlpbrt {
namespace {

// ---------------------------------------------------------------------------------------
// Helpers

Param numParam(ParamType type, const std::string& name, std::vector<double> v) {
    Param p;
    p.type = type;
    p.name = name;
    p.numbers = std::move(v);
    return p;
}
Param rgbParam(const std::string& name, float r, float g, float b) {
    return numParam(ParamType::RGB, name, {r, g, b});
}
Param floatParam(const std::string& name, float v) {
    return numParam(ParamType::Float, name, {v});
}
Param pointParam(const std::string& name, Vec3 v) {
    return numParam(ParamType::Point3, name, {v.x, v.y, v.z});
}
Param stringParam(const std::string& name, const std::string& s) {
    Param p;
    p.type = ParamType::String;
    p.name = name;
    p.strings = {s};
    return p;
}
Param boolParam(const std::string& name, bool b) {
    Param p;
    p.type = ParamType::Bool;
    p.name = name;
    p.bools = {uint8_t(b)};
    return p;
}

struct Fixture {
    Diagnostics diag;
    Fixture() { diag.setStream(nullptr); }
    ParamList params(std::vector<Param> ps) {
        ParamList l(&diag);
        for (auto& p : ps) l.add(std::move(p));
        return l;
    }
    std::unique_ptr<Light> make(const std::string& type, std::vector<Param> ps,
                                const Mat4& worldFromLight = Mat4(1.f)) {
        ParamList l = params(std::move(ps));
        return createLight(type, l, worldFromLight, FileLoc(), diag);
    }
};

struct Rng {
    std::mt19937_64 gen;
    explicit Rng(uint64_t seed) : gen(seed) {}
    float uniform() { return float(gen() >> 40) * 0x1p-24f; }
    Vec2 uniform2() { return Vec2(uniform(), uniform()); }
};

// Mean and standard error of a Monte Carlo estimator.
struct Estimate {
    double mean = 0, stdErr = 0;
};
template <typename F>
Estimate monteCarlo(int n, F&& f) {
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        double v = f(i);
        sum += v;
        sum2 += v * v;
    }
    Estimate e;
    e.mean = sum / n;
    double var = std::max(0.0, sum2 / n - e.mean * e.mean);
    e.stdErr = std::sqrt(var / n);
    return e;
}

// Writes a float RGB EXR with OpenImageIO (rows top to bottom); returns its path.
std::string writeExr(const std::string& name, int w, int h, const std::vector<float>& rgb) {
    std::string path = ::testing::TempDir() + "rlpbrt_lights_test_" + std::to_string(getpid()) +
                       "_" + name + ".exr";
    auto out = OIIO::ImageOutput::create(path);
    EXPECT_TRUE(out != nullptr);
    if (!out) return path;
    OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
    EXPECT_TRUE(out->open(path, spec));
    EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
    out->close();
    return path;
}

// Irradiance at x (unit normal n) from a uniform one-sided polygon of radiance 1 facing x:
// Lambert's formula E = |1/2 sum_i theta_i (gamma_i . n)|.
double polygonIrradiance(const std::vector<Vec3>& poly, const Vec3& x, const Vec3& n) {
    double sum = 0;
    for (size_t i = 0; i < poly.size(); ++i) {
        glm::dvec3 a = glm::normalize(glm::dvec3(poly[i] - x));
        glm::dvec3 b = glm::normalize(glm::dvec3(poly[(i + 1) % poly.size()] - x));
        double theta = std::acos(clamp(glm::dot(a, b), -1.0, 1.0));
        sum += theta * glm::dot(glm::normalize(glm::cross(a, b)), glm::dvec3(n));
    }
    return std::abs(0.5 * sum);
}

// Monte Carlo irradiance (red channel) at ctx from sampleLi: L cos / pdf.
Estimate irradiance(const Light& light, const LightSampleContext& ctx, int n, uint64_t seed) {
    Rng rng(seed);
    return monteCarlo(n, [&](int) {
        LightSample s;
        if (!light.sampleLi(ctx, rng.uniform2(), &s)) return 0.0;
        return double(s.L.x) * std::max(0.f, glm::dot(s.wi, ctx.n)) / s.pdf;
    });
}

std::shared_ptr<QuadricShape> makeQuadricShape(const Quadric& q, const Mat4& worldFromObject,
                                               bool flip = false) {
    auto s = std::make_shared<QuadricShape>();
    s->quadric = q;
    s->worldFromObject = worldFromObject;
    s->objectFromWorld = glm::inverse(worldFromObject);
    s->flipNormals = flip;
    return s;
}

// The first visible point of a quadric along a world ray, with pbrt-v3's (and scene.cpp's)
// intersection normal: the object-space normal flipped by flipNormals, transformed.
bool hitQuadric(const QuadricShape& s, const Vec3& o, const Vec3& d, Vec3* p, Vec3* n) {
    Vec3 oo = transformPoint(s.objectFromWorld, o), dd = transformVector(s.objectFromWorld, d);
    QuadricHit h;
    if (!intersect(s.quadric, oo, dd, 0.f, Infinity, &h)) return false;
    *p = transformPoint(s.worldFromObject, h.p);
    Vec3 nw = glm::normalize(transformNormal(s.objectFromWorld, h.n));
    *n = s.flipNormals ? -nw : nw;
    return true;
}


// Checks over n samples that sampleLi's pdf equals pdfLi for the sampled direction.
// normalAt(s, &pLight, &nLight) gives the light point and normal a renderer would find along
// s.wi (false: skip the sample, e.g. one hidden behind another part of the same light).
template <typename NormalAt>
void expectPdfConsistent(const Light& light, const LightSampleContext& ctx, uint64_t seed,
                         NormalAt&& normalAt, int n = 2000) {
    Rng rng(seed);
    int checked = 0;
    for (int i = 0; i < n; ++i) {
        LightSample s;
        if (!light.sampleLi(ctx, rng.uniform2(), &s)) continue;
        ASSERT_FALSE(s.isDelta);
        ASSERT_NEAR(glm::length(s.wi), 1.f, 1e-5f);
        Vec3 pLight(0.f), nLight(0.f);
        if (!normalAt(s, &pLight, &nLight)) continue;
        ++checked;
        float pdf = light.pdfLi(ctx, s.wi, pLight, nLight);
        // Area-to-solid-angle conversions divide by cos at the light: float error in the
        // normal and point (~1e-5) grows as 1/cos at grazing angles.
        float cosL = std::max(std::abs(glm::dot(nLight, s.wi)), 1e-6f);
        ASSERT_NEAR(pdf, s.pdf, (2e-3f + 3e-4f / cosL) * s.pdf)
            << "sample " << i << " cos " << cosL << " dist " << s.dist;
    }
    EXPECT_GT(checked, n / 4);
}

// ---------------------------------------------------------------------------------------
// Factory and parameters

TEST(Lights, UnknownTypeIsAnError) {
    Fixture f;
    EXPECT_EQ(f.make("laser", {}), nullptr);
    ASSERT_EQ(f.diag.errorCount(), 1);
    EXPECT_NE(f.diag.all()[0].message.find("unknown light type"), std::string::npos);

    auto mesh = std::make_shared<TriangleMesh>();
    mesh->p = {Vec3(0.f), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    mesh->indices = {0, 1, 2};
    ShapeData shape;
    shape.mesh = mesh;
    std::vector<std::unique_ptr<Light>> out;
    ParamList none = f.params({});
    EXPECT_FALSE(createAreaLights("glowing", none, shape, FileLoc(), f.diag, &out));
    EXPECT_EQ(f.diag.errorCount(), 2);
    EXPECT_TRUE(out.empty());
}

TEST(Lights, UnusedParametersAreReported) {
    Fixture f;
    // "conedelta" is not pbrt-v3's name ("conedeltaangle"); a float "I" has the wrong type.
    auto l = f.make("spot", {floatParam("conedelta", 3.f), floatParam("I", 2.f),
                             rgbParam("scale", 1, 1, 1)});
    ASSERT_NE(l, nullptr);
    EXPECT_EQ(f.diag.errorCount(), 0);
    EXPECT_EQ(f.diag.warningCount(), 2);
    // nsamples is accepted (and ignored) by the infinite light.
    Fixture g;
    auto inf = g.make("infinite", {numParam(ParamType::Integer, "nsamples", {8})});
    ASSERT_NE(inf, nullptr);
    EXPECT_EQ(g.diag.warningCount(), 0);
}

// ---------------------------------------------------------------------------------------
// Delta lights

TEST(Lights, PointLightInverseSquareLaw) {
    Fixture f;
    // pbrt-v3: the position is CTM(origin) + from (Translate(from) applied after the CTM).
    Mat4 ctm = translateMatrix(Vec3(1, 0, 0)) * rotateMatrix(90.f, Vec3(0, 0, 1));
    auto l = f.make("point", {rgbParam("I", 2, 4, 6), rgbParam("scale", 0.5f, 0.5f, 0.5f),
                              pointParam("from", Vec3(0, 0, 3))},
                    ctm);
    ASSERT_NE(l, nullptr);
    EXPECT_EQ(l->kind(), LightKind::DeltaPosition);
    EXPECT_TRUE(l->isDelta());
    Vec3 pos(1, 0, 3);
    for (float d : {0.5f, 1.f, 2.f, 7.f}) {
        LightSampleContext ctx;
        ctx.p = pos + d * glm::normalize(Vec3(1, -2, 0.5f));
        LightSample s;
        ASSERT_TRUE(l->sampleLi(ctx, Vec2(0.3f, 0.6f), &s));
        EXPECT_TRUE(s.isDelta);
        EXPECT_FLOAT_EQ(s.pdf, 1.f);
        EXPECT_NEAR(s.dist, d, 1e-5f * d);
        EXPECT_NEAR(glm::length(ctx.p + s.wi * s.dist - pos), 0.f, 1e-5f);
        EXPECT_NEAR(s.L.x, 1.f / (d * d), 1e-5f / (d * d));
        EXPECT_NEAR(s.L.z, 3.f / (d * d), 3e-5f / (d * d));
        EXPECT_EQ(l->pdfLi(ctx, s.wi, pos, Vec3(0.f)), 0.f);
    }
    EXPECT_NEAR(l->power().y, 4.f * Pi * 2.f, 1e-4f);
}

TEST(Lights, SpotLightFalloff) {
    Fixture f;
    Vec3 from(0, 0, 2), to(0, 0, 0);  // pointing down -z
    auto l = f.make("spot", {rgbParam("I", 3, 3, 3), floatParam("coneangle", 30.f),
                             floatParam("conedeltaangle", 10.f), pointParam("from", from),
                             pointParam("to", to)});
    ASSERT_NE(l, nullptr);
    float cosTotal = std::cos(radians(30.f)), cosStart = std::cos(radians(20.f));
    for (float deg : {0.f, 10.f, 19.f, 21.f, 25.f, 29.f, 31.f, 60.f, 120.f}) {
        float a = radians(deg);
        float d = 1.5f;
        LightSampleContext ctx;
        ctx.p = from + d * Vec3(std::sin(a), 0.f, -std::cos(a));
        LightSample s;
        bool ok = l->sampleLi(ctx, Vec2(0.5f), &s);
        float c = std::cos(a), expected;
        if (c < cosTotal) {
            expected = 0.f;
        } else if (c > cosStart) {
            expected = 1.f;
        } else {
            float delta = (c - cosTotal) / (cosStart - cosTotal);
            expected = delta * delta * delta * delta;
        }
        EXPECT_EQ(ok, expected > 0.f) << deg;
        EXPECT_NEAR(s.L.x, 3.f * expected / (d * d), 1e-4f) << deg;
    }
    // Power: I 2 pi (1 - (cosStart + cosTotal) / 2).
    EXPECT_NEAR(l->power().x, 3.f * 2.f * Pi * (1.f - 0.5f * (cosStart + cosTotal)), 1e-4f);
}

TEST(Lights, SpotLightFollowsTheTransform) {
    Fixture f;
    // Default from (0,0,0) to (0,0,1), rotated so the spot points along +x, placed at (0,1,0).
    Mat4 ctm = translateMatrix(Vec3(0, 1, 0)) * rotateMatrix(90.f, Vec3(0, 1, 0));
    auto l = f.make("spot", {}, ctm);
    ASSERT_NE(l, nullptr);
    LightSampleContext ctx;
    ctx.p = Vec3(2, 1, 0);
    LightSample s;
    ASSERT_TRUE(l->sampleLi(ctx, Vec2(0.5f), &s));
    EXPECT_NEAR(s.L.x, 0.25f, 1e-5f);
    EXPECT_NEAR(s.wi.x, -1.f, 1e-5f);
    ctx.p = Vec3(0, 1, 2);  // along the light's old +z, now sideways
    EXPECT_FALSE(l->sampleLi(ctx, Vec2(0.5f), &s));
}

TEST(Lights, DistantLightIsConstant) {
    Fixture f;
    Mat4 ctm = rotateMatrix(90.f, Vec3(1, 0, 0));
    auto l = f.make("distant", {rgbParam("L", 1, 2, 3), pointParam("from", Vec3(0, 0, 0)),
                                pointParam("to", Vec3(0, -1, 0))},
                    ctm);
    ASSERT_NE(l, nullptr);
    EXPECT_EQ(l->kind(), LightKind::DeltaDirection);
    // wLight = from - to = (0,1,0), rotated 90 degrees about x: (0,0,1).
    Vec3 expectedDir = glm::normalize(transformVector(ctm, Vec3(0, 1, 0)));
    Rng rng(3);
    for (int i = 0; i < 20; ++i) {
        LightSampleContext ctx;
        ctx.p = 100.f * (Vec3(rng.uniform(), rng.uniform(), rng.uniform()) - 0.5f);
        LightSample s;
        ASSERT_TRUE(l->sampleLi(ctx, rng.uniform2(), &s));
        EXPECT_TRUE(s.isDelta);
        EXPECT_NEAR(glm::length(s.wi - expectedDir), 0.f, 1e-5f);
        EXPECT_EQ(s.L, Spectrum(1, 2, 3));
        EXPECT_TRUE(std::isinf(s.dist));
    }
    l->preprocess(Vec3(0.f), 10.f);
    EXPECT_NEAR(l->power().z, 3.f * Pi * 100.f, 1e-3f);
}

// A power-of-two RGB test image whose texel (x, y) is (x+1, y+1, 10) * k.
std::vector<float> gridImage(int w, int h, float k) {
    std::vector<float> rgb(size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* t = &rgb[(size_t(y) * w + x) * 3];
            t[0] = (x + 1) * k;
            t[1] = (y + 1) * k;
            t[2] = 10.f * k;
        }
    return rgb;
}

TEST(Lights, GoniometricLightIndexesTheMapWithPbrtAxisSwap) {
    const int w = 8, h = 4;
    std::string path = writeExr("gonio", w, h, gridImage(w, h, 1.f));
    Fixture f;
    auto l = f.make("goniometric", {rgbParam("I", 2, 2, 2), stringParam("mapname", path)});
    ASSERT_NE(l, nullptr);
    EXPECT_EQ(f.diag.warningCount(), 0);
    // Texel centres: theta is measured from the light's +y axis, phi in its z-x plane
    // (pbrt-v3 swaps y and z before the spherical lookup).
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float phi = (x + 0.5f) / w * 2.f * Pi, theta = (y + 0.5f) / h * Pi;
            Vec3 wp = sphericalDirection(std::sin(theta), std::cos(theta), phi);
            Vec3 dir(wp.x, wp.z, wp.y);  // light-space direction leaving the light
            LightSampleContext ctx;
            ctx.p = 2.f * dir;
            LightSample s;
            ASSERT_TRUE(l->sampleLi(ctx, Vec2(0.5f), &s));
            EXPECT_NEAR(s.L.x, 2.f * (x + 1) / 4.f, 2e-3f) << x << " " << y;
            EXPECT_NEAR(s.L.y, 2.f * (y + 1) / 4.f, 2e-3f) << x << " " << y;
        }
    // Power: 4 pi I times the map average.
    EXPECT_NEAR(l->power().x, 4.f * Pi * 2.f * 4.5f, 1e-2f);
    EXPECT_NEAR(l->power().y, 4.f * Pi * 2.f * 2.5f, 1e-2f);
    std::remove(path.c_str());
}

TEST(Lights, ProjectionLightWithoutMap) {
    Fixture f;
    auto l = f.make("projection", {rgbParam("I", 5, 5, 5), floatParam("fov", 90.f)});
    ASSERT_NE(l, nullptr);
    // fov 90: the screen window [-1,1]^2 at z = 1 spans 45 degrees each way.
    auto at = [&](Vec3 dirLight) {
        LightSampleContext ctx;
        ctx.p = 2.f * glm::normalize(dirLight);
        LightSample s;
        l->sampleLi(ctx, Vec2(0.5f), &s);
        return s.L.x;
    };
    EXPECT_NEAR(at(Vec3(0, 0, 1)), 5.f / 4.f, 1e-5f);
    EXPECT_NEAR(at(Vec3(0.9f, -0.9f, 1)), 5.f / 4.f, 1e-5f);
    EXPECT_EQ(at(Vec3(1.1f, 0, 1)), 0.f);
    EXPECT_EQ(at(Vec3(0, 0, -1)), 0.f);
    // Power: I 2 pi (1 - cos(atan(tan(fov/2) sqrt(2)))) with aspect 1.
    float cosTotal = std::cos(std::atan(std::sqrt(2.f)));
    EXPECT_NEAR(l->power().x, 5.f * 2.f * Pi * (1.f - cosTotal), 1e-3f);
}

TEST(Lights, ProjectionLightMapsTheImageOntoTheScreenWindow) {
    const int w = 4, h = 2;  // aspect 2: screen window [-2,2] x [-1,1]
    std::string path = writeExr("proj", w, h, gridImage(w, h, 1.f));
    Fixture f;
    float fov = 60.f, tanHalf = std::tan(radians(fov) / 2.f);
    Mat4 ctm = translateMatrix(Vec3(1, 2, 3));
    auto l = f.make("projection", {stringParam("mapname", path), floatParam("fov", fov)}, ctm);
    ASSERT_NE(l, nullptr);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            // Texel centre -> screen point -> light-space direction (s along +x, t along +y).
            Vec2 st((x + 0.5f) / w, (y + 0.5f) / h);
            Vec2 p(-2.f + 4.f * st.x, -1.f + 2.f * st.y);
            Vec3 dir = glm::normalize(Vec3(p.x * tanHalf, p.y * tanHalf, 1.f));
            LightSampleContext ctx;
            ctx.p = Vec3(1, 2, 3) + 3.f * dir;
            LightSample s;
            ASSERT_TRUE(l->sampleLi(ctx, Vec2(0.5f), &s));
            EXPECT_NEAR(s.L.x, (x + 1) / 9.f, 1e-3f) << x << " " << y;
            EXPECT_NEAR(s.L.y, (y + 1) / 9.f, 1e-3f) << x << " " << y;
        }
    std::remove(path.c_str());
}

TEST(Lights, UnreadableMapWarnsAndFallsBack) {
    Fixture f;
    auto l = f.make("goniometric", {stringParam("mapname", "/nonexistent/map.exr")});
    ASSERT_NE(l, nullptr);
    EXPECT_EQ(f.diag.warningCount(), 1);
    EXPECT_EQ(f.diag.errorCount(), 0);
    LightSampleContext ctx;
    ctx.p = Vec3(0, 0, 1);
    LightSample s;
    ASSERT_TRUE(l->sampleLi(ctx, Vec2(0.5f), &s));
    EXPECT_NEAR(s.L.x, 1.f, 1e-6f);
}

// ---------------------------------------------------------------------------------------
// Infinite lights

// A 16x8 environment map: smooth variation plus one bright texel, so that importance
// sampling is far from uniform.
std::vector<float> envImage(int w, int h) {
    std::vector<float> rgb(size_t(w) * h * 3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* t = &rgb[(size_t(y) * w + x) * 3];
            float base = 1.f + 0.5f * std::sin(2.f * Pi * (x + 0.5f) / w) +
                         0.25f * std::cos(Pi * (y + 0.5f) / h);
            t[0] = base;
            t[1] = 0.5f * base;
            t[2] = 2.f;
        }
    float* bright = &rgb[(size_t(2) * w + 11) * 3];
    bright[0] = bright[1] = bright[2] = 40.f;
    return rgb;
}

struct EnvFixture : Fixture {
    const int kW, kH;
    std::string path;
    Mat4 ctm = rotateMatrix(-90.f, Vec3(1, 0, 0)) * rotateMatrix(30.f, Vec3(0, 0, 1));
    std::unique_ptr<Light> light;
    std::vector<float> rgb;
    explicit EnvFixture(int w = 16, int h = 8) : kW(w), kH(h), rgb(envImage(w, h)) {
        path = writeExr("env", kW, kH, rgb);
        light = make("infinite", {stringParam("mapname", path), rgbParam("L", 2, 2, 2),
                                  rgbParam("scale", 0.5f, 0.5f, 0.5f),
                                  numParam(ParamType::Integer, "nsamples", {4})},
                     ctm);
    }
    ~EnvFixture() { std::remove(path.c_str()); }
    // World direction of light-space spherical coordinates (theta from +z, phi from +x).
    Vec3 worldDir(float theta, float phi) const {
        return glm::normalize(
            transformVector(ctm, sphericalDirection(std::sin(theta), std::cos(theta), phi)));
    }
};

// The integral of the light's pdfLi over the sphere by the midpoint rule on a 300 x 600 grid
// in (theta, phi), not aligned with the sampling table's cells.
double pdfIntegral(const EnvFixture& e) {
    const int nT = 300, nP = 600;
    double sum = 0;
    LightSampleContext ctx;
    for (int it = 0; it < nT; ++it)
        for (int ip = 0; ip < nP; ++ip) {
            float theta = (it + 0.5f) / nT * Pi, phi = (ip + 0.5f) / nP * 2.f * Pi;
            float pdf = e.light->pdfLi(ctx, e.worldDir(theta, phi), Vec3(0.f), Vec3(0.f));
            sum += pdf * std::sin(theta) * (Pi / nT) * (2.0 * Pi / nP);
        }
    return sum;
}

// The map's integral over the sphere (red channel): texel values times their solid angles,
// 2 pi / W (cos theta0 - cos theta1).
double texelIntegral(const EnvFixture& e) {
    double sum = 0;
    for (int y = 0; y < e.kH; ++y)
        for (int x = 0; x < e.kW; ++x)
            sum += e.rgb[(size_t(y) * e.kW + x) * 3] * 2.0 * Pi / e.kW *
                   (std::cos(Pi * y / e.kH) - std::cos(Pi * (y + 1) / e.kH));
    return sum;
}

// Monte Carlo estimates of the map's integral (red channel) from n directions: sampled by the
// light (Le / pdf), and uniform over the sphere.
Estimate sampledIntegral(const EnvFixture& e, uint64_t seed, int n) {
    LightSampleContext ctx;
    Rng rng(seed);
    return monteCarlo(n, [&](int) {
        LightSample s;
        if (!e.light->sampleLi(ctx, rng.uniform2(), &s)) return 0.0;
        return double(s.L.x) / s.pdf;
    });
}
Estimate uniformIntegral(const EnvFixture& e, uint64_t seed, int n) {
    Rng rng(seed);
    return monteCarlo(n, [&](int) {
        return double(e.light->Le(sampleUniformSphere(rng.uniform2())).x) / uniformSpherePdf();
    });
}

TEST(Lights, InfiniteLightLeAtTexelCentres) {
    EnvFixture e;
    ASSERT_NE(e.light, nullptr);
    EXPECT_EQ(e.diag.warningCount(), 0);
    EXPECT_EQ(e.light->kind(), LightKind::Infinite);
    for (int y = 0; y < e.kH; ++y)
        for (int x = 0; x < e.kW; ++x) {
            float theta = (y + 0.5f) / e.kH * Pi, phi = (x + 0.5f) / e.kW * 2.f * Pi;
            Spectrum Le = e.light->Le(e.worldDir(theta, phi));
            const float* t = &e.rgb[(size_t(y) * e.kW + x) * 3];
            EXPECT_NEAR(Le.x, t[0], 1e-3f * t[0]) << x << " " << y;  // L * scale = 1
            EXPECT_NEAR(Le.y, t[1], 1e-3f * t[1]) << x << " " << y;
        }
}

// Samples of e's light carry the density pdfLi gives their direction and the radiance Le
// gives it. A direction sampled next to an edge of a distribution cell can round into the
// neighbouring cell when mapped back: a few such samples are allowed, not more.
void expectSamplesMatchPdfLiAndLe(const EnvFixture& e, uint64_t seed) {
    LightSampleContext ctx;
    ctx.p = Vec3(3, -1, 2);
    Rng rng(seed);
    int n = 20000, valid = 0, pdfMismatch = 0, leMismatch = 0;
    for (int i = 0; i < n; ++i) {
        LightSample s;
        if (!e.light->sampleLi(ctx, rng.uniform2(), &s)) continue;
        ++valid;
        ASSERT_TRUE(std::isinf(s.dist));
        ASSERT_NEAR(glm::length(s.wi), 1.f, 1e-5f);
        float pdf = e.light->pdfLi(ctx, s.wi, Vec3(0.f), Vec3(0.f));
        if (std::abs(pdf - s.pdf) > 2e-3f * s.pdf) ++pdfMismatch;
        Spectrum Le = e.light->Le(s.wi);
        if (std::abs(Le.x - s.L.x) > 2e-3f * s.L.x + 1e-5f) ++leMismatch;
    }
    EXPECT_GT(valid, n * 99 / 100);
    EXPECT_LE(pdfMismatch, n / 500);
    EXPECT_LE(leMismatch, n / 500);
}

TEST(Lights, InfiniteLightSamplePdfMatchesPdfLiAndLe) {
    EnvFixture e;
    ASSERT_NE(e.light, nullptr);
    expectSamplesMatchPdfLiAndLe(e, 11);
}

TEST(Lights, InfiniteLightPdfIntegratesToOne) {
    EnvFixture e;
    ASSERT_NE(e.light, nullptr);
    // The pdf is piecewise constant in (phi, theta) after the sin(theta) factor, so the
    // midpoint rule's error is only from the 32x16 cells cut by its grid lines: well below 1%.
    EXPECT_NEAR(pdfIntegral(e), 1.0, 5e-3);
}

TEST(Lights, InfiniteLightSamplingChiSquare) {
    EnvFixture e;
    ASSERT_NE(e.light, nullptr);
    LightSampleContext ctx;
    chi2::SphereOptions opt;
    opt.thetaRes = 16;
    opt.phiRes = 32;
    opt.sampleCount = 400000;
    opt.integrationEps = 1e-6;
    auto sample = [&](Vec3 u) {
        LightSample s;
        chi2::SphereSample r;
        if (e.light->sampleLi(ctx, Vec2(u.x, u.y), &s)) {
            r.dir = s.wi;
            r.pdf = s.pdf;
        }
        return r;
    };
    auto pdf = [&](const Vec3& w) { return e.light->pdfLi(ctx, w, Vec3(0.f), Vec3(0.f)); };
    chi2::SphereResult r = chi2::testSphere(sample, pdf, opt);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdfIntegral, 1.0, 1e-2);
}

// A map too large for pbrt-v3's 2x oversampled table (over 2^20 entries) is sampled from a
// table at its own resolution: still consistent with pdfLi and Le, a density, and a far
// better estimator of the map's integral than uniform directions.
TEST(Lights, InfiniteLightLargeMapSampledAtItsResolution) {
    EnvFixture e(1024, 512);
    ASSERT_NE(e.light, nullptr);
    expectSamplesMatchPdfLiAndLe(e, 12);
    EXPECT_NEAR(pdfIntegral(e), 1.0, 5e-3);
    // The map's integral from its texels (bilinear filtering moves almost nothing at this
    // resolution); 5 standard errors plus 0.5%.
    const double texelSum = texelIntegral(e);
    const Estimate est = sampledIntegral(e, 13, 100000);
    EXPECT_NEAR(est.mean, texelSum, 5.0 * est.stdErr + 5e-3 * texelSum);
    const Estimate uni = uniformIntegral(e, 14, 100000);
    EXPECT_LT(est.stdErr, 0.5 * uni.stdErr);
}

TEST(Lights, InfiniteLightImportanceSampledIntegralOfLe) {
    EnvFixture e;
    ASSERT_NE(e.light, nullptr);
    // Reference 1: the integral of Le (bilinear texel interpolation) by a fine midpoint rule.
    const int nT = 512, nP = 1024;
    double direct = 0;
    for (int it = 0; it < nT; ++it)
        for (int ip = 0; ip < nP; ++ip) {
            float theta = (it + 0.5f) / nT * Pi, phi = (ip + 0.5f) / nP * 2.f * Pi;
            direct += e.light->Le(e.worldDir(theta, phi)).x * std::sin(theta) * (Pi / nT) *
                      (2.0 * Pi / nP);
        }
    // Reference 2: texel values times their solid angles.
    const double texelSum = texelIntegral(e);
    // Bilinear filtering (with pbrt-v3's repeat wrap across the poles) redistributes energy
    // between neighbouring texels; for this map the two references agree to a few percent.
    EXPECT_NEAR(direct, texelSum, 0.03 * texelSum);
    const Estimate est = sampledIntegral(e, 5, 200000);
    // 5 standard errors: a false failure has probability below 1e-6.
    EXPECT_NEAR(est.mean, direct, 5.0 * est.stdErr + 1e-4 * direct);
    // Importance sampling must have a smaller standard error than uniform sphere sampling.
    const Estimate uni = uniformIntegral(e, 6, 200000);
    EXPECT_NEAR(uni.mean, direct, 5.0 * uni.stdErr + 1e-4 * direct);
    EXPECT_LT(est.stdErr, 0.5 * uni.stdErr);
    // Power: pi r^2 times the map average (the mean of the L*scale = 1 texels).
    e.light->preprocess(Vec3(0.f), 2.f);
    double mean = 0;
    for (int i = 0; i < e.kW * e.kH; ++i) mean += e.rgb[size_t(i) * 3];
    mean /= e.kW * e.kH;
    EXPECT_NEAR(e.light->power().x, Pi * 4.0 * mean, 1e-3 * Pi * 4.0 * mean);
}

TEST(Lights, ConstantInfiniteLight) {
    Fixture f;
    auto l = f.make("infinite", {rgbParam("L", 0.5f, 1.f, 2.f)});
    ASSERT_NE(l, nullptr);
    EXPECT_EQ(l->Le(Vec3(0, 0, 1)), Spectrum(0.5f, 1.f, 2.f));
    EXPECT_EQ(l->Le(glm::normalize(Vec3(1, -3, 2))), Spectrum(0.5f, 1.f, 2.f));
    for (Vec3 n : {Vec3(0.f), glm::normalize(Vec3(1, 2, -2))}) {
        LightSampleContext ctx;
        ctx.p = Vec3(1, 1, 1);
        ctx.n = n;
        chi2::SphereOptions opt;
        opt.sampleCount = 200000;
        auto sample = [&](Vec3 u) {
            LightSample s;
            chi2::SphereSample r;
            if (l->sampleLi(ctx, Vec2(u.x, u.y), &s)) {
                r.dir = s.wi;
                r.pdf = s.pdf;
            }
            return r;
        };
        auto pdf = [&](const Vec3& w) { return l->pdfLi(ctx, w, Vec3(0.f), Vec3(0.f)); };
        chi2::SphereResult r = chi2::testSphere(sample, pdf, opt);
        EXPECT_TRUE(r.passed) << r.message;
        EXPECT_NEAR(r.pdfIntegral, 1.0, 1e-2);
    }
    // Irradiance on a surface under a uniform sky: pi L.
    LightSampleContext ctx;
    ctx.n = Vec3(0, 0, 1);
    Estimate e = irradiance(*l, ctx, 100000, 9);
    // 5 standard errors: a false failure has probability below 1e-6.
    EXPECT_NEAR(e.mean, Pi * 0.5, 5.0 * e.stdErr + 1e-5);
    l->preprocess(Vec3(0.f), 3.f);
    EXPECT_NEAR(l->power().z, Pi * 9.f * 2.f, 1e-3f);
}

// ---------------------------------------------------------------------------------------
// Area lights

std::vector<std::unique_ptr<Light>> makeAreaLights(Fixture& f, const ShapeData& shape,
                                                   std::vector<Param> ps,
                                                   const std::string& type = "diffuse") {
    std::vector<std::unique_ptr<Light>> out;
    ParamList l = f.params(std::move(ps));
    EXPECT_TRUE(createAreaLights(type, l, shape, FileLoc(), f.diag, &out));
    return out;
}

struct TriangleFixture : Fixture {
    std::shared_ptr<TriangleMesh> mesh = std::make_shared<TriangleMesh>();
    ShapeData shape;
    TriangleFixture() {
        // A quad at z = 2 made of two triangles wound so that cross(p1-p0, p2-p0) = -z.
        mesh->p = {Vec3(-1, -0.5f, 2), Vec3(1.5f, -0.5f, 2), Vec3(1.5f, 1, 2), Vec3(-1, 1, 2)};
        mesh->indices = {0, 2, 1, 0, 3, 2};
        shape.mesh = mesh;
        shape.type = "trianglemesh";
    }
    std::vector<Vec3> quad() const { return mesh->p; }
};

// The point and (pbrt-v3-oriented) normal a renderer would find along s.wi for a plane light.
auto planeNormal(const LightSampleContext& ctx, Vec3 n) {
    return [ctx, n](const LightSample& s, Vec3* p, Vec3* nl) {
        *p = ctx.p + s.wi * s.dist;
        *nl = n;
        return true;
    };
}

TEST(Lights, TriangleAreaLightsOnePerTriangle) {
    TriangleFixture t;
    auto lights = makeAreaLights(t, t.shape, {rgbParam("L", 2, 2, 2),
                                               numParam(ParamType::Integer, "nsamples", {4})},
                                 "area");
    ASSERT_EQ(lights.size(), 2u);
    EXPECT_EQ(t.diag.warningCount(), 0);
    EXPECT_EQ(lights[0]->kind(), LightKind::Area);
    // Power: L * area * pi per triangle (quad area 2.5 * 1.5, split in halves).
    EXPECT_NEAR(lights[0]->power().x + lights[1]->power().x, 2.f * 3.75f * Pi, 1e-4f);
}

TEST(Lights, TriangleLightIrradianceMatchesLambert) {
    TriangleFixture t;
    auto lights = makeAreaLights(t, t.shape, {rgbParam("L", 3, 3, 3)});
    ASSERT_EQ(lights.size(), 2u);
    LightSampleContext ctx;
    ctx.p = Vec3(0.2f, 0.1f, 0.5f);
    ctx.n = glm::normalize(Vec3(0.3f, -0.2f, 1.f));
    for (size_t i = 0; i < 2; ++i)
        expectPdfConsistent(*lights[i], ctx, 20 + i, planeNormal(ctx, Vec3(0, 0, -1)));
    double analytic = 3.0 * polygonIrradiance(t.quad(), ctx.p, ctx.n);
    Estimate a = irradiance(*lights[0], ctx, 100000, 1);
    Estimate b = irradiance(*lights[1], ctx, 100000, 2);
    double se = std::sqrt(a.stdErr * a.stdErr + b.stdErr * b.stdErr);
    // 5 standard errors of the summed estimate: a false failure has probability < 1e-6.
    EXPECT_NEAR(a.mean + b.mean, analytic, 5.0 * se + 1e-6);
    EXPECT_GT(analytic, 0.1);
}

TEST(Lights, TriangleLightEmitsOnTheNormalSideUnlessTwoSided) {
    TriangleFixture t;
    LightSampleContext below, above;
    below.p = Vec3(0.2f, 0.2f, 0.f);
    below.n = Vec3(0, 0, 1);
    above.p = Vec3(0.2f, 0.2f, 4.f);
    above.n = Vec3(0, 0, -1);
    {
        auto one = makeAreaLights(t, t.shape, {});
        LightSample s;
        // Winding gives normal -z: emission downwards only.
        EXPECT_TRUE(one[0]->sampleLi(below, Vec2(0.3f, 0.3f), &s));
        EXPECT_FALSE(one[0]->sampleLi(above, Vec2(0.3f, 0.3f), &s));
        EXPECT_EQ(one[0]->L(Vec3(0, 0, 2), Vec3(0, 0, -1), Vec2(0.f), Vec3(0, 0, 1)),
                  Spectrum(0.f));
        EXPECT_EQ(one[0]->L(Vec3(0, 0, 2), Vec3(0, 0, -1), Vec2(0.f), Vec3(0, 0, -1)),
                  Spectrum(1.f));
    }
    {
        auto two = makeAreaLights(t, t.shape, {boolParam("twosided", true)});
        LightSample s;
        EXPECT_TRUE(two[0]->sampleLi(above, Vec2(0.3f, 0.3f), &s));
        EXPECT_EQ(s.L, Spectrum(1.f));
        EXPECT_EQ(two[0]->L(Vec3(0, 0, 2), Vec3(0, 0, -1), Vec2(0.f), Vec3(0, 0, 1)),
                  Spectrum(1.f));
        // Symmetric points above and below receive the same irradiance.
        Estimate a = irradiance(*two[0], below, 50000, 4);
        Estimate b = irradiance(*two[0], above, 50000, 4);
        EXPECT_NEAR(a.mean, b.mean, 1e-3 * a.mean);
        EXPECT_NEAR(two[0]->power().x, 2.f * 1.875f * Pi, 1e-4f);
    }
    {
        // flipNormals (ReverseOrientation xor handedness swap) turns emission upwards.
        t.mesh->flipNormals = true;
        auto flipped = makeAreaLights(t, t.shape, {});
        LightSample s;
        EXPECT_FALSE(flipped[0]->sampleLi(below, Vec2(0.3f, 0.3f), &s));
        EXPECT_TRUE(flipped[0]->sampleLi(above, Vec2(0.3f, 0.3f), &s));
    }
    {
        // Shading normals decide the side (pbrt-v3), whatever flipNormals says.
        t.mesh->flipNormals = true;
        t.mesh->n.assign(4, Vec3(0, 0, -1));
        auto shaded = makeAreaLights(t, t.shape, {});
        LightSample s;
        EXPECT_TRUE(shaded[0]->sampleLi(below, Vec2(0.3f, 0.3f), &s));
        EXPECT_FALSE(shaded[0]->sampleLi(above, Vec2(0.3f, 0.3f), &s));
    }
}

// Sphere light of radius r at c (through a similarity with scale 2 and rotation).
struct SphereFixture : Fixture {
    Vec3 c{1, 2, -1};
    float r = 0.75f;
    std::shared_ptr<QuadricShape> qs;
    ShapeData shape;
    explicit SphereFixture(const Mat4& extra = Mat4(1.f)) {
        Mat4 m = translateMatrix(c) * rotateMatrix(40.f, Vec3(1, 1, 0)) * extra *
                 scaleMatrix(Vec3(2.f));
        qs = makeQuadricShape(makeSphere(r / 2.f), m);
        shape.quadric = qs;
        shape.type = "sphere";
    }
    auto visibleHit(const LightSampleContext& ctx) const {
        const QuadricShape* s = qs.get();
        return [ctx, s](const LightSample& ls, Vec3* p, Vec3* n) {
            if (!hitQuadric(*s, ctx.p, ls.wi, p, n)) return false;
            return std::abs(glm::length(*p - ctx.p) - ls.dist) < 1e-3f * ls.dist;
        };
    }
};

TEST(Lights, SphereLightIrradianceFromOutside) {
    SphereFixture sf;
    auto lights = makeAreaLights(sf, sf.shape, {rgbParam("L", 2, 2, 2)});
    ASSERT_EQ(lights.size(), 1u);
    for (float d : {1.f, 3.f, 10.f}) {
        LightSampleContext ctx;
        Vec3 axis = glm::normalize(Vec3(1, -1, 2));
        ctx.p = sf.c + (sf.r + d) * axis;
        ctx.n = -axis;
        float dist = sf.r + d;
        expectPdfConsistent(*lights[0], ctx, 30, sf.visibleHit(ctx));
        Estimate e = irradiance(*lights[0], ctx, 50000, 31);
        double analytic = Pi * 2.0 * (sf.r / dist) * (sf.r / dist);
        // 5 standard errors: a false failure has probability below 1e-6 (cone sampling of a
        // facing sphere has small variance).
        EXPECT_NEAR(e.mean, analytic, 5.0 * e.stdErr + 1e-4 * analytic) << d;
    }
    // Power: L pi area with the world radius 0.75.
    EXPECT_NEAR(lights[0]->power().x, 2.f * Pi * 4.f * Pi * sf.r * sf.r, 1e-3f);
}

TEST(Lights, SphereLightFromInside) {
    SphereFixture sf;
    auto lights = makeAreaLights(sf, sf.shape, {boolParam("twosided", true)});
    LightSampleContext ctx;
    ctx.p = sf.c + Vec3(0.2f, -0.1f, 0.3f);
    ctx.n = glm::normalize(Vec3(1, 1, 1));
    expectPdfConsistent(*lights[0], ctx, 40, sf.visibleHit(ctx));
    // Inside a uniformly emitting (two-sided) sphere the irradiance is pi L.
    Estimate e = irradiance(*lights[0], ctx, 100000, 41);
    // 5 standard errors: a false failure has probability below 1e-6.
    EXPECT_NEAR(e.mean, Pi, 5.0 * e.stdErr + 1e-4);
    // One-sided with outward normals: nothing reaches the inside.
    SphereFixture sf1;
    auto oneSided = makeAreaLights(sf1, sf1.shape, {});
    LightSample s;
    EXPECT_FALSE(oneSided[0]->sampleLi(ctx, Vec2(0.3f, 0.7f), &s));
}

TEST(Lights, SphereLightSamplingChiSquare) {
    SphereFixture sf;
    auto lights = makeAreaLights(sf, sf.shape, {});
    LightSampleContext ctx;
    ctx.p = sf.c + Vec3(0.f, 0.f, 1.5f);
    chi2::SphereOptions opt;
    opt.thetaRes = 40;
    opt.phiRes = 80;
    opt.sampleCount = 300000;
    auto sample = [&](Vec3 u) {
        LightSample s;
        chi2::SphereSample r;
        if (lights[0]->sampleLi(ctx, Vec2(u.x, u.y), &s)) {
            r.dir = s.wi;
            r.pdf = s.pdf;
        }
        return r;
    };
    auto pdf = [&](const Vec3& w) {
        Vec3 p, n;
        if (!hitQuadric(*sf.qs, ctx.p, w, &p, &n)) return 0.f;
        return lights[0]->pdfLi(ctx, w, p, n);
    };
    chi2::SphereResult r = chi2::testSphere(sample, pdf, opt);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdfIntegral, 1.0, 2e-2);
}

TEST(Lights, EllipsoidLightUsesExactAreaSampling) {
    // A non-uniform scale: area sampling in object space with the transform's area scaling.
    Fixture f;
    Mat4 m = translateMatrix(Vec3(0, 0, 3)) * rotateMatrix(25.f, Vec3(0, 1, 0)) *
             scaleMatrix(Vec3(2.f, 1.f, 1.f));
    auto qs = makeQuadricShape(makeSphere(1.f), m);
    ShapeData shape;
    shape.quadric = qs;
    auto lights = makeAreaLights(f, shape, {});
    ASSERT_EQ(lights.size(), 1u);
    // Prolate spheroid (a = 2, b = c = 1): S = 2 pi b^2 (1 + a / (b e) asin e).
    double e = std::sqrt(1.0 - 1.0 / 4.0);
    double area = 2.0 * Pi * (1.0 + 2.0 / e * std::asin(e));
    EXPECT_NEAR(lights[0]->power().x, Pi * area, 2e-3 * Pi * area);

    LightSampleContext ctx;
    ctx.p = Vec3(0.5f, 0.3f, -0.5f);
    ctx.n = Vec3(0, 0, 1);
    auto visible = [&](const LightSample& s, Vec3* p, Vec3* n) {
        if (!hitQuadric(*qs, ctx.p, s.wi, p, n)) return false;
        return std::abs(glm::length(*p - ctx.p) - s.dist) < 1e-3f * s.dist;
    };
    expectPdfConsistent(*lights[0], ctx, 50, visible);
    // Directions of visible samples are distributed as pdfLi; hidden ones (the far side)
    // count as "no sample", whose expected share is 1 - integral of pdfLi.
    chi2::SphereOptions opt;
    opt.thetaRes = 12;
    opt.phiRes = 24;
    opt.sampleCount = 100000;
    opt.integrationEps = 1e-5;
    opt.maxPdfMismatchFraction = 5e-3;  // grazing samples, see expectPdfConsistent
    auto sample = [&](Vec3 u) {
        LightSample s;
        chi2::SphereSample r;
        Vec3 p, n;
        if (lights[0]->sampleLi(ctx, Vec2(u.x, u.y), &s) && visible(s, &p, &n)) {
            r.dir = s.wi;
            r.pdf = s.pdf;
        }
        return r;
    };
    auto pdf = [&](const Vec3& w) {
        Vec3 p, n;
        if (!hitQuadric(*qs, ctx.p, w, &p, &n)) return 0.f;
        return lights[0]->pdfLi(ctx, w, p, n);
    };
    chi2::SphereResult r = chi2::testSphere(sample, pdf, opt);
    EXPECT_TRUE(r.passed) << r.message;
}

TEST(Lights, DiskLightIrradianceOnAxis) {
    Fixture f;
    // Disk of radius R at height h, normals flipped (ReverseOrientation) to face down.
    float R = 1.5f, h = 2.f;
    auto qs = makeQuadricShape(makeDisk(0.f, R), translateMatrix(Vec3(0, 0, h)), true);
    ShapeData shape;
    shape.quadric = qs;
    auto lights = makeAreaLights(f, shape, {rgbParam("L", 4, 4, 4)});
    ASSERT_EQ(lights.size(), 1u);
    LightSampleContext ctx;
    ctx.p = Vec3(0.f);
    ctx.n = Vec3(0, 0, 1);
    expectPdfConsistent(*lights[0], ctx, 60, planeNormal(ctx, Vec3(0, 0, -1)));
    Estimate e = irradiance(*lights[0], ctx, 100000, 61);
    double analytic = Pi * 4.0 * R * R / (h * h + R * R);
    // 5 standard errors: a false failure has probability below 1e-6.
    EXPECT_NEAR(e.mean, analytic, 5.0 * e.stdErr + 1e-5);
    // From above the one-sided disk is dark.
    LightSampleContext above;
    above.p = Vec3(0, 0, 4);
    LightSample s;
    EXPECT_FALSE(lights[0]->sampleLi(above, Vec2(0.4f, 0.4f), &s));
    EXPECT_NEAR(lights[0]->power().x, 4.f * Pi * Pi * R * R, 1e-3f);
}

TEST(Lights, QuadricNormalsFollowTheIntersectionConvention) {
    // A mirrored disk (handedness swap, no ReverseOrientation): shapes.cpp sets flipNormals,
    // and the intersection normal is then -z; the light must emit towards -z as well.
    Fixture f;
    Mat4 m = translateMatrix(Vec3(0, 0, 2)) * scaleMatrix(Vec3(-1.f, 1.f, 1.f));
    ASSERT_TRUE(swapsHandedness(m));
    auto qs = makeQuadricShape(makeDisk(0.f, 1.f), m, true);
    ShapeData shape;
    shape.quadric = qs;
    auto lights = makeAreaLights(f, shape, {});
    LightSampleContext below, above;
    below.p = Vec3(0.1f, 0.f, 0.f);
    above.p = Vec3(0.1f, 0.f, 4.f);
    Vec3 p, n;
    ASSERT_TRUE(hitQuadric(*qs, below.p, Vec3(0, 0, 1), &p, &n));
    EXPECT_NEAR(n.z, -1.f, 1e-6f);
    LightSample s;
    EXPECT_TRUE(lights[0]->sampleLi(below, Vec2(0.2f, 0.6f), &s));
    EXPECT_FALSE(lights[0]->sampleLi(above, Vec2(0.2f, 0.6f), &s));
}

TEST(Lights, CylinderLightPdfConsistent) {
    Fixture f;
    auto qs = makeQuadricShape(makeCylinder(0.5f, -1.f, 1.f),
                               translateMatrix(Vec3(2, 0, 0)) *
                                   rotateMatrix(30.f, Vec3(1, 0, 0)));
    ShapeData shape;
    shape.quadric = qs;
    auto lights = makeAreaLights(f, shape, {boolParam("twosided", true)});
    LightSampleContext ctx;
    ctx.p = Vec3(-1, 0.3f, 0.2f);
    expectPdfConsistent(*lights[0], ctx, 70, [&](const LightSample& s, Vec3* p, Vec3* n) {
        if (!hitQuadric(*qs, ctx.p, s.wi, p, n)) return false;
        return std::abs(glm::length(*p - ctx.p) - s.dist) < 1e-3f * s.dist;
    });
}

}  // namespace
}  // namespace rlpbrt
