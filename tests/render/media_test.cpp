// Participating media: the Henyey-Greenstein phase function (chi-square of its sampling
// against its pdf, normalisation), homogeneous transmittance and free flights, delta and
// ratio tracking against the analytic transmittance of a known density, pbrt-v3's grid
// lookup convention, the vdbvolume medium, and MakeNamedMedium / MediumInterface in scenes.
#include "render/media.h"

#include <gtest/gtest.h>

#include <openvdb/openvdb.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "chi2.h"
#include "render/integrator.h"
#include "render/render.h"
#include "render/scene.h"
#include "render/scene_builder.h"
#include "render/transform.h"

namespace rlpbrt {
namespace {

// ---------------------------------------------------------------------------------------
// Henyey-Greenstein.

class HGChi2 : public ::testing::TestWithParam<float> {};

TEST_P(HGChi2, SampleMatchesPdf) {
    const float g = GetParam();
    const Vec3 wo = glm::normalize(Vec3(0.3f, -0.5f, 0.8f));
    auto sample = [&](const Vec3& u) {
        float pdf;
        Vec3 wi = sampleHenyeyGreenstein(wo, g, Vec2(u.x, u.y), &pdf);
        return chi2::SphereSample{wi, pdf};
    };
    auto pdf = [&](const Vec3& wi) { return henyeyGreenstein(glm::dot(wo, wi), g); };
    chi2::SphereOptions opt;
    opt.sampleCount = 400000;
    opt.numTests = 5;
    opt.seed = uint64_t(1000 * (g + 2.f));
    chi2::SphereResult r = chi2::testSphere(sample, pdf, opt);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdfIntegral, 1.0, 2e-3) << "HG must integrate to 1 over the sphere";
}

INSTANTIATE_TEST_SUITE_P(G, HGChi2, ::testing::Values(-0.7f, -0.3f, 0.f, 0.4f, 0.85f),
                         [](const auto& info) {
                             std::string n = std::to_string(int(std::lround(info.param * 100)));
                             for (char& c : n)
                                 if (c == '-') c = 'm';
                             return "g" + n;
                         });

TEST(HenyeyGreenstein, NormalisedAndForwardForPositiveG) {
    // Quadrature over cos(angle between wo and wi): 2 pi * integral of p d(cos) = 1.
    for (float g : {-0.9f, -0.5f, 0.f, 0.3f, 0.9f}) {
        double sum = 0.0;
        const int n = 200000;
        for (int i = 0; i < n; ++i) {
            double c = -1.0 + (i + 0.5) * 2.0 / n;
            sum += henyeyGreenstein(float(c), g) * (2.0 / n);
        }
        EXPECT_NEAR(2.0 * Pi * sum, 1.0, 1e-3) << "g " << g;
    }
    // pbrt-v3 convention: wo and wi both point away; g > 0 favours wi = -wo (forward).
    Vec3 wo(0, 0, 1);
    EXPECT_GT(henyeyGreenstein(glm::dot(wo, -wo), 0.5f), henyeyGreenstein(glm::dot(wo, wo), 0.5f));
    EXPECT_NEAR(henyeyGreenstein(0.3f, 0.f), Inv4Pi, 1e-7);
    // Sampling with g > 0 goes forward on average.
    double meanCos = 0.0;
    for (int i = 0; i < 10000; ++i) {
        float pdf;
        Vec3 wi = sampleHenyeyGreenstein(wo, 0.6f, Vec2((i + 0.5f) / 10000.f, 0.37f), &pdf);
        meanCos += glm::dot(wi, -wo) / 10000.0;
    }
    EXPECT_NEAR(meanCos, 0.6, 1e-2);  // the mean cosine of HG is g
}

// ---------------------------------------------------------------------------------------
// Statistics helpers.

struct MeanVar {
    double sum = 0, sum2 = 0;
    long long n = 0;
    void add(double x) {
        sum += x;
        sum2 += x * x;
        ++n;
    }
    double mean() const { return sum / double(n); }
    double stderror() const {
        double m = mean();
        return std::sqrt(std::max(0.0, sum2 / double(n) - m * m) / double(n));
    }
};

// ---------------------------------------------------------------------------------------
// Homogeneous.

TEST(HomogeneousMedium, TransmittanceIsBeerLambert) {
    Spectrum sa(0.1f, 0.5f, 1.f), ss(0.2f, 0.f, 1.5f);
    HomogeneousMedium m(sa, ss, 0.f);
    Rng rng(7);
    for (float d : {0.f, 0.3f, 1.f, 4.f}) {
        Spectrum tr = m.tr(Vec3(0.f), Vec3(1, 0, 0), d, rng);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(tr[c], std::exp(-(sa[c] + ss[c]) * d), 1e-6);
    }
    Spectrum inf = m.tr(Vec3(0.f), Vec3(1, 0, 0), Infinity, rng);
    EXPECT_EQ(inf, Spectrum(0.f));
}

TEST(HomogeneousMedium, FreeFlightWeightsAreUnbiased) {
    // E[weight * 1{passed}] = Tr(d); E[weight * 1{scattered}] = integral_0^d Tr(t) sigma_s dt.
    Spectrum sa(0.1f, 0.5f, 1.f), ss(0.2f, 0.3f, 1.5f);
    Spectrum st = sa + ss;
    HomogeneousMedium m(sa, ss, 0.f);
    Rng rng(11);
    const float d = 1.3f;
    MeanVar pass[3], scat[3];
    for (int i = 0; i < 400000; ++i) {
        MediumSample s = m.sample(Vec3(0.f), Vec3(0, 1, 0), d, Vec2(rng.uniform(), rng.uniform()), rng);
        for (int c = 0; c < 3; ++c) {
            pass[c].add(s.scattered ? 0.0 : s.weight[c]);
            scat[c].add(s.scattered ? s.weight[c] : 0.0);
            if (s.scattered) {
                ASSERT_LT(s.t, d);
            }
        }
    }
    for (int c = 0; c < 3; ++c) {
        double tr = std::exp(-st[c] * d);
        double sc = ss[c] / st[c] * (1.0 - tr);
        EXPECT_NEAR(pass[c].mean(), tr, 4.5 * pass[c].stderror() + 1e-9) << "channel " << c;
        EXPECT_NEAR(scat[c].mean(), sc, 4.5 * scat[c].stderror() + 1e-9) << "channel " << c;
    }
}

// ---------------------------------------------------------------------------------------
// Grid medium: lookup convention and trackers.

TEST(GridMedium, LookupConventionIsPbrtV3) {
    // 3 x 2 x 2 values, x fastest: value(i, j, k) = 100 k + 10 j + i + 1.
    std::vector<float> d;
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 3; ++i) d.push_back(float(100 * k + 10 * j + i + 1));
    GridMedium m(Spectrum(1.f), Spectrum(1.f), 0.f, Mat4(1.f), 3, 2, 2, d);
    // Cell centres hold the values.
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 3; ++i) {
                Vec3 p((i + 0.5f) / 3.f, (j + 0.5f) / 2.f, (k + 0.5f) / 2.f);
                EXPECT_NEAR(m.density(p), 100 * k + 10 * j + i + 1, 1e-3) << i << j << k;
            }
    // Trilinear between centres.
    Vec3 mid((0.5f + 0.5f) / 3.f, 0.25f, 0.25f);  // halfway between i = 0 and i = 1
    EXPECT_NEAR(m.density(mid), 1.5f, 1e-4);
    // Samples outside the grid read 0: at the corner (0,0,0) only 1/8 of value(0,0,0).
    EXPECT_NEAR(m.density(Vec3(0.f)), 1.f / 8.f, 1e-5);
    EXPECT_NEAR(m.density(Vec3(1.f, 0.25f, 0.25f)), 3.f / 2.f, 1e-4);  // half of value(2,0,0)
    EXPECT_EQ(m.D(-1, 0, 0), 0.f);
    EXPECT_EQ(m.D(3, 0, 0), 0.f);
    EXPECT_EQ(m.D(2, 1, 1), 113.f);
    EXPECT_EQ(m.maxDensity(), 113.f);
}

