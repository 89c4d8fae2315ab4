// Tests for textures, texture mappings, MIP maps, Perlin noise and bump mapping.
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "render/image_io.h"
#include "render/mipmap.h"
#include "render/noise.h"
#include "render/textures.h"

namespace rlpbrt {
namespace {

// ---------------------------------------------------------------------------------------------
// Helpers.

Param numParam(ParamType type, const std::string& name, std::vector<double> values) {
    Param p;
    p.type = type;
    p.name = name;
    p.numbers = std::move(values);
    return p;
}
Param floatParam(const std::string& name, double v) {
    return numParam(ParamType::Float, name, {v});
}
Param intParam(const std::string& name, int v) {
    return numParam(ParamType::Integer, name, {double(v)});
}
Param rgbParam(const std::string& name, Spectrum c) {
    return numParam(ParamType::RGB, name, {c.x, c.y, c.z});
}
Param stringParam(const std::string& name, const std::string& v,
                  ParamType type = ParamType::String) {
    Param p;
    p.type = type;
    p.name = name;
    p.strings = {v};
    return p;
}
Param textureParam(const std::string& name, const std::string& tex) {
    return stringParam(name, tex, ParamType::Texture);
}
Param boolParam(const std::string& name, bool v) {
    Param p;
    p.type = ParamType::Bool;
    p.name = name;
    p.bools = {uint8_t(v)};
    return p;
}

ParamList makeParams(std::vector<Param> ps) {
    ParamList list;
    for (auto& p : ps) list.add(std::move(p));
    return list;
}

// A float texture defined by a function of the context (for bump mapping tests).
class FunctionTexture : public FloatTexture {
public:
    explicit FunctionTexture(std::function<float(const TextureContext&)> f) : f_(std::move(f)) {}
    float evaluate(const TextureContext& ctx) const override { return f_(ctx); }

private:
    std::function<float(const TextureContext&)> f_;
};

// Resolves "texture" parameters from two maps, inline floats and rgb values as constants.
class TestResolver : public TextureResolver {
public:
    std::shared_ptr<FloatTexture> floatTex(const ParamList& ps, const std::string& name,
                                           float def) override {
        const Param* p = ps.find(name);
        if (p && p->type == ParamType::Texture) return floats.at(ps.getTexture(name));
        return std::make_shared<ConstantFloatTexture>(ps.getFloat(name, def));
    }
    std::shared_ptr<SpectrumTexture> spectrumTex(const ParamList& ps, const std::string& name,
                                                 Spectrum def) override {
        const Param* p = ps.find(name);
        if (p && p->type == ParamType::Texture) return spectra.at(ps.getTexture(name));
        if (const Param* s = ps.getSpectral(name))
            return std::make_shared<ConstantSpectrumTexture>(
                Spectrum(s->numbers[0], s->numbers[1], s->numbers[2]));
        return std::make_shared<ConstantSpectrumTexture>(def);
    }
    std::map<std::string, std::shared_ptr<FloatTexture>> floats;
    std::map<std::string, std::shared_ptr<SpectrumTexture>> spectra;
};

std::shared_ptr<FloatTexture> makeFloat(const std::string& type, std::vector<Param> ps,
                                        TestResolver& r, const Mat4& m = Mat4(1.f),
                                        MipMapCache* cache = nullptr) {
    std::string err;
    ParamList list = makeParams(std::move(ps));
    auto t = createFloatTexture(type, list, m, r, &err, cache);
    EXPECT_TRUE(t) << err;
    return t;
}

std::shared_ptr<SpectrumTexture> makeSpectrum(const std::string& type, std::vector<Param> ps,
                                              TestResolver& r, const Mat4& m = Mat4(1.f),
                                              MipMapCache* cache = nullptr) {
    std::string err;
    ParamList list = makeParams(std::move(ps));
    auto t = createSpectrumTexture(type, list, m, r, &err, cache);
    EXPECT_TRUE(t) << err;
    return t;
}

TextureContext atUV(float u, float v, float dudx = 0, float dvdy = 0) {
    TextureContext ctx;
    ctx.uv = Vec2(u, v);
    ctx.dudx = dudx;
    ctx.dvdy = dvdy;
    return ctx;
}

TextureContext atP(const Vec3& p) {
    TextureContext ctx;
    ctx.p = p;
    return ctx;
}

void expectSpectrumNear(const Spectrum& a, const Spectrum& b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

// Writes a float image (row-major, top row first) with OpenImageIO; 8-bit if `uint8`.
std::string writeImage(const std::string& name, int w, int h, int channels,
                       const std::vector<float>& pixels, bool uint8) {
    std::string path = ::testing::TempDir() + "rlpbrt_textures_test_" + name;
    auto out = OIIO::ImageOutput::create(path);
    EXPECT_TRUE(out) << OIIO::geterror();
    if (!out) return path;
    OIIO::ImageSpec spec(w, h, channels, uint8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    EXPECT_TRUE(out->open(path, spec)) << out->geterror();
    EXPECT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) << out->geterror();
    out->close();
    return path;
}

// ---------------------------------------------------------------------------------------------
// Simple textures.

TEST(Textures, ConstantFloatAndSpectrum) {
    TestResolver r;
    auto f = makeFloat("constant", {floatParam("value", 0.25)}, r);
    EXPECT_FLOAT_EQ(f->evaluate(atUV(0.3f, 0.7f)), 0.25f);
    EXPECT_NE(dynamic_cast<ConstantFloatTexture*>(f.get()), nullptr);
    auto s = makeSpectrum("constant", {rgbParam("value", {0.1f, 0.2f, 0.3f})}, r);
    expectSpectrumNear(s->evaluate(atUV(0, 0)), {0.1f, 0.2f, 0.3f}, 1e-6f);
    auto d = makeFloat("constant", {}, r);
    EXPECT_FLOAT_EQ(d->evaluate(atUV(0, 0)), 1.f);  // pbrt-v3 default value 1
}

TEST(Textures, ScaleMixArithmetic) {
    TestResolver r;
    auto scale = makeFloat("scale", {floatParam("tex1", 3), floatParam("tex2", 0.5)}, r);
    EXPECT_FLOAT_EQ(scale->evaluate(atUV(0, 0)), 1.5f);
    auto sscale = makeSpectrum(
        "scale", {rgbParam("tex1", {1, 2, 3}), rgbParam("tex2", {0.5f, 0.5f, 2})}, r);
    expectSpectrumNear(sscale->evaluate(atUV(0, 0)), {0.5f, 1, 6}, 1e-6f);

    // amount from a texture: u itself, via a bilerp of (0, 0, 1, 1).
    r.floats["u"] = makeFloat("bilerp", {floatParam("v00", 0), floatParam("v01", 0),
                                         floatParam("v10", 1), floatParam("v11", 1)}, r);
    auto mix = makeFloat("mix", {floatParam("tex1", 2), floatParam("tex2", 4),
                                 textureParam("amount", "u")}, r);
    EXPECT_FLOAT_EQ(mix->evaluate(atUV(0.25f, 0.9f)), 2.5f);
    auto smix = makeSpectrum("mix", {rgbParam("tex1", {1, 0, 0}), rgbParam("tex2", {0, 0, 1}),
                                     floatParam("amount", 0.25)}, r);
    expectSpectrumNear(smix->evaluate(atUV(0, 0)), {0.75f, 0, 0.25f}, 1e-6f);
    auto dmix = makeFloat("mix", {}, r);  // defaults 0, 1, amount 0.5
    EXPECT_FLOAT_EQ(dmix->evaluate(atUV(0, 0)), 0.5f);
}

TEST(Textures, BilerpArithmetic) {
    TestResolver r;
    auto b = makeFloat("bilerp", {floatParam("v00", 1), floatParam("v01", 2),
                                  floatParam("v10", 3), floatParam("v11", 5)}, r);
    // (1-s)(1-t) v00 + (1-s) t v01 + s (1-t) v10 + s t v11 at (0.25, 0.5).
    float expected = 0.75f * 0.5f * 1 + 0.75f * 0.5f * 2 + 0.25f * 0.5f * 3 + 0.25f * 0.5f * 5;
    EXPECT_FLOAT_EQ(b->evaluate(atUV(0.25f, 0.5f)), expected);
    EXPECT_FLOAT_EQ(b->evaluate(atUV(0, 1)), 2.f);
    auto d = makeFloat("bilerp", {}, r);  // pbrt-v3 defaults: 0, 1, 0, 1 -> t
    EXPECT_FLOAT_EQ(d->evaluate(atUV(0.3f, 0.6f)), 0.6f);
    auto s = makeSpectrum("bilerp", {rgbParam("v00", {1, 0, 0}), rgbParam("v01", {0, 1, 0}),
                                     rgbParam("v10", {0, 0, 1}), rgbParam("v11", {1, 1, 1})},
                          r);
    expectSpectrumNear(s->evaluate(atUV(1, 0)), {0, 0, 1}, 1e-6f);
    expectSpectrumNear(s->evaluate(atUV(0.5f, 0.5f)), {0.5f, 0.5f, 0.5f}, 1e-6f);
}

TEST(Textures, UVMappingValues) {
    TestResolver r;
    auto uv = makeSpectrum("uv", {floatParam("uscale", 2), floatParam("vscale", 3),
                                  floatParam("udelta", 0.5), floatParam("vdelta", 0.25)}, r);
    // s = 2 * 0.3 + 0.5 = 1.1 -> 0.1; t = 3 * 0.4 + 0.25 = 1.45 -> 0.45.
    expectSpectrumNear(uv->evaluate(atUV(0.3f, 0.4f)), {0.1f, 0.45f, 0}, 1e-5f);

    UVMapping2D m(2, 3, 0.5f, 0.25f);
    TextureContext ctx = atUV(0.3f, 0.4f);
    ctx.dudx = 0.1f;
    ctx.dvdx = 0.2f;
    ctx.dudy = 0.3f;
    ctx.dvdy = 0.4f;
    Vec2 dx, dy;
    Vec2 st = m.map(ctx, &dx, &dy);
    EXPECT_NEAR(st.x, 1.1f, 1e-6f);
    EXPECT_NEAR(dx.x, 0.2f, 1e-6f);
    EXPECT_NEAR(dx.y, 0.6f, 1e-6f);
    EXPECT_NEAR(dy.x, 0.6f, 1e-6f);
    EXPECT_NEAR(dy.y, 1.2f, 1e-6f);
}

TEST(Textures, SphericalCylindricalPlanarMappings) {
    Vec2 dx, dy;
    // Texture space = world translated by -(1, 0, 0): worldFromTexture translates by +1.
    Mat4 worldFromTexture = glm::translate(Mat4(1.f), Vec3(1, 0, 0));
    SphericalMapping2D sph(glm::inverse(worldFromTexture));
    Vec2 st = sph.map(atP(Vec3(1, 0, 2)), &dx, &dy);  // +z in texture space: theta 0
    EXPECT_NEAR(st.x, 0.f, 1e-6f);
    st = sph.map(atP(Vec3(1, 3, 0)), &dx, &dy);  // +y: theta pi/2, phi pi/2
    EXPECT_NEAR(st.x, 0.5f, 1e-6f);
    EXPECT_NEAR(st.y, 0.25f, 1e-6f);
    st = sph.map(atP(Vec3(1, -3, 0)), &dx, &dy);  // -y: phi 3pi/2
    EXPECT_NEAR(st.y, 0.75f, 1e-6f);

    CylindricalMapping2D cyl(Mat4(1.f));
    st = cyl.map(atP(Vec3(1, 0, 0)), &dx, &dy);  // (pi + 0) / 2pi
    EXPECT_NEAR(st.x, 0.5f, 1e-6f);
    EXPECT_NEAR(st.y, 0.f, 1e-6f);
    st = cyl.map(atP(Vec3(0, 3, 4)), &dx, &dy);  // t = z of the normalized direction
    EXPECT_NEAR(st.x, 0.75f, 1e-6f);
    EXPECT_NEAR(st.y, 0.8f, 1e-6f);

    PlanarMapping2D planar(Vec3(1, 0, 0), Vec3(0, 0, 1), 0.5f, -1.f);
    TextureContext ctx = atP(Vec3(2, 7, 3));
    ctx.dpdx = Vec3(0.1f, 0.2f, 0.3f);
    st = planar.map(ctx, &dx, &dy);
    EXPECT_NEAR(st.x, 2.5f, 1e-6f);
    EXPECT_NEAR(st.y, 2.f, 1e-6f);
    EXPECT_NEAR(dx.x, 0.1f, 1e-6f);
    EXPECT_NEAR(dx.y, 0.3f, 1e-6f);

    // Through the factory: planar mapping parameters.
    TestResolver r;
    Param v2 = numParam(ParamType::Vector3, "v2", {0, 0, 1});
    auto uv = makeSpectrum("uv", {stringParam("mapping", "planar"), v2, floatParam("udelta", 0.25)},
                           r);
    expectSpectrumNear(uv->evaluate(atP(Vec3(0.5f, 9, 0.125f))), {0.75f, 0.125f, 0}, 1e-5f);
}

TEST(Textures, Checkerboard2DParity) {
    TestResolver r;
    auto c = makeFloat("checkerboard", {floatParam("tex1", 1), floatParam("tex2", 0),
                                        stringParam("aamode", "none")}, r);
    EXPECT_EQ(c->evaluate(atUV(0.5f, 0.5f)), 1.f);
    EXPECT_EQ(c->evaluate(atUV(1.5f, 0.5f)), 0.f);
    EXPECT_EQ(c->evaluate(atUV(1.5f, 1.5f)), 1.f);
    EXPECT_EQ(c->evaluate(atUV(-0.5f, 0.5f)), 0.f);
    EXPECT_EQ(c->evaluate(atUV(-0.5f, -0.5f)), 1.f);

    auto s = makeSpectrum("checkerboard", {rgbParam("tex1", {1, 0, 0}),
                                           rgbParam("tex2", {0, 0, 1}),
                                           floatParam("uscale", 4), floatParam("vscale", 4)},
                          r);
    expectSpectrumNear(s->evaluate(atUV(0.1f, 0.1f)), {1, 0, 0}, 0);  // (0.4, 0.4): even
    expectSpectrumNear(s->evaluate(atUV(0.3f, 0.1f)), {0, 0, 1}, 0);  // (1.2, 0.4): odd
}

TEST(Textures, Checkerboard2DClosedForm) {
    TestResolver r;
    auto c = makeFloat("checkerboard", {}, r);  // closedform, tex1 = 1, tex2 = 0
    // Footprint inside one check: point value.
    EXPECT_FLOAT_EQ(c->evaluate(atUV(0.5f, 0.5f, 0.1f, 0.1f)), 1.f);
    // s in [0.5, 1.5] (half even, half odd), t in [0.3, 0.7]: half of each.
    TextureContext ctx = atUV(1.f, 0.5f, 0.5f, 0.2f);
    EXPECT_NEAR(c->evaluate(ctx), 0.5f, 1e-6f);
    // s in [0.625, 1.125] (centre 0.875, half-width 0.25) is 3/4 on the even check.
    EXPECT_NEAR(c->evaluate(atUV(0.875f, 0.5f, 0.25f, 0.1f)), 0.75f, 1e-6f);
    // Zero t-width (pbrt-v3 would give NaN): limit value.
    EXPECT_NEAR(c->evaluate(atUV(1.f, 0.5f, 0.5f, 0.f)), 0.5f, 1e-6f);
    // Footprint wider than a check: the average.
    EXPECT_FLOAT_EQ(c->evaluate(atUV(0.3f, 0.3f, 2.f, 2.f)), 0.5f);
}

TEST(Textures, Checkerboard3DUsesCtmAsPbrtV3) {
    TestResolver r;
    // pbrt-v3 applies the CTM itself to world points for 3D textures: with a scale of 2 the
    // point x = 0.6 lands in texture cell x = 1.
    Mat4 m = glm::scale(Mat4(1.f), Vec3(2.f));
    auto c = makeFloat("checkerboard", {intParam("dimension", 3)}, r, m);
    EXPECT_EQ(c->evaluate(atP(Vec3(0.3f, 0.3f, 0.3f))), 1.f);
    EXPECT_EQ(c->evaluate(atP(Vec3(0.6f, 0.3f, 0.3f))), 0.f);
    EXPECT_EQ(c->evaluate(atP(Vec3(0.6f, 0.6f, 0.3f))), 1.f);
    EXPECT_EQ(c->evaluate(atP(Vec3(-0.2f, 0.3f, 0.3f))), 0.f);

    std::string err;
    ParamList bad = makeParams({intParam("dimension", 4)});
    EXPECT_FALSE(createFloatTexture("checkerboard", bad, Mat4(1.f), r, &err));
    EXPECT_FALSE(err.empty());
}

TEST(Textures, DotsMatchNoiseAndPbrtV3ParameterOrder) {
    TestResolver r;
    auto dots = makeFloat("dots", {floatParam("inside", 7), floatParam("outside", 3)}, r);
    // Find a cell whose dot exists and evaluate at its centre; pbrt-v3 shows "outside" there.
    int found = 0;
    for (int sc = 0; sc < 20 && found < 3; ++sc) {
        for (int tc = 0; tc < 20 && found < 3; ++tc) {
            if (perlinNoise(sc + 0.5f, tc + 0.5f) <= 0) continue;
            float sCenter = sc + 0.15f * perlinNoise(sc + 1.5f, tc + 2.8f);
            float tCenter = tc + 0.15f * perlinNoise(sc + 4.5f, tc + 9.8f);
            EXPECT_EQ(dots->evaluate(atUV(sCenter, tCenter)), 3.f);
            // 0.4 from the dot centre, towards the cell centre: outside the dot (radius 0.35)
            // and still inside the cell (the centre is within 0.15 of the cell centre).
            float tFar = tCenter + (tCenter > tc ? -0.4f : 0.4f);
            EXPECT_EQ(dots->evaluate(atUV(sCenter, tFar)), 7.f);
            ++found;
        }
    }
    EXPECT_EQ(found, 3);
}

TEST(Textures, NoiseTexturesMatchNoiseFunctions) {
    TestResolver r;
    Mat4 m = glm::scale(Mat4(1.f), Vec3(3.f));
    auto f = makeFloat("fbm", {intParam("octaves", 5), floatParam("roughness", 0.6)}, r, m);
    auto w = makeFloat("wrinkled", {}, r, m);
    auto windy = makeSpectrum("windy", {}, r, m);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-5.f, 5.f);
    for (int i = 0; i < 50; ++i) {
        Vec3 p(u(rng), u(rng), u(rng));
        TextureContext ctx = atP(p);
        ctx.dpdx = Vec3(0.01f, 0, 0);
        ctx.dpdy = Vec3(0, 0.02f, 0);
        Vec3 pt = 3.f * p, dx = 3.f * ctx.dpdx, dy = 3.f * ctx.dpdy;
        EXPECT_FLOAT_EQ(f->evaluate(ctx), fbm(pt, dx, dy, 0.6f, 5));
        float wv = w->evaluate(ctx);
        EXPECT_FLOAT_EQ(wv, turbulence(pt, dx, dy, 0.5f, 8));
        EXPECT_GE(wv, 0.f);
        float expected =
            std::abs(fbm(0.1f * pt, 0.1f * dx, 0.1f * dy, 0.5f, 3)) * fbm(pt, dx, dy, 0.5f, 6);
        expectSpectrumNear(windy->evaluate(ctx), Spectrum(expected), 1e-6f);
    }
}

TEST(Textures, MarbleReproducesPbrtV3Spline) {
    TestResolver r;
    auto m = makeSpectrum("marble", {floatParam("variation", 0)}, r);
    // p.y = 0: t = 0.5, pbrt-v3 picks segment 1 and evaluates the cubic Bezier of colors 1..4
    // at 2: Bernstein weights (-1, 6, -12, 8); times 1.5.
    Spectrum expected = 1.5f * Spectrum(-0.58f + 6 * 0.58f - 12 * 0.5f + 8 * 0.6f,
                                        -0.58f + 6 * 0.58f - 12 * 0.5f + 8 * 0.59f,
                                        -0.6f + 6 * 0.6f - 12 * 0.5f + 8 * 0.58f);
    expectSpectrumNear(m->evaluate(atP(Vec3(0.3f, 0, 0.7f))), expected, 1e-4f);
    // p.y = -pi/2: t = 0, the first control color times 1.5.
    expectSpectrumNear(m->evaluate(atP(Vec3(0, -PiOver2, 0))), 1.5f * Spectrum(.58f, .58f, .6f),
                       1e-4f);
    // scale multiplies p before the lookup.
    auto m4 = makeSpectrum("marble", {floatParam("variation", 0), floatParam("scale", 4)}, r);
    expectSpectrumNear(m4->evaluate(atP(Vec3(0, -PiOver2 / 4, 0))),
                       1.5f * Spectrum(.58f, .58f, .6f), 1e-4f);
}

TEST(Textures, FactoryErrors) {
    TestResolver r;
    std::string err;
    ParamList empty;
    // ptex (no library): a constant 0.5 with a warning (Textures.UnreadableImage... style).
    auto ptex = createFloatTexture("ptex", empty, Mat4(1.f), r, &err);
    ASSERT_NE(ptex, nullptr);
    EXPECT_EQ(ptex->evaluate(TextureContext()), 0.5f);
    EXPECT_FALSE(createSpectrumTexture("bogus", empty, Mat4(1.f), r, &err));
    EXPECT_NE(err.find("bogus"), std::string::npos);
    err.clear();
    EXPECT_FALSE(createFloatTexture("marble", empty, Mat4(1.f), r, &err));
    EXPECT_FALSE(err.empty());
    err.clear();
    ParamList badMap = makeParams({stringParam("mapping", "toroidal")});
    EXPECT_FALSE(createSpectrumTexture("uv", badMap, Mat4(1.f), r, &err));
    EXPECT_NE(err.find("toroidal"), std::string::npos);
    err.clear();
}

// pbrt-v3's substitute for an unreadable image: a constant of value "scale", with a warning
// at the "filename" parameter (an error in strict mode).
TEST(Textures, UnreadableImageIsTheConstantScale) {
    for (bool strict : {false, true}) {
        Diagnostics diag;
        diag.setStream(nullptr);
        diag.setStrict(strict);
        ParamList ps = makeParams({stringParam("filename", "/nonexistent/nothing.png"),
                                   floatParam("scale", 0.25f)});
        ps.setDiagnostics(&diag);
        TestResolver r;
        std::string err;
        auto t = createSpectrumTexture("imagemap", ps, Mat4(1.f), r, &err);
        ASSERT_NE(t, nullptr) << err;
        TextureContext tc;
        tc.uv = Vec2(0.3f, 0.7f);
        EXPECT_EQ(t->evaluate(tc), Spectrum(0.25f));
        auto f = createFloatTexture("imagemap", ps, Mat4(1.f), r, &err);
        ASSERT_NE(f, nullptr) << err;
        EXPECT_EQ(f->evaluate(tc), 0.25f);
        ASSERT_FALSE(diag.all().empty());
        EXPECT_EQ(diag.all()[0].severity, strict ? Severity::Error : Severity::Warning);
        EXPECT_NE(diag.all()[0].message.find("nothing.png"), std::string::npos);
    }
}

// ---------------------------------------------------------------------------------------------
// Noise.

TEST(Noise, ZeroAtLatticeAndBoundedAndDeterministic) {
    EXPECT_EQ(perlinNoise(3, -2, 5), 0.f);
    EXPECT_EQ(perlinNoise(Vec3(0, 0, 0)), 0.f);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(-100.f, 100.f);
    float maxAbs = 0, sumSq = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        Vec3 p(u(rng), u(rng), u(rng));
        float v = perlinNoise(p);
        EXPECT_EQ(v, perlinNoise(p.x, p.y, p.z));
        maxAbs = std::max(maxAbs, std::abs(v));
        sumSq += v * v;
    }
    // Gradient noise with these gradients is bounded by about 1.04; it is not degenerate.
    EXPECT_LE(maxAbs, 1.1f);
    EXPECT_GT(maxAbs, 0.5f);
    EXPECT_GT(sumSq / n, 0.01f);
    // Continuity: a tiny step changes the value a little (|grad| <= ~ 3 per unit).
    Vec3 p(1.3f, 2.7f, -0.4f);
    EXPECT_NEAR(perlinNoise(p), perlinNoise(p + Vec3(1e-4f)), 1e-3f);
}

TEST(Noise, FbmAndTurbulenceOctaves) {
    Vec3 p(0.37f, 1.21f, -2.6f), zero(0.f);
    // Zero differentials: all octaves, and the partial octave has weight smoothstep(0) = 0.
    float expected = perlinNoise(p) + 0.5f * perlinNoise(1.99f * p);
    EXPECT_NEAR(fbm(p, zero, zero, 0.5f, 2), expected, 1e-6f);
    // Footprint of length 1 allows no octave (n = clamp(-1 - log2(1)) = 0): fBm is 0 and
    // turbulence is 0.2 (partial octave) plus 0.2 per clamped octave with amplitudes
    // 1, 0.5, 0.25.
    Vec3 big(1.f, 0, 0);
    EXPECT_EQ(fbm(p, big, big, 0.5f, 3), 0.f);
    EXPECT_NEAR(turbulence(p, big, big, 0.5f, 3), 0.2f + 0.2f * 1.75f, 1e-6f);
    EXPECT_GE(turbulence(p, zero, zero, 0.5f, 8), 0.f);
}

// ---------------------------------------------------------------------------------------------
// Image maps and MIP maps.

TEST(MipMap, BilinearLookupAndWrapModes) {
    // 4x2 single-row-pair image; row 0 of the MIP map is the image's bottom row.
    std::vector<float> texels = {1, 2, 3, 4,    // t row 0
                                 5, 6, 7, 8};   // t row 1
    MipMap<float> rep(4, 2, texels, ImageWrap::Repeat);
    MipMap<float> blk(4, 2, texels, ImageWrap::Black);
    MipMap<float> clp(4, 2, texels, ImageWrap::Clamp);
    EXPECT_EQ(rep.levels(), 3);
    EXPECT_FLOAT_EQ(rep.bilerp(0, Vec2(0.125f, 0.25f)), 1.f);   // texel centre (0, 0)
    EXPECT_FLOAT_EQ(rep.bilerp(0, Vec2(0.375f, 0.75f)), 6.f);   // texel centre (1, 1)
    EXPECT_FLOAT_EQ(rep.bilerp(0, Vec2(0.25f, 0.5f)), 3.5f);    // between 1, 2, 5, 6
    // Left edge at t of row 0: half texel 0, half texel -1.
    EXPECT_FLOAT_EQ(rep.bilerp(0, Vec2(0.f, 0.25f)), 2.5f);  // wraps to texel 3 (4)
    EXPECT_FLOAT_EQ(blk.bilerp(0, Vec2(0.f, 0.25f)), 0.5f);  // black outside
    EXPECT_FLOAT_EQ(clp.bilerp(0, Vec2(0.f, 0.25f)), 1.f);   // clamped to texel 0
    EXPECT_FLOAT_EQ(rep.bilerp(0, Vec2(1.125f, 0.25f)), 1.f);  // period 1
    EXPECT_FLOAT_EQ(blk.bilerp(0, Vec2(1.5f, 0.25f)), 0.f);
    EXPECT_FLOAT_EQ(clp.bilerp(0, Vec2(-3.f, 0.75f)), 5.f);
    // Coarser levels are 2x2 box averages.
    EXPECT_FLOAT_EQ(rep.texel(1, 0, 0), (1 + 2 + 5 + 6) / 4.f);
    EXPECT_FLOAT_EQ(rep.texel(2, 0, 0), 4.5f);
}

TEST(MipMap, LargeFootprintAveragesCheckerToMean) {
    const int n = 64;
    std::vector<float> texels(n * n);
    for (int t = 0; t < n; ++t)
        for (int s = 0; s < n; ++s) texels[t * n + s] = float((s + t) % 2);
    MipMap<float> map(n, n, texels, ImageWrap::Repeat);
    EXPECT_EQ(map.levels(), 7);
    Vec2 st(0.3f, 0.6f);
    // A zero footprint at a texel centre sees a single check (with every filter)...
    for (MipFilter f : {MipFilter::Point, MipFilter::Bilinear, MipFilter::Trilinear,
                        MipFilter::EWA}) {
        EXPECT_FLOAT_EQ(map.lookup(Vec2(0.5f / n, 0.5f / n), Vec2(0), Vec2(0), f, 8), 0.f);
        EXPECT_FLOAT_EQ(map.lookup(Vec2(1.5f / n, 0.5f / n), Vec2(0), Vec2(0), f, 8), 1.f);
    }
    // ...footprints of several texels land on levels >= 1, where every texel is 0.5.
    Vec2 d(4.f / n, 0.f), e(0.f, 4.f / n);
    EXPECT_NEAR(map.lookup(st, d, e, MipFilter::Trilinear, 8), 0.5f, 1e-6f);
    EXPECT_NEAR(map.lookup(st, d, e, MipFilter::EWA, 8), 0.5f, 1e-6f);
    EXPECT_NEAR(map.lookup(st, Vec2(0.5f, 0), Vec2(0, 0.5f), MipFilter::EWA, 8), 0.5f, 1e-6f);
    EXPECT_NEAR(map.trilinear(st, 10.f), 0.5f, 1e-6f);  // beyond the coarsest level
    // Anisotropic footprint (long in s, one texel in t) is still averaged by EWA.
    EXPECT_NEAR(map.lookup(st, Vec2(8.f / n, 0), Vec2(0, 1.f / n), MipFilter::EWA, 8), 0.5f,
                0.05f);
}

TEST(MipMap, NonPowerOfTwoIsResampled) {
    std::vector<Spectrum> texels(6 * 3, Spectrum(0.25f, 0.5f, 1.f));
    MipMap<Spectrum> map(6, 3, texels, ImageWrap::Repeat);
    EXPECT_EQ(map.width(), 8);
    EXPECT_EQ(map.height(), 4);
    EXPECT_EQ(map.levels(), 4);
    // The normalized Lanczos weights reproduce a constant image exactly.
    for (float s : {0.f, 0.3f, 0.77f})
        expectSpectrumNear(map.bilerp(0, Vec2(s, 0.4f)), Spectrum(0.25f, 0.5f, 1.f), 1e-5f);
    expectSpectrumNear(map.texel(3, 0, 0), Spectrum(0.25f, 0.5f, 1.f), 1e-5f);
}

TEST(ImageMap, BilinearLookupsFromFileFlipVertically) {
    // Image rows top to bottom: (10, 20), (30, 40) in channel R; G = R / 10, B = 0.
    std::vector<float> px = {10, 1, 0, 20, 2, 0, 30, 3, 0, 40, 4, 0};
    std::string path = writeImage("bilinear.exr", 2, 2, 3, px, false);
    TestResolver r;
    MipMapCache cache;
    auto tex = makeSpectrum("imagemap", {stringParam("filename", path),
                                         stringParam("filter", "bilinear")},
                            r, Mat4(1.f), &cache);
    // v = 0.25 is the bottom image row (30, 40); v = 0.75 the top row.
    expectSpectrumNear(tex->evaluate(atUV(0.25f, 0.25f)), {30, 3, 0}, 1e-4f);
    expectSpectrumNear(tex->evaluate(atUV(0.75f, 0.75f)), {20, 2, 0}, 1e-4f);
    expectSpectrumNear(tex->evaluate(atUV(0.5f, 0.5f)), {25, 2.5f, 0}, 1e-4f);
    // Float variant: luminance of the RGB texel (EXR: no gamma).
    auto ftex = makeFloat("imagemap", {stringParam("filename", path),
                                       stringParam("filter", "bilinear")},
                          r, Mat4(1.f), &cache);
    EXPECT_NEAR(ftex->evaluate(atUV(0.25f, 0.25f)), luminance(Spectrum(30, 3, 0)), 1e-4f);
    // Wrap modes through the factory.
    auto black = makeSpectrum("imagemap", {stringParam("filename", path),
                                           stringParam("filter", "bilinear"),
                                           stringParam("wrap", "black")},
                              r, Mat4(1.f), &cache);
    expectSpectrumNear(black->evaluate(atUV(0.f, 0.25f)), {15, 1.5f, 0}, 1e-4f);
    auto clampT = makeSpectrum("imagemap", {stringParam("filename", path),
                                            stringParam("filter", "bilinear"),
                                            stringParam("wrap", "clamp")},
                               r, Mat4(1.f), &cache);
    expectSpectrumNear(clampT->evaluate(atUV(-2.f, 0.25f)), {30, 3, 0}, 1e-4f);
    expectSpectrumNear(tex->evaluate(atUV(0.f, 0.25f)), {35, 3.5f, 0}, 1e-4f);  // repeat
}

TEST(ImageMap, GammaScaleInvertAndCacheSharing) {
    // 8-bit PNG, grey 128 everywhere (OIIO quantizes 128/255 exactly).
    std::vector<float> px(4 * 4 * 3, 128.f / 255.f);
    std::string path = writeImage("grey.png", 4, 4, 3, px, true);
    TestResolver r;
    MipMapCache cache;
    float lin = srgbToLinear(128.f / 255.f);
    EXPECT_NEAR(lin, 0.2158605f, 1e-5f);
    auto t = makeSpectrum("imagemap", {stringParam("filename", path)}, r, Mat4(1.f), &cache);
    expectSpectrumNear(t->evaluate(atUV(0.3f, 0.6f, 0.01f, 0.01f)), Spectrum(lin), 1e-5f);
    auto raw = makeSpectrum("imagemap", {stringParam("filename", path), boolParam("gamma", false)},
                            r, Mat4(1.f), &cache);
    expectSpectrumNear(raw->evaluate(atUV(0.3f, 0.6f)), Spectrum(128.f / 255.f), 1e-5f);
    auto f = makeFloat("imagemap", {stringParam("filename", path), floatParam("scale", 2)}, r,
                       Mat4(1.f), &cache);
    EXPECT_NEAR(f->evaluate(atUV(0.3f, 0.6f)), 2 * lin, 1e-5f);
    auto inv = makeFloat("imagemap", {stringParam("filename", path), boolParam("invert", true)},
                         r, Mat4(1.f), &cache);
    EXPECT_NEAR(inv->evaluate(atUV(0.3f, 0.6f)), 1 - lin, 1e-5f);
    EXPECT_EQ(cache.size(), 4u);
    // Same contents, different filter: shared.
    auto t2 = makeSpectrum("imagemap", {stringParam("filename", path),
                                        boolParam("trilinear", true)},
                           r, Mat4(1.f), &cache);
    expectSpectrumNear(t2->evaluate(atUV(0.1f, 0.1f)), Spectrum(lin), 1e-5f);
    EXPECT_EQ(cache.size(), 4u);
}

TEST(ImageMap, CheckerImageLargeFootprintThroughTexture) {
    const int n = 16;
    std::vector<float> px(n * n);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) px[y * n + x] = float((x / 2 + y / 2) % 2);
    std::string path = writeImage("checker.exr", n, n, 1, px, false);
    TestResolver r;
    for (const char* filter : {"trilinear", "ewa"}) {
        auto t = makeFloat("imagemap", {stringParam("filename", path),
                                        stringParam("filter", filter)}, r);
        EXPECT_NEAR(t->evaluate(atUV(0.37f, 0.61f, 0.5f, 0.5f)), 0.5f, 1e-5f) << filter;
        // Zero footprint: the finest level.
        EXPECT_NEAR(t->evaluate(atUV(0.5f / n, 0.5f / n)), 1.f * float(((n - 1) / 2) % 2),
                    1e-5f) << filter;
    }
}

