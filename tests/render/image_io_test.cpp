#include "render/image_io.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <OpenImageIO/imageio.h>

#include "shared_data.h"

namespace rlpbrt {
namespace {

namespace fs = std::filesystem;

class ImageIoTest : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() /
               (std::string("rlpbrt_image_io_") + info->name() + "_" +
                std::to_string(std::random_device{}()));
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    // Names of all entries in the test directory.
    std::vector<std::string> listing() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename());
        return names;
    }

    fs::path dir_;
};

// A 5x3 RGB test image with distinct values, including ones outside [0,1].
Image testImage() {
    Image img;
    img.width = 5;
    img.height = 3;
    img.channels = 3;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (int i = 0; i < 5 * 3 * 3; ++i) img.pixels.push_back(u(rng));
    img.at(0, 0, 0) = 1234.5f;
    img.at(1, 0, 1) = -0.25f;
    img.at(2, 1, 2) = 3e-6f;
    img.at(4, 2, 0) = 0.f;
    return img;
}

// Writes raw 8-bit pixels with OIIO (nc channels) for the reader tests.
void writeRaw8(const std::string& file, int w, int h, int nc, const std::vector<uint8_t>& px) {
    auto out = OIIO::ImageOutput::create(file);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(w, h, nc, OIIO::TypeDesc::UINT8);
    if (nc == 4 || nc == 2) spec.attribute("oiio:UnassociatedAlpha", 1);
    ASSERT_TRUE(out->open(file, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px.data()));
    ASSERT_TRUE(out->close());
}

TEST(Srgb, TransferFunctions) {
    EXPECT_FLOAT_EQ(srgbToLinear(0.f), 0.f);
    EXPECT_FLOAT_EQ(srgbToLinear(1.f), 1.f);
    EXPECT_NEAR(srgbToLinear(0.5f), 0.2140411f, 1e-6f);  // ((0.555)/1.055)^2.4
    EXPECT_NEAR(srgbToLinear(0.04f), 0.04f / 12.92f, 1e-9f);
    EXPECT_FLOAT_EQ(linearToSrgb(0.f), 0.f);
    EXPECT_NEAR(linearToSrgb(1.f), 1.f, 1e-6f);
    EXPECT_NEAR(linearToSrgb(0.002f), 0.02584f, 1e-7f);
    for (float v = 0.f; v <= 1.f; v += 1.f / 64)
        EXPECT_NEAR(srgbToLinear(linearToSrgb(v)), v, 2e-6f) << v;
    // Both pieces meet at the thresholds (continuity to about 1e-4 by the standard).
    EXPECT_NEAR(srgbToLinear(0.04045f), srgbToLinear(0.040451f), 1e-5f);
}

TEST(PbrtGamma, DefaultByExtension) {
    EXPECT_TRUE(pbrtDefaultGamma("textures/a.png"));
    EXPECT_TRUE(pbrtDefaultGamma("A.TGA"));
    EXPECT_FALSE(pbrtDefaultGamma("x.exr"));
    EXPECT_FALSE(pbrtDefaultGamma("x.pfm"));
    EXPECT_FALSE(pbrtDefaultGamma("png"));
}

TEST_F(ImageIoTest, ExrRoundTripIsExactWithMetadata) {
    Image img = testImage();
    std::string err;
    ASSERT_TRUE(writeImage(path("a.exr"), img, {{"rlpbrt:spp", "64"}, {"rlpbrt:scene", "x y"}},
                           &err))
        << err;
    Image back;
    ImageFileInfo info;
    ASSERT_TRUE(readImage(path("a.exr"), &back, &err, &info)) << err;
    EXPECT_EQ(back.width, 5);
    EXPECT_EQ(back.height, 3);
    EXPECT_EQ(back.channels, 3);
    EXPECT_EQ(back.pixels, img.pixels);
    EXPECT_EQ(info.format, "openexr");
    EXPECT_EQ(info.fileChannels, 3);
    EXPECT_FALSE(info.eightBit);

    auto in = OIIO::ImageInput::open(path("a.exr"));
    ASSERT_TRUE(in);
    EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
    EXPECT_EQ(in->spec().get_string_attribute("rlpbrt:spp"), "64");
    EXPECT_EQ(in->spec().get_string_attribute("rlpbrt:scene"), "x y");
    EXPECT_EQ(listing(), std::vector<std::string>{"a.exr"});  // no temporary left
}