// A 2x1x1 grid gives a known piecewise-linear density along the line y = z = 0.5:
// 0 at x = -0.25, d0 at 0.25, d1 at 0.75, 0 at 1.25. Its optical depth from x = a to b.
double rampDepth(double d0, double d1, double a, double b) {
    auto dens = [&](double x) {
        if (x <= 0.25) return d0 * (x + 0.25) / 0.5;
        if (x <= 0.75) return d0 + (d1 - d0) * (x - 0.25) / 0.5;
        return d1 * (1.25 - x) / 0.5;
    };
    const int n = 100000;
    double s = 0;
    for (int i = 0; i < n; ++i) s += dens(a + (i + 0.5) * (b - a) / n);
    return s * (b - a) / n;
}

struct TrackCase {
    const char* name;
    float ox, len;  // start x and segment length along +x (local = world up to the scale)
};

class GridTracking : public ::testing::TestWithParam<TrackCase> {};

TEST_P(GridTracking, TrackersMatchAnalyticTransmittance) {
    const TrackCase c = GetParam();
    const float d0 = 0.3f, d1 = 1.f;
    const Spectrum sa(0.5f), ss(1.5f);  // sigma_t = 2
    // World = local scaled by 2 along x, shifted: the world ray covers 2 * len.
    Mat4 worldFromLocal = translateMatrix(Vec3(5.f, 0.f, 0.f)) * scaleMatrix(Vec3(2.f, 1.f, 1.f));
    GridMedium m(sa, ss, 0.f, worldFromLocal, 2, 1, 1, {d0, d1});
    Vec3 o(5.f + 2.f * c.ox, 0.5f, 0.5f), dir(1, 0, 0);
    float tMax = 2.f * c.len;
    double tau = 2.0 /*sigma_t*/ * 2.0 /*x scale*/ *
                 rampDepth(d0, d1, std::max(0.f, c.ox), std::min(1.f, c.ox + c.len));
    double expected = std::exp(-tau);
    Rng rng(123);
    MeanVar ratio, delta, scatterWeight;
    for (int i = 0; i < 200000; ++i) {
        ratio.add(m.tr(o, dir, tMax, rng)[0]);
        MediumSample s = m.sample(o, dir, tMax, Vec2(rng.uniform(), rng.uniform()), rng);
        delta.add(s.scattered ? 0.0 : 1.0);
        if (s.scattered) {
            ASSERT_LT(s.t, tMax);
            scatterWeight.add(s.weight[0]);
        }
    }
    EXPECT_NEAR(ratio.mean(), expected, 4.5 * ratio.stderror() + 1e-6) << "ratio tracking";
    EXPECT_NEAR(delta.mean(), expected, 4.5 * delta.stderror() + 1e-6) << "delta tracking";
    if (scatterWeight.n) {
        EXPECT_NEAR(scatterWeight.mean(), 0.75, 1e-6);  // sigma_s / sigma_t
    }
}

