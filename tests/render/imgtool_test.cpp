// rlpbrt-imgtool's side-by-side command (the demo's comparison picture): the layout (left,
// a 4-pixel gap, right; a caption strip below), the pixels of both images, the captions'
// ink drawn with the built-in font, and errors for images of different sizes or bad usage.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "cli_run.h"
#include "render/image_io.h"

namespace rlpbrt {
namespace {

Image constant(int w, int h, float v) {
    Image img;
    img.width = w;
    img.height = h;
    img.channels = 3;
    img.pixels.assign(size_t(w) * h * 3, v);
    return img;
}

std::string tempPath(const std::string& name) {
    return ::testing::TempDir() + "imgtool_" + std::to_string(getpid()) + "_" + name;
}

int countAbove(const Image& img, int x0, int x1, int y0, int y1, float v) {
    int n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) n += img.at(x, y, 0) > v;
    return n;
}

TEST(Imgtool, SideBySideLayoutAndCaptions) {
    const std::string a = tempPath("a.exr"), b = tempPath("b.exr"), out = tempPath("ab.png");
    std::string err;
    ASSERT_TRUE(writeImage(a, constant(40, 30, 0.2f), {}, &err)) << err;
    ASSERT_TRUE(writeImage(b, constant(40, 30, 0.5f), {}, &err)) << err;
    // A capital I has 11 pixels of ink in the 5x7 font; two of them 22.
    auto r = test::runCommand(std::string(RLPBRT_IMGTOOL) +
                          " side-by-side " + a + " " + b + " " + out + " I II");
    ASSERT_EQ(r.status, 0) << r.output;
    Image img;
    ASSERT_TRUE(readImage(out, &img, &err)) << err;
    // 40 + 4 + 40 wide; 30 + a strip of 6 + 7 + 6 pixels (font scale 1 below 200 pixels).
    ASSERT_EQ(img.width, 84);
    ASSERT_EQ(img.height, 49);
    const float left = img.at(10, 10, 0), right = img.at(60, 10, 0);
    EXPECT_NEAR(left, std::round(255 * linearToSrgb(0.2f)) / 255, 1e-6);
    EXPECT_NEAR(right, std::round(255 * linearToSrgb(0.5f)) / 255, 1e-6);
    EXPECT_EQ(countAbove(img, 40, 44, 0, 30, 0.f), 0) << "the gap is black";
    EXPECT_EQ(countAbove(img, 0, 40, 0, 30, 0.f), 40 * 30);
    EXPECT_EQ(countAbove(img, 0, 42, 30, 49, 0.99f), 11);
    EXPECT_EQ(countAbove(img, 42, 84, 30, 49, 0.99f), 22);
    EXPECT_EQ(countAbove(img, 0, 84, 30, 49, 0.f), 33) << "the strip is black but for the ink";
    std::remove(out.c_str());

    // Different sizes: an error, no output.
    const std::string c = tempPath("c.exr");
    ASSERT_TRUE(writeImage(c, constant(41, 30, 0.5f), {}, &err)) << err;
    r = test::runCommand(std::string(RLPBRT_IMGTOOL) + " side-by-side " +
                     a + " " + c + " " + out);
    EXPECT_EQ(r.status, 1);
    EXPECT_NE(r.output.find("image sizes differ"), std::string::npos) << r.output;
    EXPECT_NE(access(out.c_str(), F_OK), 0);
    // One caption only: usage, exit 2.
    r = test::runCommand(std::string(RLPBRT_IMGTOOL) + " side-by-side " +
                     a + " " + b + " " + out + " I");
    EXPECT_EQ(r.status, 2);
    EXPECT_NE(r.output.find("usage"), std::string::npos) << r.output;
    for (const std::string& p : {a, b, c}) std::remove(p.c_str());
}

// pair A B REF: the pair's error (half the weighted squared difference), each render's
// relmse_trim against REF and their mean less the pair's error (REF's own error).
TEST(Imgtool, PairSeparatesTheReferencesError) {
    const std::string a = tempPath("pa.exr"), b = tempPath("pb.exr"), r = tempPath("pr.exr");
    std::string err;
    // Against ref 0.1: a = 0.3 and b = 0.1 differ by 0.2: (0.2^2 / 0.02) / 2 = 1 per pixel;
    // a's relmse_trim is 2, b's 0: reference error (2 + 0) / 2 - 1 = 0.
    ASSERT_TRUE(writeImage(a, constant(20, 20, 0.3f), {}, &err)) << err;
    ASSERT_TRUE(writeImage(b, constant(20, 20, 0.1f), {}, &err)) << err;
    ASSERT_TRUE(writeImage(r, constant(20, 20, 0.1f), {}, &err)) << err;
    auto run = test::runCommand(std::string(RLPBRT_IMGTOOL) + " pair " + a + " " + b + " " + r);
    ASSERT_EQ(run.status, 0) << run.output;
    auto field = [&](const std::string& key) {
        const size_t at = run.output.find("\"" + key + "\": ");
        EXPECT_NE(at, std::string::npos) << key << " in " << run.output;
        return at == std::string::npos ? NAN : std::stod(run.output.substr(at + key.size() + 4));
    };
    EXPECT_NEAR(field("pair_relmse"), 1.0, 1e-5);
    EXPECT_NEAR(field("relmse_a"), 2.0, 1e-5);
    EXPECT_NEAR(field("relmse_b"), 0.0, 1e-9);
    EXPECT_NEAR(field("reference_error"), 0.0, 1e-5);
    // A missing argument: usage, exit 2.
    run = test::runCommand(std::string(RLPBRT_IMGTOOL) + " pair " + a + " " + b);
    EXPECT_EQ(run.status, 2);
    for (const std::string& p : {a, b, r}) std::remove(p.c_str());
}

}  // namespace
}  // namespace rlpbrt