TEST_F(ImageIoTest, PngRoundTripWithinOneStep) {
    Image img = testImage();
    std::string err;
    ASSERT_TRUE(writeImage(path("a.png"), img, {{"Comment", "hello"}}, &err)) << err;
    Image back;
    ImageFileInfo info;
    ASSERT_TRUE(readImage(path("a.png"), &back, &err, &info)) << err;
    EXPECT_TRUE(info.eightBit);
    EXPECT_EQ(info.format, "png");
    ASSERT_EQ(back.pixels.size(), img.pixels.size());
    for (size_t i = 0; i < img.pixels.size(); ++i) {
        // The file holds round(255 * srgb(clamp(v))), read back as byte / 255.
        float encoded = linearToSrgb(std::min(std::max(img.pixels[i], 0.f), 1.f));
        EXPECT_LE(std::abs(back.pixels[i] - encoded), 0.5f / 255 + 1e-6f) << i;
        EXPECT_LE(std::abs(back.pixels[i] - encoded), 1.f / 255);
        // Values are exactly byte / 255.
        float b = back.pixels[i] * 255;
        EXPECT_NEAR(b, std::round(b), 1e-3f);
    }
    EXPECT_FLOAT_EQ(back.at(0, 0, 0), 1.f);   // 1234.5 clamps to white
    EXPECT_FLOAT_EQ(back.at(1, 0, 1), 0.f);   // negative clamps to black
}

TEST_F(ImageIoTest, PfmRoundTripIsExact) {
    Image img = testImage();
    std::string err;
    ASSERT_TRUE(writeImage(path("a.pfm"), img, {}, &err)) << err;
    std::ifstream f(path("a.pfm"), std::ios::binary);
    std::string magic, scale;
    int w, h;
    f >> magic >> w >> h >> scale;
    EXPECT_EQ(magic, "PF");
    EXPECT_EQ(w, 5);
    EXPECT_EQ(h, 3);
    EXPECT_LT(std::stof(scale), 0.f);  // little-endian
    Image back;
    ASSERT_TRUE(readImage(path("a.pfm"), &back, &err)) << err;
    EXPECT_EQ(back.pixels, img.pixels);  // also checks the bottom-to-top row order
}

TEST_F(ImageIoTest, HdrRoundTripWithinRgbePrecision) {
    Image img = testImage();
    img.at(1, 0, 1) = 0.25f;  // RGBE cannot store negative values
    std::string err;
    ASSERT_TRUE(writeImage(path("a.hdr"), img, {}, &err)) << err;
    Image back;
    ASSERT_TRUE(readImage(path("a.hdr"), &back, &err)) << err;
    ASSERT_EQ(back.pixels.size(), img.pixels.size());
    for (size_t p = 0; p < img.pixels.size() / 3; ++p) {
        // Shared exponent, 8-bit mantissas: error <= max channel / 128.
        float m = std::max({img.pixels[3 * p], img.pixels[3 * p + 1], img.pixels[3 * p + 2]});
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(back.pixels[3 * p + c], img.pixels[3 * p + c], m / 128) << p;
    }
}

TEST_F(ImageIoTest, OverwritesExistingFileAtomically) {
    Image img = testImage();
    std::string err;
    ASSERT_TRUE(writeImage(path("a.exr"), img, {}, &err)) << err;
    img.at(3, 1, 1) = 77.f;
    ASSERT_TRUE(writeImage(path("a.exr"), img, {}, &err)) << err;
    Image back;
    ASSERT_TRUE(readImage(path("a.exr"), &back, &err)) << err;
    EXPECT_EQ(back.at(3, 1, 1), 77.f);
    EXPECT_EQ(listing().size(), 1u);
}

TEST_F(ImageIoTest, UnknownExtensionIsAnErrorAndWritesNothing) {
    std::string err;
    EXPECT_FALSE(writeImage(path("a.jpg"), testImage(), {}, &err));
    EXPECT_NE(err.find("unknown image format"), std::string::npos) << err;
    EXPECT_FALSE(writeImage(path("noextension"), testImage(), {}, &err));
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageIoTest, UnwritableDirectoryIsAnError) {
    std::string err;
    EXPECT_FALSE(writeImage(path("missing/dir/a.exr"), testImage(), {}, &err));
    EXPECT_FALSE(err.empty());
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageIoTest, FailedRenameRemovesTemporary) {
    // The target is an existing directory: writing succeeds, the final rename fails.
    fs::create_directory(path("taken.png"));
    std::string err;
    EXPECT_FALSE(writeImage(path("taken.png"), testImage(), {}, &err));
    EXPECT_NE(err.find("rename"), std::string::npos) << err;
    EXPECT_EQ(listing(), std::vector<std::string>{"taken.png"});
    EXPECT_TRUE(fs::is_directory(path("taken.png")));
}