INSTANTIATE_TEST_SUITE_P(Segments, GridTracking,
                         ::testing::Values(TrackCase{"Inside", 0.25f, 0.5f},
                                           TrackCase{"Crossing", -1.f, 3.f},
                                           TrackCase{"EndsInside", -0.5f, 1.1f},
                                           TrackCase{"StartsInside", 0.6f, 10.f}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(GridMedium, MajorantGridBoundsTheDensity) {
    // Random sparse data: every point of a majorant cell has density <= the cell's bound.
    const int nx = 13, ny = 9, nz = 6;
    Rng rng(99);
    std::vector<float> d(size_t(nx * ny * nz));
    for (float& v : d) v = rng.uniform() < 0.2f ? 3.f * rng.uniform() : 0.f;
    GridMedium m(Spectrum(1.f), Spectrum(1.f), 0.f, Mat4(1.f), nx, ny, nz, d);
    glm::ivec3 res = m.majorantResolution();
    EXPECT_EQ(res, glm::ivec3(4, 3, 2));
    for (int i = 0; i < 200000; ++i) {
        Vec3 p(rng.uniform(), rng.uniform(), rng.uniform());
        glm::ivec3 c = glm::min(glm::ivec3(p * Vec3(res)), res - 1);
        ASSERT_LE(m.density(p), m.majorant(c.x, c.y, c.z) + 1e-6f) << p.x << " " << p.y << " " << p.z;
    }
}

TEST(GridMedium, RayMissingTheBoxIsUnattenuated) {
    GridMedium m(Spectrum(1.f), Spectrum(1.f), 0.f, Mat4(1.f), 1, 1, 1, {1.f});
    Rng rng(3);
    EXPECT_EQ(m.tr(Vec3(2, 2, 2), Vec3(1, 0, 0), 10.f, rng), Spectrum(1.f));
    EXPECT_FALSE(m.sample(Vec3(2, 2, 2), Vec3(1, 0, 0), 10.f, Vec2(0.5f), rng).scattered);
    // Segment ending before the box.
    EXPECT_EQ(m.tr(Vec3(-5, 0.5f, 0.5f), Vec3(1, 0, 0), 4.f, rng), Spectrum(1.f));
}

// ---------------------------------------------------------------------------------------
// Scenes: MakeNamedMedium / MediumInterface.

std::string writeTemp(const std::string& name, const std::string& text) {
    std::string path = (std::filesystem::temp_directory_path() / name).string();
    std::ofstream(path) << text;
    return path;
}

std::unique_ptr<Scene> buildFrom(const std::string& path, Diagnostics& diag) {
    SceneDesc desc;
    if (!loadSceneDesc(path, diag, &desc)) return nullptr;
    return buildScene(desc, BuildOptions(), diag);
}

TEST(MediaScene, InterfaceCameraAndTypes) {
    std::string path = writeTemp("rlpbrt_media_scene.pbrt", R"(
Integrator "volpath"
MakeNamedMedium "fog" "string type" "homogeneous" "rgb sigma_a" [1 1 1] "rgb sigma_s" [2 2 2]
  "float scale" 0.5 "float g" 0.3
MakeNamedMedium "grid" "string type" "heterogeneous" "integer nx" 2 "integer ny" 1
  "integer nz" 1 "float density" [0.5 1] "point p0" [-1 -1 -1] "point p1" [1 1 1]
MediumInterface "" "fog"
Camera "perspective"
WorldBegin
LightSource "point" "rgb I" [1 1 1]
AttributeBegin
  Material ""
  MediumInterface "grid" "fog"
  Shape "sphere" "float radius" 1
AttributeEnd
Translate 0 0 5
Shape "sphere" "float radius" 0.5
Translate 0 0 5
MediumInterface "fog" "fog"
Shape "sphere" "float radius" 0.5
WorldEnd
)");
    Diagnostics diag;
    diag.setStream(nullptr);
    std::unique_ptr<Scene> scene = buildFrom(path, diag);
    ASSERT_NE(scene, nullptr);
    EXPECT_EQ(diag.errorCount(), 0);
    ASSERT_EQ(scene->media.size(), 2u);
    EXPECT_EQ(scene->cameraMedium, 0);
    EXPECT_NEAR(scene->media[0]->g(), 0.3f, 1e-6);
    // Closed-form homogeneous: sigma_t = (1 + 2) * 0.5.
    Rng rng(1);
    EXPECT_NEAR(scene->media[0]->tr(Vec3(0.f), Vec3(1, 0, 0), 2.f, rng)[1], std::exp(-3.f), 1e-6);
    // The boundary sphere: inside "grid" (1), outside "fog" (0), interface only.
    SurfaceInteraction si;
    ASSERT_TRUE(scene->intersect(Ray(Vec3(0, 0, -3), Vec3(0, 0, 1)), &si));
    EXPECT_EQ(si.material, -1);
    EXPECT_EQ(si.mediumInside, 1);
    EXPECT_EQ(si.mediumOutside, 0);
    EXPECT_EQ(si.mediumAfter(Vec3(0, 0, 1), 0), 1);   // entering
    EXPECT_EQ(si.mediumAfter(Vec3(0, 0, -1), 1), 0);  // leaving
    // The second sphere keeps the interface "" / "fog" set before the Camera (the graphics
    // state outlives WorldBegin, as in pbrt-v3).
    ASSERT_TRUE(scene->intersect(Ray(Vec3(0, 0, 2), Vec3(0, 0, 1)), &si));
    EXPECT_GE(si.material, 0);
    EXPECT_EQ(si.mediumInside, -1);
    EXPECT_EQ(si.mediumOutside, 0);
    // The third sphere has the same medium on both sides: it keeps the ray's medium.
    ASSERT_TRUE(scene->intersect(Ray(Vec3(0, 0, 7), Vec3(0, 0, 1)), &si));
    EXPECT_FALSE(si.isMediumTransition());
    EXPECT_EQ(si.mediumAfter(Vec3(0, 0, -1), 1), 1);
}

// "preset" names pbrt-v3's measured media (Ketchup: sigma_a (0.061, 0.97, 1.45), sigma'_s
// (0.18, 0.07, 0.03) per mm); sigma_a, sigma_s and scale apply on top, as in pbrt-v3; an
// unknown name keeps the defaults with a located warning.
TEST(MediaScene, PresetsAreMeasuredMedia) {
    std::string path = writeTemp("rlpbrt_media_preset.pbrt", R"(
Integrator "volpath"
MakeNamedMedium "ketchup" "string type" "homogeneous" "string preset" "Ketchup"
  "float scale" 2
MakeNamedMedium "odd" "string type" "homogeneous" "string preset" "Gravy"
WorldBegin
LightSource "point" "rgb I" [1 1 1]
AttributeBegin
  MediumInterface "ketchup" ""
  Material ""
  Shape "sphere"
AttributeEnd
MediumInterface "odd" ""
Material ""
Shape "sphere" "float radius" 2
WorldEnd
)");
    Diagnostics diag;
    std::ostringstream out;
    diag.setStream(&out);
    std::unique_ptr<Scene> scene = buildFrom(path, diag);
    ASSERT_NE(scene, nullptr);
    EXPECT_EQ(diag.errorCount(), 0);
    ASSERT_EQ(scene->media.size(), 2u);
    Rng rng(1);
    // Blue: sigma_t = 2 x (1.45 + 0.03) over a unit distance.
    EXPECT_NEAR(scene->media[0]->tr(Vec3(0.f), Vec3(1, 0, 0), 1.f, rng)[2],
                std::exp(-2.f * 1.48f), 1e-5);
    // The defaults: sigma_t (2.5511, 3.2124, 3.784) in red, green, blue.
    EXPECT_NEAR(scene->media[1]->tr(Vec3(0.f), Vec3(1, 0, 0), 1.f, rng)[0],
                std::exp(-(0.0011f + 2.55f)), 1e-5);
    EXPECT_NE(out.str().find("rlpbrt_media_preset.pbrt:5:"), std::string::npos) << out.str();
    EXPECT_NE(out.str().find("Gravy"), std::string::npos) << out.str();
}

TEST(MediaScene, PathIntegratorIgnoresMediaAsPbrtV3) {
    std::string path = writeTemp("rlpbrt_media_path.pbrt", R"(
MakeNamedMedium "fog" "string type" "homogeneous"
WorldBegin
LightSource "point" "rgb I" [1 1 1]
MediumInterface "fog" ""
Shape "sphere"
WorldEnd
)");
    Diagnostics diag;
    std::ostringstream out;
    diag.setStream(&out);
    std::unique_ptr<Scene> scene = buildFrom(path, diag);
    ASSERT_NE(scene, nullptr);
    EXPECT_TRUE(scene->media.empty());
    EXPECT_NE(out.str().find("ignores participating media"), std::string::npos) << out.str();
}

TEST(MediaScene, BadMediaAreLocatedErrors) {
    struct Case {
        const char* text;
        const char* loc;
        const char* message;
    } cases[] = {
        {"Integrator \"volpath\"\nMakeNamedMedium \"m\" \"string type\" \"heterogeneous\" "
         "\"integer nx\" 3\n  \"float density\" [1 2]\nWorldBegin\nWorldEnd\n",
         ":3:3: error:", "has 2 density values; expected nx*ny*nz = 3"},
        {"MakeNamedMedium \"m\" \"string type\" \"cloudy\"\nWorldBegin\nWorldEnd\n", ":1:1: error:",
         "unknown medium type \"cloudy\""},
        {"WorldBegin\nMediumInterface \"nope\" \"\"\nShape \"sphere\"\nWorldEnd\n", ":2:1: error:",
         "undefined medium \"nope\""},
        {"MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"float g\" 1.5\nWorldBegin\n"
         "WorldEnd\n", ":1:49: error:", "g must be in (-1, 1)"},
    };
    int i = 0;
    for (const Case& c : cases) {
        std::string path = writeTemp("rlpbrt_media_bad" + std::to_string(i++) + ".pbrt", c.text);
        Diagnostics diag;
        std::ostringstream out;
        diag.setStream(&out);
        std::unique_ptr<Scene> scene = buildFrom(path, diag);
        EXPECT_EQ(scene, nullptr) << c.text;
        EXPECT_NE(out.str().find(path + c.loc), std::string::npos) << out.str();
        EXPECT_NE(out.str().find(c.message), std::string::npos) << out.str();
    }
}

// End to end: the camera in a purely absorbing fog looks at an emitter of radiance 1 at
// distance 2 (camera medium from MediumInterface before Camera, delta tracking, passage
// weights): every pixel expects exp(-sigma_a * 2). With scattering added and the emitter
// still the only light, the mean can only fall.
double renderMean(const std::string& sigmaS, int spp) {
    std::string path = writeTemp("rlpbrt_media_e2e.pbrt", R"(
Film "image" "integer xresolution" 8 "integer yresolution" 8
Sampler "random" "integer pixelsamples" )" + std::to_string(spp) + R"(
Integrator "volpath" "integer maxdepth" 5
MakeNamedMedium "fog" "string type" "homogeneous" "rgb sigma_a" [.5 .5 .5]
  "rgb sigma_s" [)" + sigmaS + R"(]
MediumInterface "" "fog"
Camera "perspective" "float fov" 10
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 1 1]
  Translate 0 0 2
  Shape "trianglemesh" "point P" [-5 -5 0 5 -5 0 5 5 0 -5 5 0] "integer indices" [0 2 1 0 3 2]
AttributeEnd
WorldEnd
)");
    Diagnostics diag;
    diag.setStream(nullptr);
    std::unique_ptr<Scene> scene = buildFrom(path, diag);
    if (!scene) return -1.0;
    RenderOptions ro;
    ro.nThreads = 1;
    RenderResult r = render(*scene, ro);
    double sum = 0;
    for (int y = 0; y < r.image.height; ++y)
        for (int x = 0; x < r.image.width; ++x) sum += r.image.at(x, y, 1);
    return sum / double(r.image.width * r.image.height);
}

TEST(MediaRender, CameraInAbsorbingFogSeesBeerLambert) {
    double mean = renderMean(".0 .0 .0", 256);
    // 16384 binary pass/absorb samples: standard error sqrt(T (1 - T) / n) ~ 0.004.
    EXPECT_NEAR(mean, std::exp(-1.0), 0.02);
    double scattering = renderMean(".5 .5 .5", 64);
    EXPECT_GT(scattering, 0.0);
    EXPECT_LT(scattering, mean);
}

// Through medium boundaries: a camera in vacuum sees an emitter through an absorbing
// sphere of radius 1 (Material "", MediumInterface "ball" ""), and a floor lit by a point
// light whose shadow rays cross another such sphere (direct light only). Both see
// exp(-sigma_a * 2) of the unattenuated value (fov 1 degree: chords within 0.2% of 2).
double boundaryMean(const std::string& type, float scale, bool shadow) {
    std::string medium =
        type == "homogeneous"
            ? "\"string type\" \"homogeneous\" \"rgb sigma_a\" [.5 .5 .5] \"rgb sigma_s\" [0 0 0]"
            : "\"string type\" \"heterogeneous\" \"integer nx\" 1 \"integer ny\" 1 "
              "\"integer nz\" 5 \"float density\" [0 1 1 1 0] \"point p0\" [-4 -4 -5] "
              "\"point p1\" [4 4 5] \"rgb sigma_a\" [.5 .5 .5] \"rgb sigma_s\" [0 0 0]";
    // The 1x1x5 grid's samples sit at z = -4, -2, 0, 2, 4: density 1 for |z| <= 2 (and
    // within 0.5% of 1 near the axis x = y = 0), so the ball of radius 1 sees density 1.
    std::string world =
        shadow ? R"(
LightSource "point" "rgb I" [10 10 10] "point from" [0 0 4]
Material "matte" "rgb Kd" [.5 .5 .5]
Shape "trianglemesh" "point P" [-9 -9 0 9 -9 0 9 9 0 -9 9 0] "integer indices" [0 1 2 0 2 3]
AttributeBegin
  Material ""
  MediumInterface "ball" ""
  Translate 0 0 2
  Shape "sphere" "float radius" 1
AttributeEnd
)"
               : R"(
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 1 1]
  Translate 0 0 -3
  Shape "trianglemesh" "point P" [-5 -5 0 5 -5 0 5 5 0 -5 5 0] "integer indices" [0 1 2 0 2 3]
