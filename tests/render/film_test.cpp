// Tests of the pixel filters (values, integrals, factory) and the film (crop bounds, filtered
// accumulation, scale, maxsampleluminance, tiles and deterministic merging).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <thread>

#include "parser/params.h"
#include "render/film.h"
#include "render/filter.h"

namespace rlpbrt {
namespace {

Param numParam(ParamType type, const std::string& name, std::vector<double> values) {
    Param p;
    p.type = type;
    p.name = name;
    p.numbers = std::move(values);
    return p;
}

Param floatParam(const std::string& name, std::vector<double> values) {
    return numParam(ParamType::Float, name, std::move(values));
}

Param intParam(const std::string& name, int v) {
    return numParam(ParamType::Integer, name, {double(v)});
}

Param stringParam(const std::string& name, const std::string& v) {
    Param p;
    p.type = ParamType::String;
    p.name = name;
    p.strings = {v};
    return p;
}

std::shared_ptr<const Filter> makeFilter(const std::string& name, const ParamList& params = {}) {
    std::string err;
    std::shared_ptr<const Filter> f = createFilter(name, params, &err);
    EXPECT_TRUE(f) << err;
    return f;
}

// Midpoint-rule integral of the filter over its support with n x n cells.
double integrate(const Filter& f, int n = 400) {
    Vec2 r = f.radius();
    double sum = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            Vec2 p(-r.x + (i + 0.5f) * 2 * r.x / n, -r.y + (j + 0.5f) * 2 * r.y / n);
            sum += f.evaluate(p);
        }
    return sum * (4.0 * r.x * r.y) / (double(n) * n);
}

const char* kFilterNames[] = {"box", "gaussian", "mitchell", "sinc", "triangle"};

// ------------------------------------------------------------------------------------------
// Filters

TEST(Filter, DefaultsFollowPbrtV3) {
    EXPECT_EQ(makeFilter("box")->radius(), Vec2(0.5f));
    EXPECT_EQ(makeFilter("gaussian")->radius(), Vec2(2.f));
    EXPECT_EQ(makeFilter("mitchell")->radius(), Vec2(2.f));
    EXPECT_EQ(makeFilter("sinc")->radius(), Vec2(4.f));
    EXPECT_EQ(makeFilter("triangle")->radius(), Vec2(2.f));
    for (const char* n : kFilterNames) EXPECT_STREQ(makeFilter(n)->name(), n);
    auto g = std::dynamic_pointer_cast<const GaussianFilter>(makeFilter("gaussian"));
    ASSERT_TRUE(g);
    EXPECT_FLOAT_EQ(g->alpha(), 2.f);
}

TEST(Filter, UnknownNameAndBadWidthAreErrors) {
    std::string err;
    EXPECT_FALSE(createFilter("lanczos", ParamList(), &err));
    EXPECT_NE(err.find("lanczos"), std::string::npos);
    ParamList bad;
    bad.add(floatParam("xwidth", {0.0}));
    err.clear();
    EXPECT_FALSE(createFilter("box", bad, &err));
    EXPECT_FALSE(err.empty());
}

TEST(Filter, WidthParametersAreRadii) {
    ParamList ps;
    ps.add(floatParam("xwidth", {1.0}));
    ps.add(floatParam("ywidth", {1.5}));
    auto f = makeFilter("triangle", ps);
    EXPECT_EQ(f->radius(), Vec2(1.f, 1.5f));
    EXPECT_FLOAT_EQ(f->evaluate(Vec2(0.f)), 1.5f);
    EXPECT_FLOAT_EQ(f->evaluate(Vec2(0.5f, 1.f)), 0.5f * 0.5f);
    EXPECT_FLOAT_EQ(f->evaluate(Vec2(1.f, 0.f)), 0.f);
}

TEST(Filter, BoxIntegralIsSupportArea) {
    for (float r : {0.5f, 1.f, 1.5f}) {
        BoxFilter f(Vec2(r, 2 * r));
        EXPECT_NEAR(integrate(f), 4.0 * r * 2 * r, 1e-4);
        EXPECT_EQ(f.evaluate(Vec2(0.3f * r, -0.9f * r)), 1.f);
    }
}

TEST(Filter, GaussianValues) {
    auto f = makeFilter("gaussian");
    const double e8 = std::exp(-8.0);  // exp(-alpha r^2), alpha = r = 2
    EXPECT_NEAR(f->evaluate(Vec2(0.f)), (1 - e8) * (1 - e8), 1e-6);
    EXPECT_NEAR(f->evaluate(Vec2(1.f, 0.f)), (std::exp(-2.0) - e8) * (1 - e8), 1e-6);
    EXPECT_NEAR(f->evaluate(Vec2(0.5f, -1.5f)),
                (std::exp(-0.5) - e8) * (std::exp(-4.5) - e8), 1e-6);
    EXPECT_EQ(f->evaluate(Vec2(2.f, 0.f)), 0.f);
    ParamList ps;
    ps.add(floatParam("alpha", {1.0}));
    auto g = makeFilter("gaussian", ps);
    EXPECT_NEAR(g->evaluate(Vec2(1.f, 0.f)),
                (std::exp(-1.0) - std::exp(-4.0)) * (1 - std::exp(-4.0)), 1e-6);
    // 1D integral of e^{-2x^2} - e^{-8} over [-2, 2]: sqrt(pi/2) erf(2 sqrt 2) - 4 e^{-8}.
    double i1 = std::sqrt(Pi / 2.0) * std::erf(2 * std::sqrt(2.0)) - 4 * e8;
    EXPECT_NEAR(integrate(*f), i1 * i1, 1e-4);
}

TEST(Filter, MitchellValues) {
    auto f = std::dynamic_pointer_cast<const MitchellFilter>(makeFilter("mitchell"));
    ASSERT_TRUE(f);
    const double b = 1.0 / 3.0;
    // Centre: (6 - 2B) / 6 per axis; at half the radius (cubic argument 1): B / 6; edge 0.
    EXPECT_NEAR(f->mitchell1D(0.f), (6 - 2 * b) / 6, 1e-6);
    EXPECT_NEAR(f->mitchell1D(0.5f), b / 6, 1e-6);
    EXPECT_NEAR(f->mitchell1D(1.f), 0.0, 1e-6);
    EXPECT_NEAR(f->evaluate(Vec2(0.f)), std::pow((6 - 2 * b) / 6, 2), 1e-6);
    EXPECT_NEAR(f->evaluate(Vec2(1.f, 0.f)), (b / 6) * (6 - 2 * b) / 6, 1e-6);
    // Negative lobe between the half radius and the edge.
    EXPECT_LT(f->evaluate(Vec2(1.5f, 0.f)), 0.f);
    // The cubic integrates to 1 over [-2, 2]; stretched to radius r it integrates to r / 2.
    EXPECT_NEAR(integrate(*f), 1.0, 1e-4);
    MitchellFilter g(Vec2(1.f, 3.f), 0.f, 0.5f);  // Catmull-Rom
    EXPECT_NEAR(integrate(g), 0.5 * 1.5, 1e-4);
    EXPECT_NEAR(g.mitchell1D(0.f), 1.0, 1e-6);
}

TEST(Filter, SincValues) {
    auto f = std::dynamic_pointer_cast<const LanczosSincFilter>(makeFilter("sinc"));
    ASSERT_TRUE(f);
    EXPECT_FLOAT_EQ(f->evaluate(Vec2(0.f)), 1.f);
    EXPECT_NEAR(f->evaluate(Vec2(1.f, 0.f)), 0.0, 1e-6);  // zero of sinc(x)
    double s = (2 / Pi) * (std::sin(Pi / 6) / (Pi / 6));     // sinc(0.5) sinc(0.5 / tau)
    EXPECT_NEAR(f->evaluate(Vec2(0.5f, 0.f)), s, 1e-6);
    EXPECT_NEAR(f->evaluate(Vec2(0.5f, 0.5f)), s * s, 1e-6);
    EXPECT_EQ(f->windowedSinc(4.5f, 4.f), 0.f);
    ParamList ps;
    ps.add(floatParam("tau", {1.0}));
    auto g = makeFilter("sinc", ps);
    EXPECT_NEAR(g->evaluate(Vec2(0.5f, 0.f)), (2 / Pi) * (2 / Pi), 1e-6);
}

TEST(Filter, TriangleValuesAndIntegral) {
    auto f = makeFilter("triangle");
    EXPECT_FLOAT_EQ(f->evaluate(Vec2(0.f)), 4.f);
    EXPECT_FLOAT_EQ(f->evaluate(Vec2(0.5f, -1.f)), 1.5f * 1.f);
    EXPECT_FLOAT_EQ(f->evaluate(Vec2(2.5f, 0.f)), 0.f);
    // Integral of (r - |x|) over [-r, r] is r^2 per axis.
    EXPECT_NEAR(integrate(*f), 16.0, 1e-3);
}

// ------------------------------------------------------------------------------------------
// Film parameters and bounds

FilmParams filmParams(int xres, int yres, std::vector<double> crop = {}) {
    ParamList ps;
    ps.add(intParam("xresolution", xres));
    ps.add(intParam("yresolution", yres));
    if (!crop.empty()) ps.add(floatParam("cropwindow", crop));
    std::string err;
    FilmParams fp = parseFilm(ps, &err);
    EXPECT_EQ(err, "");
    return fp;
}

TEST(FilmParams, Defaults) {
    std::string err = "x";
    FilmParams fp = parseFilm(ParamList(), &err);
    EXPECT_EQ(err, "");
    EXPECT_EQ(fp.xResolution, 1280);
    EXPECT_EQ(fp.yResolution, 720);
    EXPECT_EQ(fp.filename, "pbrt.exr");
    EXPECT_EQ(fp.scale, 1.f);
    EXPECT_TRUE(std::isinf(fp.maxSampleLuminance));
    EXPECT_EQ(fp.pixelBounds(), Bounds2i({0, 0}, {1280, 720}));
}

TEST(FilmParams, ReadsAllParameters) {
    ParamList ps;
    ps.add(intParam("xresolution", 64));
    ps.add(intParam("yresolution", 32));
    ps.add(floatParam("scale", {12.0}));
    ps.add(floatParam("maxsampleluminance", {5.0}));
    ps.add(floatParam("diagonal", {50.0}));
    ps.add(stringParam("filename", "out.exr"));
    std::string err;
    FilmParams fp = parseFilm(ps, &err);
    EXPECT_EQ(err, "");
    EXPECT_EQ(fp.xResolution, 64);
    EXPECT_EQ(fp.yResolution, 32);
    EXPECT_EQ(fp.scale, 12.f);
    EXPECT_EQ(fp.maxSampleLuminance, 5.f);
    EXPECT_EQ(fp.filename, "out.exr");
    for (const Param& p : ps.params()) EXPECT_TRUE(p.used) << p.name;
}

TEST(FilmParams, CropBoundsMatchPbrtV3) {
    // cloud: cropwindow [0 .9 0 .8]; 200 * 0.9f rounds to 180 in float, so ceil gives 180.
    EXPECT_EQ(filmParams(200, 200, {0, .9, 0, .8}).pixelBounds(),
              Bounds2i({0, 0}, {180, 160}));
    EXPECT_EQ(filmParams(900, 900, {0, .9, 0, .8}).pixelBounds(),
              Bounds2i({0, 0}, {810, 720}));
    // caustic-glass f16-11a: [.3 .7 .4 .7] at 1050 x 1500, and at the small 140 x 200.
    EXPECT_EQ(filmParams(1050, 1500, {.3, .7, .4, .7}).pixelBounds(),
              Bounds2i({315, 600}, {735, 1050}));
    EXPECT_EQ(filmParams(140, 200, {.3, .7, .4, .7}).pixelBounds(),
              Bounds2i({42, 80}, {98, 140}));
    // Fractional edges round up: 2.1 -> 3, 7.5 -> 8.
    EXPECT_EQ(filmParams(10, 10, {.21, .75, .21, .75}).pixelBounds(),
              Bounds2i({3, 3}, {8, 8}));
    // Pairs are ordered and clamped as in pbrt-v3.
    EXPECT_EQ(filmParams(200, 200, {.9, 0, 1.5, .8}).pixelBounds(),
              Bounds2i({0, 160}, {180, 200}));
}

TEST(FilmParams, Errors) {
    std::string err;
    ParamList ps;
    ps.add(floatParam("cropwindow", {0, .5, 0}));
    parseFilm(ps, &err);
    EXPECT_NE(err.find("cropwindow"), std::string::npos);
    ParamList empty;
    empty.add(floatParam("cropwindow", {.5, .5, 0, 1}));
    err.clear();
    parseFilm(empty, &err);
    EXPECT_FALSE(err.empty());
    ParamList res;
    res.add(intParam("xresolution", 0));
    err.clear();
    parseFilm(res, &err);
    EXPECT_FALSE(err.empty());
}

TEST(Film, SampleBoundsAndTiles) {
    Film box(filmParams(200, 100), makeFilter("box"));
    EXPECT_EQ(box.pixelBounds(), Bounds2i({0, 0}, {200, 100}));
    EXPECT_EQ(box.sampleBounds(), Bounds2i({0, 0}, {200, 100}));
    Film gauss(filmParams(200, 100, {0, .9, 0, .8}), makeFilter("gaussian"));
    EXPECT_EQ(gauss.fullWidth(), 200);
    EXPECT_EQ(gauss.fullHeight(), 100);
    EXPECT_EQ(gauss.sampleBounds(), Bounds2i({-2, -2}, {182, 82}));
    // Tiles cover the sample bounds exactly once, in row-major order.
    std::vector<Bounds2i> tiles = gauss.sampleTiles(16);
    long area = 0;
    for (const Bounds2i& t : tiles) area += t.area();
    EXPECT_EQ(area, long(gauss.sampleBounds().area()));
    EXPECT_EQ(tiles.front().pMin, glm::ivec2(-2, -2));
    EXPECT_EQ(tiles.back().pMax, glm::ivec2(182, 82));
    // A tile holds the pixels its samples reach: radius 2 beyond the sample region, clipped.
    auto tile = gauss.makeTile(Bounds2i({0, 0}, {16, 16}));
    EXPECT_EQ(tile->pixelBounds(), Bounds2i({0, 0}, {18, 18}));
    auto inner = gauss.makeTile(Bounds2i({32, 32}, {48, 48}));
    EXPECT_EQ(inner->pixelBounds(), Bounds2i({30, 30}, {50, 50}));
}

TEST(Film, SampleSplatsWithTabulatedFilterWeights) {
    auto filter = makeFilter("gaussian");
    Film film(filmParams(32, 32), filter);
    auto tile = film.makeTile(Bounds2i({0, 0}, {32, 32}));
    tile->addSample(Vec2(10.5f, 10.5f), Spectrum(1.f, 2.f, 3.f));
    // Offsets -2..2 reach pixels 8..12 (the pixel at exactly the radius uses the last cell).
    EXPECT_EQ(tile->weightSum(7, 10), 0.f);
    EXPECT_EQ(tile->weightSum(13, 10), 0.f);
    EXPECT_GT(tile->weightSum(8, 10), 0.f);
    EXPECT_GT(tile->weightSum(12, 12), 0.f);
    // Offset 0 -> cell 0 (centre 1/16 of the radius); offset 1 -> cell 8.
    const float c = 2.f / 16;
    EXPECT_FLOAT_EQ(tile->weightSum(10, 10), filter->evaluate(Vec2(0.5f * c)));
    EXPECT_FLOAT_EQ(tile->weightSum(11, 10), filter->evaluate(Vec2(8.5f * c, 0.5f * c)));
    EXPECT_FLOAT_EQ(tile->weightSum(12, 8), filter->evaluate(Vec2(15.5f * c)));
    EXPECT_FLOAT_EQ(tile->contribution(11, 10).z, 3.f * tile->weightSum(11, 10));
    // The camera ray weight scales the contribution but not the weight sum.
    tile->clear();
    tile->addSample(Vec2(10.5f, 10.5f), Spectrum(1.f), 0.5f);
    EXPECT_FLOAT_EQ(tile->contribution(10, 10).x, 0.5f * tile->weightSum(10, 10));
}

// A scaled tile's samples weigh the factor each in the film (the auto trial's plain pass,
// render.cpp): the pixel is their weighted mean with the other passes' samples.
TEST(Film, ScaledTileWeighsItsSamples) {
    Film film(filmParams(8, 8), makeFilter("box"));
    const Bounds2i all({0, 0}, {8, 8});
    std::vector<std::unique_ptr<FilmTile>> tiles;
    tiles.push_back(film.makeTile(all));
    tiles[0]->addSample(Vec2(3.5f, 3.5f), Spectrum(1.f, 2.f, 4.f));
    film.mergeTiles(tiles);
    tiles[0]->clear();
    tiles[0]->addSample(Vec2(3.5f, 3.5f), Spectrum(5.f, 10.f, 20.f));
    tiles[0]->addSample(Vec2(3.5f, 3.5f), Spectrum(5.f, 10.f, 20.f), 0.5f);
    const float w1 = tiles[0]->weightSum(3, 3);
    tiles[0]->scale(0.25f);
    EXPECT_FLOAT_EQ(tiles[0]->weightSum(3, 3), 0.25f * w1);
    film.mergeTiles(tiles);
    const Image img = film.toImage();
    // (1 x 1 + 0.25 x (5 + 2.5)) / (1 + 0.25 x 2) for red; the others alike.
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(img.at(3, 3, c), float(1 << c) * (1.f + 0.25f * 7.5f) / 1.5f, 1e-5f) << c;
    tiles[0]->scale(0.f);  // a tile scaled to nothing adds nothing
    EXPECT_EQ(tiles[0]->weightSum(3, 3), 0.f);
}

// Splats L at a jittered 3x3 grid of samples in every pixel of the sample bounds.
void splatUniform(Film& film, Spectrum L, int tileSize = 16, uint32_t seed = 1) {
    std::vector<std::unique_ptr<FilmTile>> tiles;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (const Bounds2i& tb : film.sampleTiles(tileSize)) {
        auto tile = film.makeTile(tb);
        for (int y = tb.pMin.y; y < tb.pMax.y; ++y)
            for (int x = tb.pMin.x; x < tb.pMax.x; ++x)
                for (int s = 0; s < 9; ++s) {
                    Vec2 p(x + (s % 3 + u(rng)) / 3.f, y + (s / 3 + u(rng)) / 3.f);
                    film.addSample(*tile, p, L);
                }
        tiles.push_back(std::move(tile));
    }
    film.mergeTiles(tiles);
}

TEST(Film, ConstantRadianceGivesConstantImageForEveryFilter) {
    const Spectrum L(0.25f, 0.5f, 2.f);
    for (const char* name : kFilterNames) {
        for (bool crop : {false, true}) {
            Film film(crop ? filmParams(40, 30, {.1, .8, .3, .9}) : filmParams(40, 30),
                      makeFilter(name));
            splatUniform(film, L);
            Image img = film.toImage();
            ASSERT_EQ(img.width, film.pixelBounds().width());
            ASSERT_EQ(img.height, film.pixelBounds().height());
            ASSERT_EQ(img.channels, 3);
            for (int y = 0; y < img.height; ++y)
                for (int x = 0; x < img.width; ++x)
                    for (int c = 0; c < 3; ++c)
                        ASSERT_NEAR(img.at(x, y, c), L[c], 1e-4f * L[c])
                            << name << " crop " << crop << " at " << x << "," << y;
        }
    }
}

TEST(Film, ScaleIsApplied) {
    ParamList ps;
    ps.add(intParam("xresolution", 8));
    ps.add(intParam("yresolution", 8));
    ps.add(floatParam("scale", {1.5}));
    std::string err;
    Film film(parseFilm(ps, &err), makeFilter("mitchell"));
    splatUniform(film, Spectrum(2.f));
    Image img = film.toImage();
    for (float v : img.pixels) EXPECT_NEAR(v, 3.f, 1e-4f);
}

TEST(Film, MaxSampleLuminanceScalesBrightSamples) {
    FilmParams fp = filmParams(4, 4);
    fp.maxSampleLuminance = 2.f;
    Film film(fp, makeFilter("box"));
    auto tile = film.makeTile(film.sampleBounds());
    // Luminance weights sum to 1, so grey 10 has luminance 10 and is scaled to 2.
    tile->addSample(Vec2(0.5f, 0.5f), Spectrum(10.f));
    tile->addSample(Vec2(0.25f, 0.75f), Spectrum(1.f));
    // A coloured sample keeps its chromaticity: (0, 10, 0) has luminance 7.1516.
    tile->addSample(Vec2(1.5f, 0.5f), Spectrum(0.f, 10.f, 0.f));
    film.mergeTile(*tile);
    Image img = film.toImage();
    EXPECT_NEAR(img.at(0, 0, 0), 1.5f, 1e-5f);
    EXPECT_NEAR(img.at(1, 0, 1), 2.f / 0.715160f, 1e-4f);
    EXPECT_EQ(img.at(1, 0, 0), 0.f);
    EXPECT_EQ(img.at(2, 0, 0), 0.f);  // no samples: black
}

TEST(Film, InvalidRadianceCountsAsBlackAndImageHasNoNaN) {
    Film film(filmParams(2, 1), makeFilter("box"));
    auto tile = film.makeTile(film.sampleBounds());
    tile->addSample(Vec2(0.5f, 0.5f), Spectrum(std::nanf(""), 1.f, 1.f));
    tile->addSample(Vec2(0.5f, 0.5f), Spectrum(1.f));
    tile->addSample(Vec2(1.5f, 0.5f), Spectrum(Infinity));
    tile->addSample(Vec2(1.5f, 0.5f), Spectrum(-1.f));
    film.mergeTile(*tile);
    Image img = film.toImage();
    EXPECT_NEAR(img.at(0, 0, 0), 0.5f, 1e-6f);
    for (float v : img.pixels) EXPECT_FALSE(std::isnan(v));
    EXPECT_EQ(img.at(1, 0, 2), 0.f);
}

TEST(Film, ProgressivePassesAndClear) {
    Film film(filmParams(6, 5), makeFilter("triangle"));
    splatUniform(film, Spectrum(1.f), 4, 7);
    Image first = film.toImage();
    for (float v : first.pixels) EXPECT_NEAR(v, 1.f, 1e-5f);
    // The same sample positions again (same seed), so both passes have equal weight sums and
    // the image is the plain mean of 1 and 3.
    splatUniform(film, Spectrum(3.f), 4, 7);
    Image img = film.toImage();
    for (float v : img.pixels) EXPECT_NEAR(v, 2.f, 1e-5f);
    film.clear();
    EXPECT_EQ(film.weightSum(2, 2), 0.0);
    for (float v : film.toImage().pixels) EXPECT_EQ(v, 0.f);
}

TEST(Film, FixedOrderMergeIsDeterministicAcrossThreads) {
    // Random radiance spanning many magnitudes makes sums order-sensitive.
    auto render = [](int nThreads) {
        Film film(filmParams(48, 40, {.05, .95, 0, 1}), makeFilter("gaussian"));
        std::vector<Bounds2i> tb = film.sampleTiles(8);
        std::vector<std::unique_ptr<FilmTile>> tiles(tb.size());
        auto work = [&](int t0) {
            for (size_t i = t0; i < tb.size(); i += nThreads) {
                auto tile = film.makeTile(tb[i]);
                std::mt19937 rng{uint32_t(i)};
                std::uniform_real_distribution<float> u(0.f, 1.f);
                for (int y = tb[i].pMin.y; y < tb[i].pMax.y; ++y)
                    for (int x = tb[i].pMin.x; x < tb[i].pMax.x; ++x)
                        for (int s = 0; s < 4; ++s)
                            tile->addSample(Vec2(x + u(rng), y + u(rng)),
                                            Spectrum(std::exp(20.f * u(rng) - 10.f)));
                tiles[i] = std::move(tile);
            }
        };
        std::vector<std::thread> threads;
        for (int t = 0; t < nThreads; ++t) threads.emplace_back(work, t);
        for (auto& th : threads) th.join();
        film.mergeTiles(tiles);
        return film.toImage();
    };
    Image a = render(1), b = render(2), c = render(3);
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    EXPECT_TRUE(a.pixels == b.pixels);
    EXPECT_TRUE(a.pixels == c.pixels);
}

}  // namespace
}  // namespace rlpbrt