TEST_F(ImageIoTest, RejectsNonRgbImages) {
    Image img;
    img.width = 2;
    img.height = 1;
    img.channels = 4;
    img.pixels.assign(8, 0.5f);
    std::string err;
    EXPECT_FALSE(writeImage(path("a.exr"), img, {}, &err));
    EXPECT_FALSE(writeImage(path("b.exr"), Image{}, {}, &err));
    EXPECT_TRUE(listing().empty());
}

#ifdef NDEBUG
TEST_F(ImageIoTest, NonFiniteValuesAreWrittenAsZero) {
    Image img = testImage();
    img.at(0, 0, 0) = std::numeric_limits<float>::quiet_NaN();
    img.at(1, 1, 1) = std::numeric_limits<float>::infinity();
    std::string err;
    ASSERT_TRUE(writeImage(path("a.exr"), img, {}, &err)) << err;
    Image back;
    ASSERT_TRUE(readImage(path("a.exr"), &back, &err)) << err;
    EXPECT_EQ(back.at(0, 0, 0), 0.f);
    EXPECT_EQ(back.at(1, 1, 1), 0.f);
    EXPECT_EQ(back.at(2, 1, 1), img.at(2, 1, 1));
}
#endif

TEST_F(ImageIoTest, ReadsGreyAndDropsAlphaWithoutPremultiplying) {
    writeRaw8(path("grey.png"), 2, 1, 1, {77, 255});
    writeRaw8(path("rgba.png"), 1, 1, 4, {200, 100, 50, 128});
    writeRaw8(path("ga.png"), 1, 1, 2, {60, 0});
    Image img;
    ImageFileInfo info;
    std::string err;
    ASSERT_TRUE(readImage(path("grey.png"), &img, &err, &info)) << err;
    EXPECT_EQ(info.fileChannels, 1);
    EXPECT_TRUE(info.eightBit);
    ASSERT_EQ(img.channels, 3);
    for (int c = 0; c < 3; ++c) {
        EXPECT_FLOAT_EQ(img.at(0, 0, c), 77.f / 255);
        EXPECT_FLOAT_EQ(img.at(1, 0, c), 1.f);
    }
    ASSERT_TRUE(readImage(path("rgba.png"), &img, &err, &info)) << err;
    EXPECT_EQ(info.fileChannels, 4);
    EXPECT_FLOAT_EQ(img.at(0, 0, 0), 200.f / 255);
    EXPECT_FLOAT_EQ(img.at(0, 0, 1), 100.f / 255);
    EXPECT_FLOAT_EQ(img.at(0, 0, 2), 50.f / 255);
    ASSERT_TRUE(readImage(path("ga.png"), &img, &err, &info)) << err;
    EXPECT_FLOAT_EQ(img.at(0, 0, 2), 60.f / 255);  // alpha 0 does not zero the colour
}

TEST_F(ImageIoTest, SixteenBitPngIsNotEightBit) {
    auto out = OIIO::ImageOutput::create(path("a16.png"));
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(1, 1, 3, OIIO::TypeDesc::UINT16);
    ASSERT_TRUE(out->open(path("a16.png"), spec));
    const uint16_t px[3] = {65535, 32768, 1};
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT16, px));
    ASSERT_TRUE(out->close());
    Image img;
    ImageFileInfo info;
    std::string err;
    ASSERT_TRUE(readImage(path("a16.png"), &img, &err, &info)) << err;
    EXPECT_FALSE(info.eightBit);
    EXPECT_FLOAT_EQ(img.at(0, 0, 1), 32768.f / 65535);
}

TEST_F(ImageIoTest, MissingFileIsAnError) {
    Image img;
    std::string err;
    EXPECT_FALSE(readImage(path("nope.exr"), &img, &err));
    EXPECT_NE(err.find("nope.exr"), std::string::npos) << err;
}

TEST(ImageIoScenes, ReadsSceneTextures) {
    RLPBRT_REQUIRE_SHARED();
    const std::string png = rlpbrt::test::sharedDir() + "/scenes/breakfast/textures/goldbuddha.png";
    Image img;
    ImageFileInfo info;
    std::string err;
    ASSERT_TRUE(readImage(png, &img, &err, &info)) << err;
    EXPECT_EQ(img.width, 340);
    EXPECT_EQ(img.height, 510);
    EXPECT_EQ(info.fileChannels, 4);
    EXPECT_TRUE(info.eightBit);
}

}  // namespace
}  // namespace rlpbrt