AttributeEnd
AttributeBegin
  Material ""
  MediumInterface "ball" ""
  Shape "sphere" "float radius" 1
AttributeEnd
)";
    std::string camera = shadow ? "LookAt 5 0 0.5  0 0 0  0 0 1\n" : "LookAt 0 0 5  0 0 0  0 1 0\n";
    std::string path = writeTemp("rlpbrt_media_boundary.pbrt", R"(
Film "image" "integer xresolution" 8 "integer yresolution" 8
Sampler "random" "integer pixelsamples" 64
Integrator "volpath" "integer maxdepth" 1
)" + (shadow ? std::string("Translate 0 0 2\n") : std::string()) +
        "MakeNamedMedium \"ball\" " + medium + " \"float scale\" " + std::to_string(scale) +
        "\n" + (shadow ? std::string("Identity\n") : std::string()) + camera +
        "Camera \"perspective\" \"float fov\" 1\nWorldBegin\n" + world + "WorldEnd\n");
    Diagnostics diag;
    std::ostringstream out;
    diag.setStream(&out);
    std::unique_ptr<Scene> scene = buildFrom(path, diag);
    EXPECT_NE(scene, nullptr) << out.str();
    if (!scene) return -1.0;
    RenderOptions ro;
    ro.nThreads = 1;
    RenderResult r = render(*scene, ro);
    double sum = 0;
    for (int y = 0; y < r.image.height; ++y)
        for (int x = 0; x < r.image.width; ++x) sum += r.image.at(x, y, 1);
    return sum / double(r.image.width * r.image.height);
}

