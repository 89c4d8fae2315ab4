// The bad-input corpus: every scene file in tests/data/bad/ starts with a line
//   # expect: [file:]line:col: text      (or "# expect: ok" for a file that must parse)
// naming the location of the first error (file relative to the scene's directory, default
// the scene itself) and a substring of its message; an empty file must parse without error.
// Files directly in tests/data/bad/ hold syntax errors and are parsed in-process; files in
// tests/data/bad/semantic/ hold errors found by the scene builder and are run through the
// CLI (`rlpbrt --parse-only`); files in tests/data/bad/strict/ hold input that pbrt-v3
// tolerates with a substitute: an error with --strict, a warning at the same place without.
// Files under inc/ are helpers included by the cases.
#include "parser/parser.h"

#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "recording_sink.h"

namespace rlpbrt {
namespace {

namespace fs = std::filesystem;

std::string corpusDir() { return std::string(RLPBRT_SOURCE_DIR) + "/tests/data/bad"; }

struct Expectation {
    bool ok = false;   // the file must parse without error
    std::string file;  // absolute, canonical path of the file holding the first error
    int line = 0, col = 0;
    std::string text;  // substring of the first error's message
};

// Reads the "# expect:" line of a corpus file; false (with a gtest failure) if malformed.
bool readExpectation(const std::string& path, Expectation* e) {
    std::ifstream in(path, std::ios::binary);
    std::string first;
    if (!std::getline(in, first)) {
        e->ok = true;  // an empty file
        return true;
    }
    if (!first.empty() && first.back() == '\r') first.pop_back();
    const std::string tag = "# expect: ";
    if (first.compare(0, tag.size(), tag) != 0) {
        ADD_FAILURE() << path << ": first line is not \"# expect: ...\"";
        return false;
    }
    std::string spec = first.substr(tag.size());
    if (spec == "ok") {
        e->ok = true;
        return true;
    }
    static const std::regex re(R"(^(?:([^:]+):)?(\d+):(\d+): (.+)$)");
    std::smatch m;
    if (!std::regex_match(spec, m, re)) {
        ADD_FAILURE() << path << ": cannot read expectation \"" << spec << "\"";
        return false;
    }
    fs::path dir = fs::path(path).parent_path();
    e->file = fs::weakly_canonical(m[1].matched ? dir / m[1].str() : fs::path(path)).string();
    e->line = std::stoi(m[2]);
    e->col = std::stoi(m[3]);
    e->text = m[4];
    return true;
}

// Corpus files (sorted) directly in `dir`.
std::vector<std::string> corpusFiles(const std::string& dir) {
    std::vector<std::string> out;
    std::error_code ec;
    for (const auto& f : fs::directory_iterator(dir, ec))
        if (f.is_regular_file() && f.path().extension() == ".pbrt") out.push_back(f.path());
    std::sort(out.begin(), out.end());
    return out;
}

std::string testName(const ::testing::TestParamInfo<std::string>& info) {
    std::string n = fs::path(info.param).stem().string();
    for (char& c : n)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return n;
}

// ---------------------------------------------------------------- parser corpus

class BadSyntax : public ::testing::TestWithParam<std::string> {};

TEST_P(BadSyntax, FirstErrorMatches) {
    const std::string& path = GetParam();
    Expectation e;
    ASSERT_TRUE(readExpectation(path, &e));
    Diagnostics diag;
    diag.setStream(nullptr);
    test::RecordingSink sink;
    sink.maxValues = 16;
    bool ok = parseFile(path, sink, diag);
    // The parse always ends with the end-of-input call unless a fatal error stopped it.
    ASSERT_FALSE(sink.lines.empty() && diag.errorCount() == 0);
    if (e.ok) {
        EXPECT_TRUE(ok);
        EXPECT_EQ(diag.errorCount(), 0);
        for (const auto& d : diag.all()) ADD_FAILURE() << d.str();
        return;
    }
    EXPECT_FALSE(ok);
    const Diagnostic* first = nullptr;
    for (const auto& d : diag.all())
        if (d.severity == Severity::Error) {
            first = &d;
            break;
        }
    ASSERT_NE(first, nullptr) << path << ": no error reported";
    ASSERT_NE(first->loc.file, nullptr);
    EXPECT_EQ(fs::weakly_canonical(*first->loc.file).string() + ":" +
                  std::to_string(first->loc.line) + ":" + std::to_string(first->loc.col),
              e.file + ":" + std::to_string(e.line) + ":" + std::to_string(e.col))
        << first->str();
    EXPECT_NE(first->message.find(e.text), std::string::npos)
        << "message: " << first->message << "\nexpected to contain: " << e.text;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadSyntax, ::testing::ValuesIn(corpusFiles(corpusDir())),
                         testName);

TEST(BadInputCorpus, HasEnoughCases) {
    auto syntax = corpusFiles(corpusDir());
    auto semantic = corpusFiles(corpusDir() + "/semantic");
    auto strict = corpusFiles(corpusDir() + "/strict");
    EXPECT_GE(syntax.size(), 30u);
    EXPECT_GE(semantic.size(), 20u);
    EXPECT_GE(strict.size(), 3u);
    // Every case names a distinct expectation (no accidental duplicates).
    std::vector<std::string> specs;
    for (const auto& list : {syntax, semantic, strict})
        for (const auto& f : list) {
            Expectation e;
            ASSERT_TRUE(readExpectation(f, &e));
            if (!e.ok) specs.push_back(e.file + ":" + std::to_string(e.line) + e.text);
        }
    std::sort(specs.begin(), specs.end());
    EXPECT_EQ(std::adjacent_find(specs.begin(), specs.end()), specs.end());
}

// ---------------------------------------------------------------- generated huge input

struct Result {
    bool ok = false;
    Diagnostics diag;
    test::RecordingSink sink;
    std::string firstError() const {
        for (const auto& d : diag.all())
            if (d.severity == Severity::Error)
                return std::to_string(d.loc.line) + ":" + std::to_string(d.loc.col) + ": " +
                       d.message;
        return "(no error)";
    }
};

std::unique_ptr<Result> parseText(const std::string& text) {
    auto r = std::make_unique<Result>();
    r->diag.setStream(nullptr);
    r->sink.showLocations = false;
    r->sink.maxValues = 16;
    r->ok = parseString(text, "huge.pbrt", r->sink, r->diag);
    return r;
}

TEST(HugeInput, OneMegabyteTokens) {
    const std::string big(1 << 20, 'a');
    const std::string shown = std::string(37, 'a') + "...";

    auto unterminated = parseText("Shape \"" + big);
    EXPECT_EQ(unterminated->firstError(), "1:7: unterminated string");

    auto name = parseText("Shape \"" + big + "\" \"float radius\" 1");
    EXPECT_TRUE(name->ok);
    ASSERT_EQ(name->sink.lines.size(), 2u);
    EXPECT_EQ(name->sink.lines[0].size(), big.size() + 25);  // Shape "..." float radius=[1]

    auto word = parseText("WorldBegin " + big);
    EXPECT_EQ(word->firstError(), "1:12: unknown directive \"" + shown + "\"");

    auto number = parseText("Shape \"s\" \"float r\" " + std::string(1 << 20, '7'));
    EXPECT_EQ(number->firstError(), "1:21: number " + std::string(37, '7') + "... is out of range");

    auto decl = parseText("Shape \"s\" \"float " + big + "\" 1");
    EXPECT_TRUE(decl->ok);

    auto badType = parseText("Shape \"s\" \"" + big + " x\" 1");
    EXPECT_EQ(badType->firstError(),
              "1:11: unknown parameter type \"" + shown + "\" in \"" + shown + "\"");
}

TEST(HugeInput, ManyBracketsAndErrors) {
    // 200k nested '[': one error each, no recursion, parsing goes on afterwards.
    auto r = parseText("Shape \"s\" \"float r\" [" + std::string(200000, '[') + "\nWorldBegin");
    EXPECT_EQ(r->firstError(), "1:22: nested '[' in a parameter value");
    EXPECT_EQ(r->diag.errorCount(), 200001);  // and the unclosed bracket at WorldBegin
    EXPECT_EQ(r->sink.lines.back(), "EndOfFiles");
    EXPECT_EQ(r->sink.lines[r->sink.lines.size() - 2], "WorldBegin");

    // A megabyte of control characters and of stray ']'.
    auto c = parseText(std::string(1 << 20, '\x01') + "WorldBegin");
    EXPECT_EQ(c->diag.errorCount(), 1 << 20);
    EXPECT_EQ(c->sink.lines.front(), "WorldBegin");
    auto b = parseText(std::string(1 << 20, ']'));
    EXPECT_EQ(b->firstError(), "1:1: unexpected ']'; expected a directive");
}

TEST(HugeInput, ManyDistinctParametersAreNotQuadratic) {
    // 200k parameters in one directive (4 MB): once quadratic (minutes), now linear.
    std::string text = "Shape \"sphere\"";
    for (int i = 0; i < 200000; ++i) text += " \"float a" + std::to_string(i) + "\" 1";
    text += " \"float a7\" 2";  // a repeated name replaces the earlier value
    auto t0 = std::chrono::steady_clock::now();
    auto r = parseText(text);
    double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_TRUE(r->ok);
    ASSERT_EQ(r->sink.paramLists.size(), 1u);
    const ParamList& list = r->sink.paramLists[0];
    EXPECT_EQ(list.params().size(), 200000u);
    EXPECT_EQ(list.getFloat("a7", 0.f), 2.f);
    EXPECT_EQ(list.getFloat("a199999", 0.f), 1.f);
    EXPECT_LT(sec, 10.0);
}

// ---------------------------------------------------------------- through the CLI

struct RunResult {
    int exitCode = -1;  // -1 when killed by a signal
    std::string output;  // stderr
};

// Runs `rlpbrt --parse-only <scene>` with a time limit; stdout is discarded.
RunResult runCli(const std::string& scene, const std::string& flags = "") {
    RunResult r;
    std::string cmd = "timeout -k 5 120 '" + std::string(RLPBRT_BINARY) + "' --parse-only " +
                      flags + " '" + scene + "' 2>&1 >/dev/null";
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return r;
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
    int status = pclose(p);
    if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
    return r;
}

// Every "file:line:col: error: message" line of CLI output as (canonical location, message).
std::vector<std::pair<std::string, std::string>> cliErrors(const std::string& output,
                                                           const std::string& kind = "error") {
    const std::regex re("^(.+):(\\d+):(\\d+): " + kind + ": (.*)$");
    std::vector<std::pair<std::string, std::string>> out;
    std::size_t start = 0;
    while (start < output.size()) {
        std::size_t end = output.find('\n', start);
        if (end == std::string::npos) end = output.size();
        std::string line = output.substr(start, end - start);
        std::smatch m;
        if (std::regex_match(line, m, re))
            out.emplace_back(fs::weakly_canonical(m[1].str()).string() + ":" + m[2].str() + ":" +
                                 m[3].str(),
                             m[4]);
        start = end + 1;
    }
    return out;
}

bool haveCli() {
    std::error_code ec;
    return fs::is_regular_file(RLPBRT_BINARY, ec);
}

class BadSemantics : public ::testing::TestWithParam<std::string> {};

TEST_P(BadSemantics, CliReportsTheFirstErrorAndFails) {
    if (!haveCli()) GTEST_SKIP() << RLPBRT_BINARY << " not built";
    const std::string& path = GetParam();
    Expectation e;
    ASSERT_TRUE(readExpectation(path, &e));
    ASSERT_FALSE(e.ok) << "semantic cases must expect an error";
    RunResult r = runCli(path);
    ASSERT_NE(r.exitCode, -1) << "crashed:\n" << r.output;
    ASSERT_NE(r.exitCode, 124) << "timed out";
    ASSERT_LT(r.exitCode, 124) << r.output;  // 125+ = timeout(1) failure or a signal
    EXPECT_NE(r.exitCode, 0) << r.output;
    auto errors = cliErrors(r.output);
    ASSERT_FALSE(errors.empty()) << "no error line in:\n" << r.output;
    EXPECT_EQ(errors[0].first, e.file + ":" + std::to_string(e.line) + ":" + std::to_string(e.col))
        << r.output;
    EXPECT_NE(errors[0].second.find(e.text), std::string::npos)
        << "message: " << errors[0].second << "\nexpected to contain: " << e.text;
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadSemantics,
                         ::testing::ValuesIn(corpusFiles(corpusDir() + "/semantic")), testName);

class StrictSubstitutes : public ::testing::TestWithParam<std::string> {};

// pbrt-v3's tolerance: a located warning and a scene that builds; with --strict the same
// place is the first error and the exit status is non-zero.
TEST_P(StrictSubstitutes, WarningWithoutStrictErrorWithStrict) {
    if (!haveCli()) GTEST_SKIP() << RLPBRT_BINARY << " not built";
    const std::string& path = GetParam();
    Expectation e;
    ASSERT_TRUE(readExpectation(path, &e));
    ASSERT_FALSE(e.ok) << "strict cases must expect an error";
    const std::string loc = e.file + ":" + std::to_string(e.line) + ":" + std::to_string(e.col);
    for (bool strict : {false, true}) {
        SCOPED_TRACE(strict ? "--strict" : "tolerant");
        RunResult r = runCli(path, strict ? "--strict" : "");
        ASSERT_NE(r.exitCode, -1) << "crashed:\n" << r.output;
        ASSERT_LT(r.exitCode, 124) << r.output;
        EXPECT_EQ(r.exitCode, strict ? 1 : 0) << r.output;
        auto found = cliErrors(r.output, strict ? "error" : "warning");
        ASSERT_FALSE(found.empty()) << r.output;
        EXPECT_EQ(found[0].first, loc) << r.output;
        EXPECT_NE(found[0].second.find(e.text), std::string::npos)
            << "message: " << found[0].second << "\nexpected to contain: " << e.text;
        if (!strict) {
            EXPECT_TRUE(cliErrors(r.output).empty()) << r.output;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Corpus, StrictSubstitutes,
                         ::testing::ValuesIn(corpusFiles(corpusDir() + "/strict")), testName);

TEST(BadSyntaxCli, ParserErrorsReachTheCli) {
    if (!haveCli()) GTEST_SKIP() << RLPBRT_BINARY << " not built";
    // A sample of the parser cases (each run costs a process start): includes, .spd files,
    // lexical errors, values, directive arguments.
    const char* sample[] = {"cyclic_include",     "include_depth_bomb",  "include_fanout_bomb",
                            "missing_include",    "include_directory",   "missing_spd_file",
                            "control_character",  "unterminated_string", "crlf_line_ends",
                            "rgb_4_values",       "lookat_8_numbers",    "error_in_included_file"};
    for (const char* name : sample) {
        const std::string path = corpusDir() + "/" + name + ".pbrt";
        Expectation e;
        ASSERT_TRUE(readExpectation(path, &e));
        if (e.ok) continue;  // valid syntax; the CLI rejects it for having no world block
        RunResult r = runCli(path);
        ASSERT_NE(r.exitCode, -1) << path << " crashed:\n" << r.output;
        EXPECT_GT(r.exitCode, 0) << path;
        EXPECT_LT(r.exitCode, 124) << path;
        // The scene builder may report errors of its own (these scenes are not meant to be
        // complete), so the parser's error only has to be among those printed.
        const std::string want = e.file + ":" + std::to_string(e.line) + ":" +
                                 std::to_string(e.col);
        bool found = false;
        for (const auto& [loc, message] : cliErrors(r.output))
            found = found || (loc == want && message.find(e.text) != std::string::npos);
        EXPECT_TRUE(found) << path << ": no error \"" << want << ": ..." << e.text
                           << "\" in:\n" << r.output;
    }
}

}  // namespace
}  // namespace rlpbrt
