// pbrt-v3's tolerance (issue 35): the scenes of ../shared/scenes/pbrt-features/tolerance/ (an
// undefined named material, an unknown material type, an unreadable image texture) render with
// a located warning and pbrt-v3's substitute, and the image equals the same scene with the
// substitute written out; with strict mode (--strict) each is a located error and nothing is
// rendered.
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "parser/diagnostics.h"
#include "render/image_io.h"
#include "render/render.h"
#include "render/scene.h"
#include "render/scene_builder.h"
#include "shared_data.h"

namespace rlpbrt {
namespace {

namespace fs = std::filesystem;

struct ToleranceCase {
    const char* file;         // in pbrt-features/tolerance/
    int line, col;            // where the warning points
    const char* message;      // part of the warning
    const char* original;     // the line to replace ...
    const char* substitute;   // ... by pbrt-v3's substitute, written out
};

const ToleranceCase kCases[] = {
    {"named.pbrt", 8, 1, "undefined named material \"undefinedname\"",
     "NamedMaterial \"undefinedname\"", ""},  // the current (default) material stays
    {"mat.pbrt", 8, 1, "unknown material type \"BUSH1\"", "Material \"BUSH1\"",
     "Material \"matte\""},
    {"tex.pbrt", 8, 35, "nonexistent.png", "\"imagemap\" \"string filename\" \"nonexistent.png\"",
     "\"constant\" \"rgb value\" [1 1 1]"},  // pbrt-v3: the "scale" (1) everywhere
};

void PrintTo(const ToleranceCase& c, std::ostream* os) { *os << c.file; }

std::string slurp(const std::string& path) {
    std::ifstream f(path);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

struct Rendered {
    bool ok = false;
    Image image;
};

// Parses, builds and renders `path` at 16 spp on one thread.
Rendered renderScene(const std::string& path, Diagnostics& diag) {
    Rendered r;
    SceneDesc desc;
    if (!loadSceneDesc(path, diag, &desc)) return r;
    BuildOptions bo;
    bo.sppOverride = 16;
    bo.seed = 3;
    std::unique_ptr<Scene> scene = buildScene(desc, bo, diag);
    if (!scene || diag.errorCount() > 0) return r;
    RenderOptions ro;
    ro.nThreads = 1;
    r.image = render(*scene, ro).image;
    r.ok = true;
    return r;
}

double mean(const Image& img) {
    double s = 0;
    for (float v : img.pixels) s += v;
    return s / double(img.pixels.size());
}

// The diagnostic of `severity` at file:line:col whose message contains `text`, if any.
const Diagnostic* find(const Diagnostics& diag, Severity severity, const std::string& file,
                       int line, int col, const std::string& text) {
    for (const Diagnostic& d : diag.all())
        if (d.severity == severity && d.loc.file && fs::weakly_canonical(*d.loc.file) == file &&
            d.loc.line == line && d.loc.col == col && d.message.find(text) != std::string::npos)
            return &d;
    return nullptr;
}

std::string scenePath(const ToleranceCase& c) {
    return fs::weakly_canonical(test::sharedDir() + "/scenes/pbrt-features/tolerance/" + c.file);
}

class Tolerance : public ::testing::TestWithParam<ToleranceCase> {};

TEST_P(Tolerance, RendersWithALocatedWarningAndPbrtV3sSubstitute) {
    RLPBRT_REQUIRE_SHARED();
    const ToleranceCase& c = GetParam();
    const std::string path = scenePath(c);
    Diagnostics diag;
    diag.setStream(nullptr);
    Rendered tolerant = renderScene(path, diag);
    ASSERT_TRUE(tolerant.ok) << (diag.all().empty() ? "" : diag.all()[0].str());
    EXPECT_EQ(diag.errorCount(), 0);
    EXPECT_NE(find(diag, Severity::Warning, path, c.line, c.col, c.message), nullptr)
        << "no warning at " << c.line << ":" << c.col << " naming " << c.message;

    // The same scene with the substitute written out (next to the original, for its
    // relative paths: a temporary copy in the build directory).
    std::string text = slurp(path);
    auto at = text.find(c.original);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, std::string(c.original).size(), c.substitute);
    const std::string explicitPath = fs::temp_directory_path().string() + "/rlpbrt-tolerance-" +
                                     std::to_string(getpid()) + "-" + c.file;
    std::ofstream(explicitPath) << text;
    Diagnostics diag2;
    diag2.setStream(nullptr);
    Rendered written = renderScene(explicitPath, diag2);
    std::remove(explicitPath.c_str());
    ASSERT_TRUE(written.ok) << (diag2.all().empty() ? "" : diag2.all()[0].str());
    EXPECT_EQ(diag2.warningCount(), 0) << diag2.all()[0].str();
    // The same samples through the same material: the images agree to rounding.
    ASSERT_EQ(tolerant.image.pixels.size(), written.image.pixels.size());
    EXPECT_NEAR(mean(tolerant.image), mean(written.image), 1e-6 * mean(written.image));
    EXPECT_GT(mean(written.image), 0.05);  // the sphere is lit: not a black image
}

TEST_P(Tolerance, StrictModeMakesTheSubstituteALocatedError) {
    RLPBRT_REQUIRE_SHARED();
    const ToleranceCase& c = GetParam();
    const std::string path = scenePath(c);
    Diagnostics diag;
    diag.setStream(nullptr);
    diag.setStrict(true);
    EXPECT_FALSE(renderScene(path, diag).ok);
    EXPECT_NE(find(diag, Severity::Error, path, c.line, c.col, c.message), nullptr)
        << "no error at " << c.line << ":" << c.col << " naming " << c.message;
}

// Through the program: --strict exits 1 with the located error and writes no image.
TEST_P(Tolerance, StrictCliFailsWithoutOutput) {
    RLPBRT_REQUIRE_SHARED();
    const ToleranceCase& c = GetParam();
    const std::string path = scenePath(c);
    const std::string out = fs::temp_directory_path().string() + "/rlpbrt-strict-" +
                            std::to_string(getpid()) + ".exr";
    const std::string cmd = "timeout -k 5 60 '" + std::string(RLPBRT_BINARY) + "' --strict --quiet '" +
                            path + "' -o '" + out + "' 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string output;
    char buf[4096];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) output.append(buf, n);
    int status = pclose(p);
    ASSERT_TRUE(WIFEXITED(status)) << output;
    EXPECT_EQ(WEXITSTATUS(status), 1) << output;
    const std::string want = path + ":" + std::to_string(c.line) + ":" + std::to_string(c.col) +
                             ": error: ";
    auto at = output.find(want);
    ASSERT_NE(at, std::string::npos) << output;
    EXPECT_NE(output.find(c.message, at), std::string::npos) << output;
    EXPECT_FALSE(fs::exists(out));
}

std::string caseName(const ::testing::TestParamInfo<ToleranceCase>& info) {
    return fs::path(info.param.file).stem().string();
}

INSTANTIATE_TEST_SUITE_P(Scenes, Tolerance, ::testing::ValuesIn(kCases), caseName);

}  // namespace
}  // namespace rlpbrt