TEST(MediaRender, TransmittanceThroughBoundaries) {
    for (const char* type : {"homogeneous", "heterogeneous"})
        for (bool shadow : {false, true}) {
            double clear = boundaryMean(type, 0.f, shadow);
            double fog = boundaryMean(type, 1.f, shadow);
            ASSERT_GT(clear, 0.0) << type << " shadow " << shadow;
            // Homogeneous shadow rays are exact; delta/ratio tracking over 4096 paths:
            // a few percent.
            EXPECT_NEAR(fog / clear, std::exp(-1.0), 0.03) << type << " shadow " << shadow;
        }
}

// ---------------------------------------------------------------------------------------
// vdbvolume.

// Writes a vdb file with a float grid "density": value v in index box [0, n-1]^3, voxel
// size `voxel`.
std::string writeVdb(const std::string& name, int n, float v, double voxel) {
    openvdb::initialize();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.f);
    grid->setName("density");
    grid->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    grid->fill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(n - 1)), v, true);
    std::string path = (std::filesystem::temp_directory_path() / name).string();
    openvdb::io::File file(path);
    openvdb::GridPtrVec grids{grid};
    file.write(grids);
    file.close();
    return path;
}

TEST(VdbMedium, ConstantBlockTransmittance) {
    std::string vdb = writeVdb("rlpbrt_media_block.vdb", 10, 0.5f, 0.1);
    std::string path = writeTemp("rlpbrt_media_vdb.pbrt",
                                 "Integrator \"volpath\"\nTranslate 3 0 0\n"
                                 "MakeNamedMedium \"c\" \"string type\" \"vdbvolume\" "
                                 "\"string filename\" \"" + vdb + "\" \"rgb sigma_a\" [1 1 1] "
                                 "\"rgb sigma_s\" [3 3 3]\nWorldBegin\n"
                                 "LightSource \"point\" \"rgb I\" [1 1 1]\nWorldEnd\n");
    Diagnostics diag;
    std::ostringstream out;
    diag.setStream(&out);
    std::unique_ptr<Scene> scene = buildFrom(path, diag);
    ASSERT_NE(scene, nullptr) << out.str();
    ASSERT_EQ(scene->media.size(), 1u);
    // Voxel centres 0..9 at world x = 3 + 0.1 i; between centres 1 and 8 the density is 0.5.
    Rng rng(5);
    MeanVar tr;
    Vec3 o(3.1f, 0.45f, 0.45f);
    for (int i = 0; i < 100000; ++i) tr.add(scene->media[0]->tr(o, Vec3(1, 0, 0), 0.7f, rng)[0]);
    double expected = std::exp(-4.0 * 0.5 * 0.7);
    EXPECT_NEAR(tr.mean(), expected, 4.5 * tr.stderror() + 1e-6);
    // Outside the active voxels (beyond the one-voxel filter margin): no extinction.
    EXPECT_EQ(scene->media[0]->tr(Vec3(3.f, 5.f, 0.45f), Vec3(1, 0, 0), 2.f, rng), Spectrum(1.f));
}