// ---------------------------------------------------------------------------------------------
// Bump mapping.

TEST(Bump, LinearDisplacementTiltsNormal) {
    const float a = 0.5f;  // d(u, v) = a u
    FunctionTexture d([&](const TextureContext& c) { return a * c.uv.x; });
    BumpInput in;
    in.uv = Vec2(0.3f, 0.7f);
    in.p = Vec3(0.3f, 0.7f, 0);
    in.n = in.ns = Vec3(0, 0, 1);
    in.dpdu = Vec3(1, 0, 0);
    in.dpdv = Vec3(0, 1, 0);
    Vec3 dpdu, dpdv, ns;
    bump(d, in, &dpdu, &dpdv, &ns);
    // p' = p + a u z: dp'/du = (1, 0, a), normal (-a, 0, 1) / sqrt(1 + a^2).
    EXPECT_NEAR(dpdu.z, a, 1e-4f);
    EXPECT_NEAR(std::acos(ns.z), std::atan(a), 1e-4f);
    EXPECT_NEAR(ns.x, -a / std::sqrt(1 + a * a), 1e-4f);
    EXPECT_NEAR(ns.y, 0.f, 1e-6f);

    // Same with screen-space differentials (other step) and a geometric normal pointing down:
    // the result is flipped to the -z side.
    in.dudx = 0.02f;
    in.dvdy = 0.03f;
    in.n = Vec3(0, 0, -1);
    bump(d, in, &dpdu, &dpdv, &ns);
    EXPECT_NEAR(std::acos(-ns.z), std::atan(a), 1e-4f);
    EXPECT_NEAR(ns.x, a / std::sqrt(1 + a * a), 1e-4f);

    // Constant displacement on a plane leaves the normal unchanged.
    ConstantFloatTexture c(0.3f);
    in.n = Vec3(0, 0, 1);
    bump(c, in, &dpdu, &dpdv, &ns);
    EXPECT_NEAR(ns.z, 1.f, 1e-6f);
}

}  // namespace
}  // namespace rlpbrt
