// Inputs found by the libFuzzer targets of fuzz/ (each once crashed, hung or misbehaved) and
// the fuzzers' seed corpora, replayed in the ordinary build: no crash, and every failure
// comes with a message (parser: located at a file:line:col; PLY: naming the PLY line or
// byte offset). fuzz/regressions/<target>/ holds the inputs; see docs/RELIABILITY.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "parser/parser.h"
#include "parser/ply.h"
#include "recording_sink.h"

namespace rlpbrt {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> filesIn(const std::string& dir) {
    std::vector<std::string> out;
    std::error_code ec;
    for (const auto& f : fs::directory_iterator(std::string(RLPBRT_SOURCE_DIR) + "/" + dir, ec))
        if (f.is_regular_file() && f.path().extension() != ".md") out.push_back(f.path());
    std::sort(out.begin(), out.end());
    return out;
}

std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

TEST(FuzzRegressions, ParserInputs) {
    auto files = filesIn("fuzz/regressions/parser");
    auto seeds = filesIn("fuzz/corpus/parser");
    files.insert(files.end(), seeds.begin(), seeds.end());
    ASSERT_FALSE(seeds.empty());
    for (const auto& f : files) {
        SCOPED_TRACE(f);
        Diagnostics diag;
        diag.setStream(nullptr);
        test::RecordingSink sink;
        sink.maxValues = 16;
        // As the fuzzer does: a name in a directory that does not exist.
        bool ok = parseString(slurp(f), "/nonexistent-rlpbrt-fuzz/input.pbrt", sink, diag);
        EXPECT_EQ(ok, diag.errorCount() == 0);
        for (const auto& d : diag.all()) {
            ASSERT_NE(d.loc.file, nullptr) << d.message;
            EXPECT_GE(d.loc.line, 1) << d.str();
        }
    }
}

TEST(FuzzRegressions, PlyInputs) {
    auto regressions = filesIn("fuzz/regressions/ply");
    ASSERT_FALSE(regressions.empty());
    for (const auto& f : regressions) {
        SCOPED_TRACE(f);
        std::string data = slurp(f);
        PlyMesh mesh;
        std::string error;
        // Each regression is malformed: it must fail with a message naming where.
        EXPECT_FALSE(readPlyFromMemory(data.data(), data.size(), &mesh, &error));
        EXPECT_TRUE(error.find("(PLY line") != std::string::npos ||
                    error.find("(byte offset") != std::string::npos || error.find("PLY file") == 0)
            << error;
        EXPECT_EQ(mesh.vertexCount(), 0u);
    }
    for (const auto& f : filesIn("fuzz/corpus/ply")) {
        SCOPED_TRACE(f);
        std::string data = slurp(f);
        PlyMesh mesh;
        std::string error;
        EXPECT_TRUE(readPlyFromMemory(data.data(), data.size(), &mesh, &error)) << error;
        for (uint32_t i : mesh.indices) ASSERT_LT(i, mesh.vertexCount());
    }
}

}  // namespace
}  // namespace rlpbrt