TEST(VdbMedium, SameMediumAsTheEquivalentHeterogeneousGrid) {
    // docs/MEDIA.md's recipe: voxel i holds sample i, the transform scales by (p1 - p0) / n
    // and translates to p0 + 0.5 (p1 - p0) / n. Both media must then have the same
    // transmittance along any ray (compared through ratio-tracking means).
    const int nx = 6, ny = 5, nz = 4;
    const Vec3 p0(-1.f, 0.f, 0.f), p1(1.f, 1.f, 2.f);
    Rng rng(17);
    std::vector<float> d(size_t(nx * ny * nz));
    // The outer samples are 0: the grid medium ends at [p0, p1] (half a cell beyond its
    // outer samples) while the vdb field goes on to a whole voxel beyond its active voxels.
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                bool inner = i > 0 && j > 0 && k > 0 && i < nx - 1 && j < ny - 1 && k < nz - 1;
                float u = rng.uniform(), v = rng.uniform();
                d[size_t((k * ny + j) * nx + i)] = inner && u < 0.8f ? 2.f * v : 0.f;
            }
    openvdb::initialize();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.f);
    grid->setName("density");
    Vec3 s = (p1 - p0) / Vec3(float(nx), float(ny), float(nz)), t = p0 + 0.5f * s;
    openvdb::math::Mat4d m(double(s.x), 0., 0., 0., 0., double(s.y), 0., 0., 0., 0., double(s.z),
                           0., double(t.x), double(t.y), double(t.z), 1.);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(m));
    auto acc = grid->getAccessor();
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                if (float v = d[size_t((k * ny + j) * nx + i)]; v != 0.f)
                    acc.setValue(openvdb::Coord(i, j, k), v);
    std::string vdb = (std::filesystem::temp_directory_path() / "rlpbrt_media_equiv.vdb").string();
    {
        openvdb::io::File file(vdb);
        file.write(openvdb::GridPtrVec{grid});
        file.close();
    }
    std::string density;
    for (float v : d) density += std::to_string(v) + " ";
    std::string path = writeTemp(
        "rlpbrt_media_equiv.pbrt",
        "Integrator \"volpath\"\nRotate 30 0 1 1\n"
        "MakeNamedMedium \"a\" \"string type\" \"heterogeneous\" \"integer nx\" 6 "
        "\"integer ny\" 5 \"integer nz\" 4 \"point p0\" [-1 0 0] \"point p1\" [1 1 2] "
        "\"float density\" [" + density + "] \"rgb sigma_a\" [1 1 1] \"rgb sigma_s\" [1 1 1]\n"
        "MakeNamedMedium \"b\" \"string type\" \"vdbvolume\" \"string filename\" \"" + vdb +
        "\" \"rgb sigma_a\" [1 1 1] \"rgb sigma_s\" [1 1 1]\nWorldBegin\n"
        "LightSource \"point\" \"rgb I\" [1 1 1]\nWorldEnd\n");
    Diagnostics diag;
    std::ostringstream out;
    diag.setStream(&out);
    std::unique_ptr<Scene> scene = buildFrom(path, diag);
    ASSERT_NE(scene, nullptr) << out.str();
    ASSERT_EQ(scene->media.size(), 2u);
    for (int r = 0; r < 6; ++r) {
        Vec3 o(4.f * rng.uniform() - 2.f, 4.f * rng.uniform() - 2.f, -3.f);
        Vec3 target(rng.uniform() - 0.5f, rng.uniform(), 2.f * rng.uniform());
        Vec3 dir = glm::normalize(target - o);
        MeanVar a, b;
        for (int i = 0; i < 40000; ++i) {
            a.add(scene->media[0]->tr(o, dir, 10.f, rng)[0]);
            b.add(scene->media[1]->tr(o, dir, 10.f, rng)[0]);
        }
        double se = std::hypot(a.stderror(), b.stderror());
        EXPECT_NEAR(a.mean(), b.mean(), 5.0 * se + 1e-6) << "ray " << r;
    }
}

TEST(VdbMedium, MissingGridIsLocatedError) {
    std::string vdb = writeVdb("rlpbrt_media_block2.vdb", 2, 1.f, 1.0);
    std::string path = writeTemp("rlpbrt_media_vdb_bad.pbrt",
                                 "MakeNamedMedium \"c\" \"string type\" \"vdbvolume\" "
                                 "\"string filename\" \"" + vdb + "\" \"string grid\" \"smoke\"\n"
                                 "WorldBegin\nWorldEnd\n");
    Diagnostics diag;
    std::ostringstream out;
    diag.setStream(&out);
    EXPECT_EQ(buildFrom(path, diag), nullptr);
    EXPECT_NE(out.str().find(path + ":1:47: error:"), std::string::npos) << out.str();
    EXPECT_NE(out.str().find("has no grid \"smoke\" (grids: \"density\")"), std::string::npos)
        << out.str();
}

}  // namespace
}  // namespace rlpbrt
