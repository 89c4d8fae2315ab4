// The "fourier" material's tabulated BSDF (render/fourier_bsdf.*): a small generator of
// pbrt-v3's .bsdf format tabulates BSDFs that can also be evaluated directly (a Lambertian and
// a rough conductor), writes and reads the file back, and the tabulated lobe must agree with
// the direct one (values and albedo) and sample its own pdf (chi-square).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

#include "chi2.h"
#include "parser/diagnostics.h"
#include "render/bxdfs.h"
#include "render/fourier_bsdf.h"
#include "render/render.h"
#include "render/scene.h"
#include "render/scene_builder.h"

namespace rlpbrt {
namespace {

using BsdfFn = std::function<Spectrum(const Vec3& wo, const Vec3& wi)>;

// The generator: tabulates f at nMu cosines (denser towards +-1) with mMax Fourier
// coefficients of f(wo, wi) |mu_i| per channel (Y, or Y, R, B), computed by the midpoint rule
// over phi (exact for trigonometric polynomials of degree below the number of points), and the
// cdf rows as the integral of the a0 spline (pbrt-v3's layout, see fourier_bsdf.h).
FourierTable tabulate(const BsdfFn& f, int nMu, int mMax, int nChannels, float eta) {
    FourierTable t;
    t.eta = eta;
    t.nMu = nMu;
    t.mMax = mMax;
    t.nChannels = nChannels;
    for (int i = 0; i < nMu; ++i) t.mu.push_back(-float(std::cos(Pi * double(i) / (nMu - 1))));
    t.mu.front() = -1.f;
    t.mu.back() = 1.f;
    t.mu[size_t(nMu / 2)] = 0.f;
    const int nPhi = 4 * mMax + 8;
    for (int o = 0; o < nMu; ++o) {
        float muO = t.mu[size_t(o)];
        Vec3 wo(safeSqrt(1.f - muO * muO), 0.f, muO);
        for (int i = 0; i < nMu; ++i) {
            float muI = t.mu[size_t(i)], sinI = safeSqrt(1.f - muI * muI);
            std::vector<double> coeff(size_t(nChannels) * mMax, 0.0);
            for (int j = 0; j < nPhi; ++j) {
                double phi = 2.0 * Pi * (j + 0.5) / nPhi;
                Vec3 wi = -Vec3(sinI * float(std::cos(phi)), sinI * float(std::sin(phi)), muI);
                Spectrum v = f(wo, wi) * std::abs(muI);
                float ch[3] = {luminance(v), v.x, v.z};
                for (int c = 0; c < nChannels; ++c)
                    for (int k = 0; k < mMax; ++k)
                        coeff[size_t(c) * mMax + k] +=
                            ch[c] * std::cos(k * phi) * (k == 0 ? 1.0 : 2.0) / nPhi;
            }
            t.aOffset.push_back(int(t.a.size()));
            t.m.push_back(mMax);
            for (double c : coeff) t.a.push_back(float(c));
        }
    }
    t.a0.resize(size_t(nMu) * nMu);
    for (size_t k = 0; k < t.a0.size(); ++k) t.a0[k] = t.a[size_t(t.aOffset[k])];
    t.cdf.resize(size_t(nMu) * nMu);
    for (int o = 0; o < nMu; ++o)
        integrateCatmullRom(nMu, t.mu.data(), &t.a0[size_t(o) * nMu], &t.cdf[size_t(o) * nMu]);
    return t;
}

// Writes the table as a .bsdf file and reads it back (the format round trip).
FourierTable roundTrip(const FourierTable& t, const std::string& name) {
    std::string path = std::filesystem::temp_directory_path().string() + "/rlpbrt-" +
                       std::to_string(getpid()) + "-" + name + ".bsdf";
    std::string err;
    EXPECT_TRUE(writeFourierTable(path, t, &err)) << err;
    FourierTable back;
    EXPECT_TRUE(readFourierTable(path, &back, &err)) << err;
    std::remove(path.c_str());
    return back;
}

const Spectrum kCopperEta(0.200438f, 0.924033f, 1.10221f), kCopperK(3.91295f, 2.45285f, 2.14219f);

BsdfFn lambertian() {
    LambertianReflection l(Spectrum(0.6f));
    return [l](const Vec3& wo, const Vec3& wi) {
        return wo.z * wi.z > 0.f ? l.f(wo, wi) : Spectrum(0.f);
    };
}

// A diffuse sheet: Lambertian reflection and transmission (continuous across mu = 0).
BsdfFn diffuseSheet() {
    return [](const Vec3&, const Vec3&) { return Spectrum(0.4f * InvPi); };
}

BsdfFn roughCopper() {
    MicrofacetReflection r(Spectrum(1.f),
                           MicrofacetDistribution(MicrofacetType::TrowbridgeReitz, 0.5f, 0.5f),
                           Fresnel::conductor(Spectrum(1.f), kCopperEta, kCopperK));
    return [r](const Vec3& wo, const Vec3& wi) {
        return wo.z * wi.z > 0.f ? r.f(wo, wi) : Spectrum(0.f);
    };
}

Vec3 randomDir(std::mt19937& rng, float minAbsCos) {
    std::uniform_real_distribution<float> U(0.f, 1.f);
    for (;;) {
        float z = 2.f * U(rng) - 1.f;
        if (std::abs(z) < minAbsCos) continue;
        float phi = 2.f * Pi * U(rng), s = safeSqrt(1.f - z * z);
        return Vec3(s * std::cos(phi), s * std::sin(phi), z);
    }
}

TEST(Fourier, FileRoundTripKeepsTheTable) {
    FourierTable t = tabulate(roughCopper(), 9, 6, 3, 1.3f);
    FourierTable back = roundTrip(t, "roundtrip");
    EXPECT_EQ(back.nMu, 9);
    EXPECT_EQ(back.mMax, 6);
    EXPECT_EQ(back.nChannels, 3);
    EXPECT_EQ(back.eta, 1.3f);
    EXPECT_EQ(back.mu, t.mu);
    EXPECT_EQ(back.cdf, t.cdf);
    EXPECT_EQ(back.a, t.a);
    EXPECT_EQ(back.a0, t.a0);
}

// A reflection-only BSDF steps to 0 at mu = 0: the splines are exact from the second node
// away from 0 on (33 nodes: the nodes next to 0 are at +-0.098 and +-0.195).
TEST(Fourier, TabulatedLambertianMatchesDirect) {
    FourierTable t = roundTrip(tabulate(lambertian(), 33, 4, 1, 1.f), "lambert");
    FourierBSDF tab(&t, TransportMode::Radiance);
    std::mt19937 rng(1);
    for (int n = 0; n < 500; ++n) {
        Vec3 wo = randomDir(rng, 0.2f), wi = randomDir(rng, 0.2f);
        Spectrum want = wo.z * wi.z > 0.f ? Spectrum(0.6f * InvPi) : Spectrum(0.f);
        Spectrum got = tab.f(wo, wi);
        // |mu_i| R / pi is linear in mu_i: the spline reproduces it away from mu_i = 0.
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-4f);
    }
}

TEST(Fourier, TabulatedRoughConductorMatchesDirect) {
    BsdfFn direct = roughCopper();
    FourierTable t = roundTrip(tabulate(direct, 41, 24, 3, 1.f), "copper");
    FourierBSDF tab(&t, TransportMode::Radiance);
    std::mt19937 rng(2);
    double sumErr = 0, sumRef = 0;
    for (int n = 0; n < 2000; ++n) {
        Vec3 wo = randomDir(rng, 0.2f), wi = randomDir(rng, 0.2f);
        Spectrum want = direct(wo, wi), got = tab.f(wo, wi);
        for (int c = 0; c < 3; ++c) {
            // Each value within 5% of the direct one (plus a floor for the dark tails).
            EXPECT_NEAR(got[c], want[c], 0.05f * want[c] + 2e-3f);
            sumErr += std::abs(got[c] - want[c]);
            sumRef += want[c];
        }
    }
    EXPECT_LT(sumErr / sumRef, 0.01);  // and within 1% on average
}

// The albedo (f |cos| / pdf over the lobe's own samples) agrees with the direct lobe's.
TEST(Fourier, TabulatedAlbedoMatchesDirect) {
    MicrofacetReflection direct(Spectrum(1.f),
                                MicrofacetDistribution(MicrofacetType::TrowbridgeReitz, 0.5f, 0.5f),
                                Fresnel::conductor(Spectrum(1.f), kCopperEta, kCopperK));
    FourierTable t = tabulate(roughCopper(), 41, 24, 3, 1.f);
    FourierBSDF tab(&t, TransportMode::Radiance);
    for (float cosO : {0.9f, 0.5f, 0.25f}) {
        Vec3 wo(safeSqrt(1.f - cosO * cosO), 0.f, cosO);
        std::mt19937_64 rng(7);
        std::uniform_real_distribution<float> U(0.f, 1.f);
        const int n = 40000;
        double a = 0, b = 0, a2 = 0, b2 = 0;
        for (int i = 0; i < n; ++i) {
            Vec2 u(U(rng), U(rng));
            BxDFSample s = tab.sampleF(wo, 0.f, u);
            double v = s.valid() ? luminance(s.f) * std::abs(s.wi.z) / s.pdf : 0.0;
            a += v;
            a2 += v * v;
            BxDFSample d = direct.sampleF(wo, 0.f, u);
            double w = d.valid() ? luminance(d.f) * std::abs(d.wi.z) / d.pdf : 0.0;
            b += w;
            b2 += w * w;
        }
        a /= n;
        b /= n;
        double se = std::sqrt((a2 / n - a * a) / n + (b2 / n - b * b) / n);
        EXPECT_NEAR(a, b, 5 * se + 0.01 * b) << "cos theta_o " << cosO;
    }
}

// Tables: 0 Lambertian reflection, 1 rough copper, 2 diffuse sheet. A reflection-only table
// steps to 0 at mu = 0 and its splines overshoot below 0 next to it: pbrt-v3's pdf clamps Y
// there, so it no longer integrates to 1 for wo near grazing (copper at cos 0.2: 1.001). The
// grazing cases therefore use the sheet, which is continuous across mu = 0.
struct Chi2Case {
    std::string name;
    int table;
    Vec3 wo;
};

void PrintTo(const Chi2Case& c, std::ostream* os) { *os << c.name; }

class FourierChi2 : public ::testing::TestWithParam<Chi2Case> {};

TEST_P(FourierChi2, SampleMatchesPdf) {
    const Chi2Case& c = GetParam();
    static const FourierTable lambert = tabulate(lambertian(), 33, 4, 1, 1.f);
    static const FourierTable copper = tabulate(roughCopper(), 41, 24, 3, 1.f);
    static const FourierTable sheet = tabulate(diffuseSheet(), 33, 4, 1, 1.f);
    FourierBSDF tab(c.table == 0 ? &lambert : c.table == 1 ? &copper : &sheet,
                    TransportMode::Radiance);
    auto sample = [&](const Vec3& u) {
        BxDFSample s = tab.sampleF(c.wo, u.x, Vec2(u.y, u.z));
        if (!s.valid()) return chi2::SphereSample();
        return chi2::SphereSample{s.wi, s.pdf};
    };
    auto pdf = [&](const Vec3& wi) { return tab.pdf(c.wo, wi); };
    chi2::SphereOptions opt;
    opt.sampleCount = 200000;
    opt.numTests = 7;
    opt.seed = std::hash<std::string>()(c.name);
    chi2::SphereResult r = chi2::testSphere(sample, pdf, opt);
    EXPECT_TRUE(r.passed) << r.message;
}

Vec3 dirFromCos(float c, float phi) {
    float s = safeSqrt(1.f - c * c);
    return Vec3(s * std::cos(phi), s * std::sin(phi), c);
}

INSTANTIATE_TEST_SUITE_P(
    Tables, FourierChi2,
    ::testing::Values(Chi2Case{"Lambert_Normal", 0, dirFromCos(0.95f, 1.1f)},
                      Chi2Case{"Lambert_Mid", 0, dirFromCos(0.5f, 2.3f)},
                      Chi2Case{"Lambert_Below", 0, dirFromCos(-0.6f, 5.2f)},
                      Chi2Case{"Copper_Normal", 1, dirFromCos(0.95f, 1.1f)},
                      Chi2Case{"Copper_Mid", 1, dirFromCos(0.5f, 2.3f)},
                      Chi2Case{"Sheet_Grazing", 2, dirFromCos(0.08f, 4.0f)},
                      Chi2Case{"Sheet_Below", 2, dirFromCos(-0.6f, 5.2f)}),
    [](const auto& info) { return info.param.name; });

// Through a scene: a sphere of the tabulated Lambertian under a uniform sky renders as the
// same sphere of "matte" (the image means agree), and a missing .bsdf file is a located
// warning and a black surface (pbrt-v3's substitute).
double renderMean(const std::string& material, Diagnostics& diag, bool* ok) {
    const std::string path = std::filesystem::temp_directory_path().string() + "/rlpbrt-" +
                             std::to_string(getpid()) + "-fourier.pbrt";
    std::ofstream(path) << "LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" 30\n"
                           "Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16\n"
                           "Integrator \"path\" \"integer maxdepth\" 1\nWorldBegin\n"
                           "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"
                        << material << "\nShape \"sphere\"\nWorldEnd\n";
    SceneDesc desc;
    *ok = loadSceneDesc(path, diag, &desc);
    std::remove(path.c_str());
    if (!*ok) return 0;
    BuildOptions bo;
    bo.sppOverride = 256;
    bo.seed = 5;
    std::unique_ptr<Scene> scene = buildScene(desc, bo, diag);
    *ok = scene != nullptr && diag.errorCount() == 0;
    if (!*ok) return 0;
    RenderOptions ro;
    ro.nThreads = 1;
    Image img = render(*scene, ro).image;
    double s = 0;
    for (float v : img.pixels) s += v;
    return s / double(img.pixels.size());
}

TEST(Fourier, MaterialRendersTheTable) {
    const std::string bsdf = std::filesystem::temp_directory_path().string() + "/rlpbrt-" +
                             std::to_string(getpid()) + "-lambert.bsdf";
    std::string err;
    ASSERT_TRUE(writeFourierTable(bsdf, tabulate(lambertian(), 33, 4, 1, 1.f), &err)) << err;
    Diagnostics d1, d2, d3;
    for (Diagnostics* d : {&d1, &d2, &d3}) d->setStream(nullptr);
    bool ok1, ok2, ok3;
    double tab = renderMean("Material \"fourier\" \"string bsdffile\" \"" + bsdf + "\"", d1, &ok1);
    std::remove(bsdf.c_str());
    double matte = renderMean("Material \"matte\" \"rgb Kd\" [.6 .6 .6]", d2, &ok2);
    double black = renderMean("Material \"fourier\" \"string bsdffile\" \"/nonexistent.bsdf\"",
                              d3, &ok3);
    ASSERT_TRUE(ok1 && ok2 && ok3);
    EXPECT_EQ(d1.warningCount(), 0);
    EXPECT_NEAR(tab, matte, 0.01 * matte) << "black " << black;
    ASSERT_EQ(d3.warningCount(), 1);
    EXPECT_EQ(d3.all()[0].loc.line, 7);
    EXPECT_NE(d3.all()[0].message.find("/nonexistent.bsdf"), std::string::npos);
    EXPECT_LT(black, 0.8 * matte);  // the sphere is black: only the sky remains
}

TEST(Fourier, ReaderRejectsBadFiles) {
    const std::string dir = std::filesystem::temp_directory_path().string() + "/rlpbrt-" +
                            std::to_string(getpid());
    FourierTable t = tabulate(lambertian(), 5, 2, 1, 1.f);
    std::string err, good = dir + "-good.bsdf";
    ASSERT_TRUE(writeFourierTable(good, t, &err)) << err;
    std::ifstream in(good, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::remove(good.c_str());
    auto check = [&](const std::string& data, const char* what) {
        std::string path = dir + "-bad.bsdf";
        std::ofstream(path, std::ios::binary) << data;
        FourierTable out;
        std::string e;
        EXPECT_FALSE(readFourierTable(path, &out, &e)) << what;
        EXPECT_NE(e.find(what), std::string::npos) << e;
        std::remove(path.c_str());
    };
    check(bytes.substr(0, bytes.size() - 4), "truncated");
    check("SCATFUN\x02" + bytes.substr(8), "header");
    std::string badOffset = bytes;
    badOffset[64 + 4 * (5 + 25)] = char(100);  // the first block's offset past the end
    check(badOffset, "out of range");
    FourierTable missing;
    EXPECT_FALSE(readFourierTable(dir + "-none.bsdf", &missing, &err));
    EXPECT_NE(err.find("cannot open"), std::string::npos);
}

}  // namespace
}  // namespace rlpbrt
