// Bad input through the whole program (`rlpbrt scene -o out.exr`), with bounded memory
// (`ulimit -v`) and time (`timeout`):
//  - every error case of tests/data/bad/ (parser cases and semantic/, which includes the
//    malformed PLY files of bad/ply/) exits 1 with its error at the expected
//    `file:line:col: error:`, and leaves no output file (nor temporary file) behind;
//  - unreadable images (truncated, empty, not an image, absurd dimensions, missing) give a
//    located warning for imagemap textures and infinite light maps, and the render goes on
//    with pbrt-v3's constant substitute (an error with --strict: tests/data/bad/strict/);
//  - generated absurd input (huge tokens, a missing scene, unwritable outputs) fails fast;
//  - non-finite radiance (an environment map with NaN and Inf texels) never reaches the
//    image: it is counted in --stats "nonfinite_samples" and reported by a warning.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "render/image_io.h"

namespace {

namespace fs = std::filesystem;

const std::string kBad = std::string(RLPBRT_SOURCE_DIR) + "/tests/data/bad";
// Address-space limit for every run: an absurd allocation fails instead of swapping.
constexpr long kMemoryLimitKb = 4L << 20;  // 4 GiB of virtual memory
constexpr int kTimeLimitSec = 60;

struct CliRun {
    int exitCode = -1;  // -1: killed by a signal
    std::string err;    // stderr
    double seconds = 0;
};

// A fresh temporary directory, removed (with a check that it is empty) by done().
struct TempDir {
    std::string path;
    TempDir() {
        char tmpl[] = "/tmp/rlpbrt-badcli-XXXXXX";
        const char* d = mkdtemp(tmpl);
        path = d ? d : "/tmp";
    }
    std::vector<std::string> entries() const {
        std::vector<std::string> out;
        std::error_code ec;
        for (const auto& e : fs::directory_iterator(path, ec)) out.push_back(e.path().filename());
        std::sort(out.begin(), out.end());
        return out;
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

std::string quote(const std::string& s) { return "'" + s + "'"; }

// Runs rlpbrt with `args` (already quoted) under the memory and time limits.
CliRun runRlpbrt(const std::string& args, const std::string& dir) {
    CliRun r;
    std::string errFile = dir + "/../" + fs::path(dir).filename().string() + ".stderr";
#if defined(__SANITIZE_ADDRESS__)
    // AddressSanitizer reserves terabytes of address space for its shadow memory, so a
    // virtual-memory limit cannot apply; its own resident-memory limit bounds the run instead.
    // Full malloc stacks so that tests/lsan.supp can name OpenImageIO's leaks on the error
    // paths these bad images take.
    const std::string memLimit = "export ASAN_OPTIONS=\"${ASAN_OPTIONS:-}:hard_rss_limit_mb=" +
                                 std::to_string(kMemoryLimitKb / 1024) +
                                 ":fast_unwind_on_malloc=0\" LSAN_OPTIONS=\"suppressions=" +
                                 std::string(RLPBRT_SOURCE_DIR) + "/tests/lsan.supp\"";
#else
    const std::string memLimit = "ulimit -v " + std::to_string(kMemoryLimitKb);
#endif
    std::string cmd = "cd " + quote(dir) + " && " + memLimit +
                      " && timeout -k 5 " + std::to_string(kTimeLimitSec) + " " +
                      quote(RLPBRT_BINARY) + " " + args + " >/dev/null 2>" + quote(errFile);
    auto t0 = std::chrono::steady_clock::now();
    int status = std::system(cmd.c_str());
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
    std::ifstream in(errFile);
    std::stringstream ss;
    ss << in.rdbuf();
    r.err = ss.str();
    std::remove(errFile.c_str());
    return r;
}

void expectNoCrash(const CliRun& r) {
    ASSERT_NE(r.exitCode, -1) << "killed by a signal:\n" << r.err;
    ASSERT_NE(r.exitCode, 124) << "timed out after " << kTimeLimitSec << " s";
    ASSERT_LT(r.exitCode, 124) << "timeout(1) failure or signal:\n" << r.err;
}

// Expectation line of a corpus file (see bad_input_test.cpp): "# expect: [file:]l:c: text".
struct Expectation {
    bool ok = false;
    std::string loc;  // canonical file:line:col
    std::string text;
};

Expectation readExpectation(const std::string& path) {
    Expectation e;
    std::ifstream in(path, std::ios::binary);
    std::string first;
    if (!std::getline(in, first)) {
        e.ok = true;
        return e;
    }
    if (!first.empty() && first.back() == '\r') first.pop_back();
    static const std::regex re(R"(^# expect: (?:([^:]+):)?(\d+):(\d+): (.+)$)");
    std::smatch m;
    if (!std::regex_match(first, m, re)) {
        e.ok = true;  // "# expect: ok"
        return e;
    }
    fs::path dir = fs::path(path).parent_path();
    e.loc = fs::weakly_canonical(m[1].matched ? dir / m[1].str() : fs::path(path)).string() +
            ":" + m[2].str() + ":" + m[3].str();
    e.text = m[4];
    return e;
}

// Every located diagnostic of `kind` ("error" or "warning") as (canonical loc, message).
std::vector<std::pair<std::string, std::string>> located(const std::string& out,
                                                         const std::string& kind) {
    const std::regex re("^(.+):(\\d+):(\\d+): " + kind + ": (.*)$");
    std::vector<std::pair<std::string, std::string>> v;
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line)) {
        std::smatch m;
        if (std::regex_match(line, m, re))
            v.emplace_back(fs::weakly_canonical(m[1].str()).string() + ":" + m[2].str() + ":" +
                               m[3].str(),
                           m[4]);
    }
    return v;
}

std::vector<std::string> corpus(const std::string& dir) {
    std::vector<std::string> out;
    std::error_code ec;
    for (const auto& f : fs::directory_iterator(dir, ec))
        if (f.is_regular_file() && f.path().extension() == ".pbrt" &&
            !readExpectation(f.path()).ok)
            out.push_back(f.path());
    std::sort(out.begin(), out.end());
    return out;
}

std::string testName(const ::testing::TestParamInfo<std::string>& info) {
    std::string n = fs::path(info.param).parent_path().filename().string() + "_" +
                    fs::path(info.param).stem().string();
    for (char& c : n)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return n;
}

// ---------------------------------------------------------------- the error corpus

class BadInputCli : public ::testing::TestWithParam<std::string> {};

TEST_P(BadInputCli, LocatedErrorNonZeroExitNoOutput) {
    const std::string& scene = GetParam();
    Expectation e = readExpectation(scene);
    TempDir tmp;
    CliRun r = runRlpbrt(quote(scene) + " -o out.exr --quiet", tmp.path);
    expectNoCrash(r);
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_LT(r.seconds, 20.0);
    auto errors = located(r.err, "error");
    ASSERT_FALSE(errors.empty()) << "no located error in:\n" << r.err;
    // Parser cases may be followed (or, for incomplete scenes, preceded by nothing else
    // but) further errors of the scene builder: the expected one must be among them.
    bool found = false;
    for (const auto& [loc, msg] : errors)
        found = found || (loc == e.loc && msg.find(e.text) != std::string::npos);
    EXPECT_TRUE(found) << "expected " << e.loc << ": error: ..." << e.text << "\nin:\n" << r.err;
    // No follow-up error without a location.
    EXPECT_EQ(r.err.find("<unknown>: error:"), std::string::npos) << r.err;
    EXPECT_TRUE(tmp.entries().empty()) << "left behind: " << tmp.entries().front();
}

INSTANTIATE_TEST_SUITE_P(Syntax, BadInputCli, ::testing::ValuesIn(corpus(kBad)), testName);
INSTANTIATE_TEST_SUITE_P(Semantic, BadInputCli, ::testing::ValuesIn(corpus(kBad + "/semantic")),
                         testName);

TEST(BadInputCliCorpus, HasTheNewCases) {
    // Issue 8: at least 50 cases beyond the 58 parser and 36 semantic cases it started with.
    // Issue 35 moved pbrt-v3's tolerated cases to strict/ (errors only with --strict).
    EXPECT_GE(corpus(kBad).size() + corpus(kBad + "/semantic").size() +
                  corpus(kBad + "/strict").size(),
              56u + 36u + 50u);
    std::error_code ec;
    int plys = 0;
    for (const auto& f : fs::directory_iterator(kBad + "/ply", ec)) plys += f.path().extension() == ".ply";
    EXPECT_GE(plys, 20);
}

// ---------------------------------------------------------------- unreadable images

// A small scene whose imagemap texture or infinite light reads `image`.
std::string imageScene(const std::string& image, bool envmap) {
    std::string s =
        "LookAt 0 0 5  0 0 0  0 1 0\n"
        "Camera \"perspective\" \"float fov\" 30\n"
        "Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 16\n"
        "Sampler \"random\" \"integer pixelsamples\" 2\n"
        "WorldBegin\n";
    if (envmap) {
        s += "LightSource \"infinite\" \"string mapname\" \"" + image + "\"\n";  // line 6
        s += "Material \"matte\"\n";
    } else {
        s += "LightSource \"point\" \"point from\" [0 0 5] \"rgb I\" [20 20 20]\n";
        s += "Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"" + image + "\"\n";
        s += "Material \"matte\" \"texture Kd\" \"t\"\n";  // line 8
    }
    s += "Shape \"sphere\"\nWorldEnd\n";
    return s;
}

struct ImageCase {
    const char* file;  // in tests/data/bad/images/ (missing_*: no such file)
    bool envmap;       // infinite light "mapname" (else imagemap "filename")
};

void PrintTo(const ImageCase& c, std::ostream* os) {
    *os << (c.envmap ? "envmap " : "imagemap ") << c.file;
}

class UnreadableImage : public ::testing::TestWithParam<ImageCase> {};

// Imagemap textures: a located warning at the "filename" parameter; infinite light maps: a
// located warning at the LightSource; both take a constant and the render goes on.
TEST_P(UnreadableImage, LocatedDiagnostic) {
    const ImageCase& c = GetParam();
    TempDir tmp;
    const std::string image = kBad + "/images/" + c.file;
    const std::string scene = tmp.path + "/scene.pbrt";
    {
        std::ofstream f(scene);
        f << imageScene(image, c.envmap);
    }
    CliRun r = runRlpbrt(quote(scene) + " -o out.exr --quiet", tmp.path);
    expectNoCrash(r);
    const std::string want = fs::weakly_canonical(scene).string() + (c.envmap ? ":6:1" : ":7:35");
    bool found = false;
    for (const auto& [loc, msg] : located(r.err, "warning"))
        found = found || (loc == want && msg.find(c.file) != std::string::npos);
    EXPECT_TRUE(found) << "no warning at " << want << " naming " << c.file << " in:\n" << r.err;
    std::remove(scene.c_str());
    EXPECT_EQ(r.exitCode, 0) << r.err;
    rlpbrt::Image img;
    std::string err;
    ASSERT_TRUE(rlpbrt::readImage(tmp.path + "/out.exr", &img, &err)) << err;
    EXPECT_EQ(img.width, 16);
    for (float v : img.pixels) ASSERT_TRUE(std::isfinite(v));
    std::remove((tmp.path + "/out.exr").c_str());
    EXPECT_TRUE(tmp.entries().empty());
}

const ImageCase kImageCases[] = {
    {"truncated.png", false},      {"truncated.exr", false},     {"zero_size.png", false},
    {"zero_size.exr", false},      {"not_an_image.png", false},  {"not_an_image.exr", false},
    {"huge_dimensions.png", false}, {"missing_texture.png", false},
    {"truncated.exr", true},       {"zero_size.exr", true},      {"not_an_image.exr", true},
    {"not_an_image.png", true},    {"huge_dimensions.png", true}, {"missing_envmap.exr", true},
};

std::string imageCaseName(const ::testing::TestParamInfo<ImageCase>& info) {
    std::string n = std::string(info.param.envmap ? "envmap_" : "imagemap_") + info.param.file;
    for (char& ch : n)
        if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
    return n;
}

INSTANTIATE_TEST_SUITE_P(Images, UnreadableImage, ::testing::ValuesIn(kImageCases),
                         imageCaseName);

// ---------------------------------------------------------------- generated input

TEST(BadInputCliGenerated, HugeTokensFailFastWithALocatedError) {
    TempDir tmp;
    {
        // 32 MB: a string, a bare word and a number, each far beyond any sane token.
        std::ofstream f(tmp.path + "/huge.pbrt");
        f << "WorldBegin\nShape \"sphere\" \"float radius\" [" << std::string(8 << 20, '9')
          << "]\nShape \"" << std::string(8 << 20, 's') << "\"\n"
          << std::string(8 << 20, 'W') << "\nMaterial \"" << std::string(8 << 20, 'x');
    }
    CliRun r = runRlpbrt(quote(tmp.path + "/huge.pbrt") + " -o out.exr --quiet", tmp.path);
    expectNoCrash(r);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_LT(r.seconds, 20.0);
    auto errors = located(r.err, "error");
    ASSERT_GE(errors.size(), 3u) << r.err.substr(0, 2000);
    const std::string f = fs::weakly_canonical(tmp.path + "/huge.pbrt").string();
    EXPECT_EQ(errors[0].first, f + ":2:32");
    EXPECT_NE(errors[0].second.find("out of range"), std::string::npos) << errors[0].second;
    // Messages quote at most a short prefix of a huge token.
    EXPECT_LT(r.err.size(), 4000u);
    std::remove((tmp.path + "/huge.pbrt").c_str());
    EXPECT_TRUE(tmp.entries().empty());
}

TEST(BadInputCliGenerated, DeepIncludeNestingIsBounded) {
    TempDir tmp;
    // 500 files each including the next: the parser stops at its depth limit.
    for (int i = 0; i < 500; ++i) {
        std::ofstream f(tmp.path + "/d" + std::to_string(i) + ".pbrt");
        f << "Include \"d" << i + 1 << ".pbrt\"\n";
    }
    CliRun r = runRlpbrt(quote(tmp.path + "/d0.pbrt") + " -o out.exr --quiet", tmp.path);
    expectNoCrash(r);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find(": error: Include nested more than"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(tmp.path + "/out.exr"));
}

TEST(BadInputCliGenerated, MissingSceneFile) {
    TempDir tmp;
    CliRun r = runRlpbrt("no_such_scene.pbrt -o out.exr --quiet", tmp.path);
    expectNoCrash(r);
    EXPECT_EQ(r.exitCode, 1);
    EXPECT_NE(r.err.find("no_such_scene.pbrt: error: cannot open file"), std::string::npos)
        << r.err;
    EXPECT_TRUE(tmp.entries().empty());
}

// An output that cannot be written is reported before the render, not after it.
TEST(BadInputCliGenerated, UnwritableOutputFailsBeforeRendering) {
    TempDir tmp;
    const std::string scene = std::string(RLPBRT_SOURCE_DIR) + "/scenes/demo/demo.pbrt";
    for (const std::string out : {"no_such_dir/out.exr", "out.jpeg2", "."}) {
        CliRun r = runRlpbrt(quote(scene) + " --spp 100000 -o " + quote(out) + " --quiet", tmp.path);
        expectNoCrash(r);
        EXPECT_EQ(r.exitCode, 1) << out;
        EXPECT_LT(r.seconds, 20.0) << out;
        EXPECT_NE(r.err.find(": error: cannot write"), std::string::npos) << r.err;
        EXPECT_TRUE(tmp.entries().empty()) << out;
    }
}

// ---------------------------------------------------------------- no NaN in the image

TEST(NonFinite, NanAndInfRadianceAreCountedAndDropped) {
    TempDir tmp;
    {
        std::ofstream f(tmp.path + "/scene.pbrt");
        f << imageScene(kBad + "/images/nan_inf.pfm", true);
    }
    CliRun r = runRlpbrt(quote(tmp.path + "/scene.pbrt") + " -o out.exr --stats stats.json", tmp.path);
    expectNoCrash(r);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.err.find("warning: "), std::string::npos);
    EXPECT_NE(r.err.find("non-finite samples were dropped"), std::string::npos) << r.err;
    std::ifstream s(tmp.path + "/stats.json");
    std::stringstream ss;
    ss << s.rdbuf();
    std::smatch m;
    std::string json = ss.str();
    ASSERT_TRUE(std::regex_search(json, m, std::regex("\"nonfinite_samples\": (\\d+)"))) << json;
    EXPECT_GT(std::stoll(m[1]), 0) << json;
    rlpbrt::Image img;
    std::string err;
    ASSERT_TRUE(rlpbrt::readImage(tmp.path + "/out.exr", &img, &err)) << err;
    for (float v : img.pixels) ASSERT_TRUE(std::isfinite(v));
}

}  // namespace
