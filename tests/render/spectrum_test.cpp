#include "render/spectrum.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "parser/spd.h"
#include "shared_data.h"

namespace rlpbrt {
namespace {

double sumTable(const float* t) {
    double s = 0;
    for (int i = 0; i < kCieSamples; ++i) s += t[i];
    return s;
}

// The test's own implementation of the pbrt-v3 conversion, written independently of
// spectrum.cpp: linear scan for the bracketing samples, explicit matrix.
Vec3 referenceRGB(const std::vector<double>& pairs) {
    const size_t n = pairs.size() / 2;
    double xyz[3] = {0, 0, 0};
    for (int i = 0; i < kCieSamples; ++i) {
        double l = 360.0 + i;
        double v;
        if (l <= pairs[0]) {
            v = pairs[1];
        } else if (l >= pairs[2 * (n - 1)]) {
            v = pairs[2 * (n - 1) + 1];
        } else {
            size_t j = 0;
            while (!(pairs[2 * j] <= l && l <= pairs[2 * (j + 1)])) ++j;
            double a = pairs[2 * j], b = pairs[2 * (j + 1)];
            v = pairs[2 * j + 1] + (l - a) / (b - a) * (pairs[2 * j + 3] - pairs[2 * j + 1]);
        }
        xyz[0] += v * kCieX[i];
        xyz[1] += v * kCieY[i];
        xyz[2] += v * kCieZ[i];
    }
    for (double& c : xyz) c *= 470.0 / (106.856895 * 471.0);
    const double m[3][3] = {{3.240479, -1.537150, -0.498535},
                            {-0.969256, 1.875991, 0.041556},
                            {0.055648, -0.204043, 1.057311}};
    Vec3 rgb;
    for (int r = 0; r < 3; ++r)
        rgb[r] = float(m[r][0] * xyz[0] + m[r][1] * xyz[1] + m[r][2] * xyz[2]);
    return rgb;
}

void expectNear(const Spectrum& a, const Vec3& b, double relTol) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(a[c], b[c], relTol * std::max(1e-6f, std::abs(b[c]))) << "channel " << c;
}

std::string scenesDir() {
    return rlpbrt::test::sharedDir() + "/scenes/";
}

TEST(Spectrum, CieTablesIntegrateToKnownValues) {
    // 1 nm spacing, so the sum is the integral in nm. pbrt-v3 uses 106.856895 for y-bar.
    EXPECT_NEAR(sumTable(kCieY), kCieYIntegral, 1e-3);
    // Equal-energy white has x = y = z = 1/3: the three integrals agree to about 0.05%.
    EXPECT_NEAR(sumTable(kCieX) / sumTable(kCieY), 1.0, 5e-4);
    EXPECT_NEAR(sumTable(kCieZ) / sumTable(kCieY), 1.0, 5e-4);
    // Spot values of the CIE 1931 standard table.
    EXPECT_FLOAT_EQ(kCieY[555 - 360], 1.0f);
    EXPECT_FLOAT_EQ(kCieX[600 - 360], 1.0622f);
    EXPECT_FLOAT_EQ(kCieZ[445 - 360], 1.7826f);
    EXPECT_EQ(kCieZ[650 - 360], 0.0f);
    EXPECT_EQ(kCieZ[kCieSamples - 1], 0.0f);
}

TEST(Spectrum, XyzRgbMatricesAreInverse) {
    Spectrum rgb(0.3f, 0.5f, 0.9f);
    Spectrum back = xyzToRGB(rgbToXYZ(rgb));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(back[c], rgb[c], 1e-5f);
    EXPECT_NEAR(rgbToXYZ(rgb).y, luminance(rgb), 1e-6f);
    // D65 white: sRGB (1,1,1) has Y = 1.
    EXPECT_NEAR(rgbToXYZ(Spectrum(1.f)).y, 1.0f, 1e-5f);
}

TEST(Spectrum, ConstantSpectrumGivesPbrtValue) {
    // A constant 1 is equal-energy white E, not D65, so it is not RGB (1,1,1) in sRGB:
    // XYZ = sum(xyzbar) * 470 / (106.856895 * 471) ~= (0.99796, 0.99788, 0.99821), which
    // pbrt-v3's matrix maps to (1.20233, 0.94622, 0.90734) (computed independently in
    // double precision from the tables).
    const double l[2] = {400, 700}, v[2] = {1, 1};
    Spectrum c = rgbFromSampled(l, v, 2);
    expectNear(c, Vec3(1.2023297f, 0.9462152f, 0.9073396f), 1e-5);
    EXPECT_NEAR(rgbToXYZ(c).y, 470.0 / 471.0 * sumTable(kCieY) / kCieYIntegral, 1e-5);
    // A single sample is a constant too.
    const double l1[1] = {550}, v1[1] = {2};
    expectNear(rgbFromSampled(l1, v1, 1), 2.f * c, 1e-5);
    EXPECT_EQ(rgbFromSampled(l, v, 0), Spectrum(0.f));
}

TEST(Spectrum, UnsortedSamplesAreSorted) {
    const double ls[4] = {400, 500, 600, 700}, vs[4] = {0.1, 0.8, 0.3, 0.5};
    const double lu[4] = {600, 400, 700, 500}, vu[4] = {0.3, 0.1, 0.5, 0.8};
    Spectrum a = rgbFromSampled(ls, vs, 4), b = rgbFromSampled(lu, vu, 4);
    EXPECT_EQ(a, b);
    expectNear(a, referenceRGB({400, 0.1, 500, 0.8, 600, 0.3, 700, 0.5}), 1e-5);
}

TEST(Spectrum, InterpolationBetweenSamplesIsLinear) {
    // A ramp from 0 at 380 nm to 1 at 780 nm, given by its end points only and by 41 points
    // on the same line: both describe the same function.
    const double l2[2] = {380, 780}, v2[2] = {0, 1};
    std::vector<double> l41, v41;
    for (int i = 0; i <= 40; ++i) {
        l41.push_back(380 + 10 * i);
        v41.push_back(i / 40.0);
    }
    expectNear(rgbFromSampled(l2, v2, 2), rgbFromSampled(l41.data(), v41.data(), 41), 1e-5);
    // A ramp is reddish: more weight at long wavelengths.
    Spectrum c = rgbFromSampled(l2, v2, 2);
    EXPECT_GT(c.x, c.y);
    EXPECT_GT(c.y, c.z);
}

TEST(Spectrum, PlanckLaw) {
    // B(500 nm, 5000 K) = 2hc^2 / (l^5 (exp(hc / (l k T)) - 1)) = 1.2107186e13 W/(m^2 sr m)
    // (evaluated separately with the same constants).
    double l = 500, le;
    blackbody(&l, 1, 5000, &le);
    EXPECT_NEAR(le, 1.2107186e13, 1e-6 * 1.2107186e13);
    // Normalised: 1 at Wien's peak, below 1 elsewhere; T <= 0 gives zero.
    double peak = 2.8977721e-3 / 5000 * 1e9, lams[3] = {peak, 400, 800}, out[3];
    blackbodyNormalized(lams, 3, 5000, out);
    EXPECT_NEAR(out[0], 1.0, 1e-12);
    EXPECT_LT(out[1], 1.0);
    EXPECT_LT(out[2], 1.0);
    blackbodyNormalized(lams, 3, 0, out);
    EXPECT_EQ(out[0], 0.0);
}

TEST(Spectrum, BlackbodyColours) {
    // 6500 K is close to D65, hence close to sRGB white (the Planckian locus passes just
    // below D65): channel ratios within 10% of 1.
    Spectrum w = blackbodyRGB(6500, 1);
    EXPECT_NEAR(w.x / w.y, 1.0, 0.1);
    EXPECT_NEAR(w.z / w.y, 1.0, 0.1);
    // Independent evaluation of the same definition.
    std::vector<double> pairs;
    for (int i = 0; i < kCieSamples; ++i) {
        double l = 360.0 + i, le;
        blackbodyNormalized(&l, 1, 6500, &le);
        pairs.push_back(l);
        pairs.push_back(le);
    }
    expectNear(w, referenceRGB(pairs), 1e-5);
    // Warm light is red > green > blue; the scale multiplies.
    Spectrum warm = blackbodyRGB(2700, 1);
    EXPECT_GT(warm.x, warm.y);
    EXPECT_GT(warm.y, warm.z);
    expectNear(blackbodyRGB(5000, 500), 500.f * blackbodyRGB(5000, 1), 1e-6);
}

TEST(Spectrum, FromParam) {
    Param p;
    p.type = ParamType::RGB;
    p.numbers = {0.1, 0.2, 0.3, 9, 9, 9};  // only the first value counts
    EXPECT_EQ(spectrumFromParam(p), Spectrum(0.1f, 0.2f, 0.3f));

    p.type = ParamType::XYZ;
    p.numbers = {0.4, 0.5, 0.6};
    expectNear(spectrumFromParam(p), xyzToRGB(Vec3(0.4f, 0.5f, 0.6f)), 1e-6);

    p.type = ParamType::Blackbody;
    p.numbers = {5000, 10};
    expectNear(spectrumFromParam(p), blackbodyRGB(5000, 10), 1e-6);
    p.numbers = {5000};  // missing scale: 1
    expectNear(spectrumFromParam(p), blackbodyRGB(5000, 1), 1e-6);

    p.type = ParamType::Spectrum;
    p.numbers = {700, 0.5, 400, 0.1, 550, 0.9};  // inline, unsorted
    expectNear(spectrumFromParam(p), referenceRGB({400, 0.1, 550, 0.9, 700, 0.5}), 1e-5);
    p.numbers.clear();
    EXPECT_EQ(spectrumFromParam(p), Spectrum(0.f));

    p.type = ParamType::Float;
    p.numbers = {1};
    EXPECT_EQ(spectrumFromParam(p), Spectrum(0.f));
}

struct MetalCase {
    const char* file;
    Vec3 approx;  // plausible RGB (published RGB fits of the same data, e.g. pbrt-v4/Mitsuba)
    float tol;
};

TEST(Spectrum, MetalSpdFiles) {
    RLPBRT_REQUIRE_SHARED();
    const std::string dir = scenesDir();
    const MetalCase cases[] = {
        {"breakfast/spds/Ag.eta.spd", Vec3(0.155f, 0.117f, 0.138f), 0.01f},
        {"breakfast/spds/Ag.k.spd", Vec3(4.83f, 3.12f, 2.15f), 0.05f},
        {"metal-spheres-envmap/spds/Ag.eta.spd", Vec3(0.155f, 0.117f, 0.138f), 0.01f},
        {"metal-spheres-envmap/spds/Ag.k.spd", Vec3(4.83f, 3.12f, 2.15f), 0.05f},
        {"breakfast/spds/Al.eta.spd", Vec3(1.66f, 0.88f, 0.52f), 0.02f},
        {"breakfast/spds/Al.k.spd", Vec3(9.22f, 6.27f, 4.84f), 0.05f},
    };
    for (const MetalCase& mc : cases) {
        SCOPED_TRACE(mc.file);
        std::vector<double> pairs;
        std::string err;
        ASSERT_TRUE(readSpdFile(dir + mc.file, &pairs, &err)) << err;
        EXPECT_EQ(pairs.size(), 112u);  // 56 (lambda, value) lines
        Param p;
        p.type = ParamType::Spectrum;
        p.numbers = pairs;
        Spectrum rgb = spectrumFromParam(p);
        // Same definition, independent code: agrees to float rounding.
        expectNear(rgb, referenceRGB(pairs), 1e-5);
        // Measured here: Ag eta (0.1549, 0.1165, 0.1381), k (4.818, 3.116, 2.142);
        // Al eta (1.654, 0.8785, 0.5201), k (9.204, 6.256, 4.827).
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(rgb[c], mc.approx[c], mc.tol * std::max(1.f, mc.approx[c]));
    }
}

class SpdFileTest : public ::testing::Test {
protected:
    // Names unique per test and process: ctest runs this fixture's tests in parallel.
    std::string write(const std::string& text) {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string path = (std::filesystem::temp_directory_path() /
                            (std::string("rlpbrt_spd_") + info->name() + "_" +
                             std::to_string(getpid()) + "_" + std::to_string(counter_++) +
                             ".spd"))
                               .string();
        std::ofstream(path) << text;
        files_.push_back(path);
        return path;
    }
    void TearDown() override {
        for (const auto& f : files_) std::remove(f.c_str());
    }
    std::vector<std::string> files_;
    int counter_ = 0;
};

TEST_F(SpdFileTest, ParsesNumbersAndComments) {
    std::vector<double> pairs = {42};  // appended to
    std::string err;
    ASSERT_TRUE(readSpdFile(write("# header\n400 0.5 # trailing\n  5e2\t1.25E0\n\n600 -2\n"),
                            &pairs, &err))
        << err;
    EXPECT_EQ(pairs, (std::vector<double>{42, 400, 0.5, 500, 1.25, 600, -2}));
}

TEST_F(SpdFileTest, Errors) {
    std::vector<double> pairs;
    std::string err;
    EXPECT_FALSE(readSpdFile("/nonexistent/dir/x.spd", &pairs, &err));
    EXPECT_NE(err.find("cannot open"), std::string::npos);
    err.clear();
    EXPECT_FALSE(readSpdFile(write("400 0.5\n500 abc\n"), &pairs, &err));
    EXPECT_NE(err.find(":2:"), std::string::npos) << err;
    EXPECT_FALSE(readSpdFile(write("400 0.5 500\n"), &pairs, &err));
    EXPECT_NE(err.find("odd"), std::string::npos) << err;
    EXPECT_FALSE(readSpdFile(write("# nothing\n"), &pairs, &err));
    EXPECT_FALSE(readSpdFile(write("400,0.5\n"), &pairs, &err));
    EXPECT_TRUE(pairs.empty());
}

}  // namespace
}  // namespace rlpbrt
