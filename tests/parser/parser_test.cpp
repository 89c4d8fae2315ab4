// Tests of the pbrt-v3 parser through a recording SceneSink: every directive and parameter
// type, value syntax, comments, escapes, Includes (nesting, relative paths, continuation of
// the last directive across the end of an included file), locations and error messages.
#include "parser/parser.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

#include "recording_sink.h"
#include "shared_data.h"

namespace rlpbrt {
namespace {

namespace fs = std::filesystem;
using Strings = std::vector<std::string>;

struct Parsed {
    bool ok = false;
    Diagnostics diag;
    test::RecordingSink sink;

    // Every error as "file:line:col: error: message".
    Strings errors() const {
        Strings out;
        for (const auto& d : diag.all())
            if (d.severity == Severity::Error) out.push_back(d.str());
        return out;
    }
    Strings warnings() const {
        Strings out;
        for (const auto& d : diag.all())
            if (d.severity == Severity::Warning) out.push_back(d.str());
        return out;
    }
    // The recorded lines without the final EndOfFiles line.
    Strings calls() const {
        Strings l = sink.lines;
        if (!l.empty() && l.back().rfind("EndOfFiles", 0) == 0) l.pop_back();
        return l;
    }
};

std::unique_ptr<Parsed> parse(const std::string& text, bool locations = true,
                              const std::string& name = "t.pbrt") {
    auto r = std::make_unique<Parsed>();
    r->diag.setStream(nullptr);
    r->sink.showLocations = locations;
    r->ok = parseString(text, name, r->sink, r->diag);
    return r;
}

// The calls of a scene that must parse without errors or warnings, without locations.
Strings calls(const std::string& text) {
    auto r = parse(text, false);
    EXPECT_TRUE(r->ok) << text;
    EXPECT_EQ(r->errors(), Strings{}) << text;
    EXPECT_EQ(r->warnings(), Strings{}) << text;
    return r->calls();
}

// The first error of a scene that must fail, as "line:col: message" (file name dropped).
std::string firstError(const std::string& text) {
    auto r = parse(text, false);
    EXPECT_FALSE(r->ok) << text;
    for (const auto& d : r->diag.all())
        if (d.severity == Severity::Error)
            return std::to_string(d.loc.line) + ":" + std::to_string(d.loc.col) + ": " +
                   d.message;
    return "(no error)";
}

// A temporary directory with helpers to write files into it; removed at destruction.
class ScratchDir {
public:
    ScratchDir() {
        static int counter = 0;
        root_ = fs::temp_directory_path() /
                ("rlpbrt_parser_test_" + std::to_string(getpid()) + "_" +
                 std::to_string(counter++));
        fs::remove_all(root_);
        fs::create_directories(root_);
    }
    ~ScratchDir() {
        std::error_code ec;
        fs::remove_all(root_, ec);
    }
    // Writes `text` to `rel` (creating directories); returns the full path.
    std::string write(const std::string& rel, const std::string& text) const {
        fs::path p = root_ / rel;
        fs::create_directories(p.parent_path());
        std::ofstream(p, std::ios::binary) << text;
        return p.string();
    }
    // Root directory with a trailing '/'.
    std::string prefix() const { return root_.string() + "/"; }
    std::string path(const std::string& rel) const { return (root_ / rel).string(); }

private:
    fs::path root_;
};

std::unique_ptr<Parsed> parseFileIn(const ScratchDir& dir, const std::string& rel) {
    auto r = std::make_unique<Parsed>();
    r->diag.setStream(nullptr);
    r->sink.stripPrefix = dir.prefix();
    r->ok = parseFile(dir.path(rel), r->sink, r->diag);
    return r;
}

// ---------------------------------------------------------------- directives

TEST(Parser, TransformDirectives) {
    EXPECT_EQ(calls("Identity\n"
                    "Translate 1 -2 3.5\n"
                    "Scale -1 1 1\n"
                    "Rotate 90 0 0 1\n"
                    "LookAt 0 0 5  0 0 0  0 1 0\n"
                    "ConcatTransform [1 0 0 0 0 1 0 0 0 0 1 0 1 2 3 1]\n"
                    "Transform [2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1]\n"
                    "Transform 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n"
                    "CoordinateSystem \"mycs\"\n"
                    "CoordSysTransform \"camera\"\n"
                    "ActiveTransform StartTime\n"
                    "ActiveTransform EndTime\n"
                    "ActiveTransform All\n"
                    "TransformTimes 0 0.5\n"
                    "ReverseOrientation\n"),
              (Strings{"Identity", "Translate 1 -2 3.5", "Scale -1 1 1", "Rotate 90 0 0 1",
                       "LookAt 0 0 5 0 0 0 0 1 0",
                       "ConcatTransform [1 0 0 0 0 1 0 0 0 0 1 0 1 2 3 1]",
                       "Transform [2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1]",
                       "Transform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1]",
                       "CoordinateSystem \"mycs\"", "CoordSysTransform \"camera\"",
                       "ActiveTransform StartTime", "ActiveTransform EndTime",
                       "ActiveTransform All", "TransformTimes 0 0.5", "ReverseOrientation"}));
}

TEST(Parser, OptionDirectives) {
    EXPECT_EQ(calls("Camera \"perspective\" \"float fov\" [45]\n"
                    "Sampler \"halton\" \"integer pixelsamples\" 16\n"
                    "Film \"image\" \"integer xresolution\" [640] \"integer yresolution\" [480]\n"
                    "  \"string filename\" \"out.exr\"\n"
                    "PixelFilter \"gaussian\"\n"
                    "Integrator \"path\" \"integer maxdepth\" [5]\n"
                    "Accelerator \"bvh\"\n"
                    "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n"
                    "MediumInterface \"fog\" \"\"\n"
                    "MediumInterface \"fog\"\n"),
              (Strings{"Camera \"perspective\" float fov=[45]",
                       "Sampler \"halton\" integer pixelsamples=[16]",
                       "Film \"image\" integer xresolution=[640] integer yresolution=[480] "
                       "string filename=[\"out.exr\"]",
                       "PixelFilter \"gaussian\"", "Integrator \"path\" integer maxdepth=[5]",
                       "Accelerator \"bvh\"",
                       "MakeNamedMedium \"fog\" string type=[\"homogeneous\"]",
                       "MediumInterface \"fog\" \"\"",
                       // One name: inside and outside are the same medium (pbrt-v3).
                       "MediumInterface \"fog\" \"fog\""}));
}

TEST(Parser, WorldDirectives) {
    EXPECT_EQ(calls("WorldBegin\n"
                    "AttributeBegin\n"
                    "TransformBegin\n"
                    "TransformEnd\n"
                    "Texture \"checks\" \"spectrum\" \"checkerboard\" \"float uscale\" [4]\n"
                    "Texture \"f\" \"float\" \"constant\"\n"
                    "Material \"matte\" \"texture Kd\" \"checks\"\n"
                    "MakeNamedMaterial \"red\" \"string type\" [\"matte\"]\n"
                    "NamedMaterial \"red\"\n"
                    "LightSource \"point\" \"rgb I\" [1 1 1]\n"
                    "AreaLightSource \"diffuse\" \"rgb L\" [4 4 4]\n"
                    "Shape \"sphere\" \"float radius\" 3\n"
                    "ObjectBegin \"thing\"\n"
                    "Shape \"sphere\"\n"
                    "ObjectEnd\n"
                    "ObjectInstance \"thing\"\n"
                    "AttributeEnd\n"
                    "WorldEnd\n"),
              (Strings{"WorldBegin", "AttributeBegin", "TransformBegin", "TransformEnd",
                       "Texture \"checks\" \"spectrum\" \"checkerboard\" float uscale=[4]",
                       "Texture \"f\" \"float\" \"constant\"",
                       "Material \"matte\" texture Kd=[\"checks\"]",
                       "MakeNamedMaterial \"red\" string type=[\"matte\"]",
                       "NamedMaterial \"red\"", "LightSource \"point\" rgb I=[1 1 1]",
                       "AreaLightSource \"diffuse\" rgb L=[4 4 4]",
                       "Shape \"sphere\" float radius=[3]", "ObjectBegin \"thing\"",
                       "Shape \"sphere\"", "ObjectEnd", "ObjectInstance \"thing\"",
                       "AttributeEnd", "WorldEnd"}));
}

TEST(Parser, DirectivesAreCaseSensitive) {
    EXPECT_EQ(firstError("worldbegin"), "1:1: unknown directive \"worldbegin\"");
    EXPECT_EQ(firstError("SHAPE \"sphere\""), "1:1: unknown directive \"SHAPE\"");
}

TEST(Parser, EndOfFilesIsCalledOnceWithTheLastTokenLocation) {
    auto r = parse("WorldBegin\n  Shape \"sphere\"\n\n# trailing comment\n");
    ASSERT_TRUE(r->ok);
    EXPECT_EQ(r->sink.lines,
              (Strings{"WorldBegin @t.pbrt:1:1", "Shape \"sphere\" @t.pbrt:2:3",
                       "EndOfFiles @t.pbrt:2:9"}));
    auto e = parse("");
    EXPECT_TRUE(e->ok);
    EXPECT_EQ(e->sink.lines, (Strings{"EndOfFiles @t.pbrt:1:1"}));
}

// ---------------------------------------------------------------- parameter types

TEST(Parser, EveryParameterTypeAndSynonym) {
    EXPECT_EQ(calls("Shape \"x\" \"integer i\" [1 -2] \"float f\" [1.5 -0.25]\n"
                    "  \"point2 p2\" [1 2] \"vector2 v2\" [3 4]\n"
                    "  \"point p\" [1 2 3] \"point3 p3\" [4 5 6]\n"
                    "  \"vector v\" [0 0 1] \"vector3 v3\" [0 1 0]\n"
                    "  \"normal n\" [1 0 0] \"normal3 n3\" [0 -1 0]\n"
                    "  \"color c\" [.1 .2 .3] \"rgb r\" [1 1 1] \"xyz x\" [0.5 0.6 0.7]\n"
                    "  \"blackbody bb\" [5000 2] \"spectrum s\" [400 0.5 500 0.75]\n"
                    "  \"bool b\" \"true\" \"string str\" \"a b\" \"texture t\" \"wood\"\n"),
              (Strings{"Shape \"x\" integer i=[1 -2] float f=[1.5 -0.25] point2 p2=[1 2] "
                       "vector2 v2=[3 4] point3 p=[1 2 3] point3 p3=[4 5 6] vector3 v=[0 0 1] "
                       "vector3 v3=[0 1 0] normal n=[1 0 0] normal n3=[0 -1 0] "
                       "rgb c=[0.1 0.2 0.3] rgb r=[1 1 1] xyz x=[0.5 0.6 0.7] "
                       "blackbody bb=[5000 2] spectrum s=[400 0.5 500 0.75] bool b=[true] "
                       "string str=[\"a b\"] texture t=[\"wood\"]"}));
}

TEST(Parser, ParameterTypesAreResolved) {
    auto r = parse("Shape \"x\" \"point a\" [1 2 3] \"vector b\" [1 2 3] \"normal c\" [1 2 3] "
                   "\"color d\" [1 2 3] \"bool e\" true \"texture f\" \"t\"");
    ASSERT_TRUE(r->ok);
    ASSERT_EQ(r->sink.paramLists.size(), 1u);
    const auto& ps = r->sink.paramLists[0].params();
    ASSERT_EQ(ps.size(), 6u);
    EXPECT_EQ(ps[0].type, ParamType::Point3);
    EXPECT_EQ(ps[1].type, ParamType::Vector3);
    EXPECT_EQ(ps[2].type, ParamType::Normal3);
    EXPECT_EQ(ps[3].type, ParamType::RGB);
    EXPECT_EQ(ps[4].type, ParamType::Bool);
    EXPECT_EQ(ps[5].type, ParamType::Texture);
    EXPECT_EQ(ps[5].strings, Strings{"t"});
    for (const auto& p : ps) EXPECT_FALSE(p.used);
    // The parameter list reports type errors through the parser's Diagnostics.
    EXPECT_EQ(r->sink.paramLists[0].diagnostics(), &r->diag);
}

TEST(Parser, BlackbodyWithASingleTemperature) {
    // A lone temperature gets scale 1.
    EXPECT_EQ(calls("LightSource \"point\" \"blackbody I\" [6500]\n"
                    "LightSource \"point\" \"blackbody I\" 3000"),
              (Strings{"LightSource \"point\" blackbody I=[6500 1]",
                       "LightSource \"point\" blackbody I=[3000 1]"}));
    EXPECT_EQ(calls("LightSource \"distant\" \"blackbody L\" [5000 10]"),
              (Strings{"LightSource \"distant\" blackbody L=[5000 10]"}));
}

TEST(Parser, BoolsBareQuotedAndBracketed) {
    EXPECT_EQ(calls("Material \"plastic\" \"bool a\" true \"bool b\" false \"bool c\" \"true\" "
                    "\"bool d\" [\"false\"] \"bool e\" [true] \"bool f\" [ false \"true\" ]"),
              (Strings{"Material \"plastic\" bool a=[true] bool b=[false] bool c=[true] "
                       "bool d=[false] bool e=[true] bool f=[false true]"}));
}

TEST(Parser, StringsAndTextures) {
    EXPECT_EQ(calls("MakeNamedMaterial \"Paint - White Matt\" \"string type\" \"matte\"\n"
                    "Shape \"curve\" \"string names\" [\"a\" \"b\" \"\"] \"texture Kd\" [\"t\"]"),
              (Strings{"MakeNamedMaterial \"Paint - White Matt\" string type=[\"matte\"]",
                       "Shape \"curve\" string names=[\"a\" \"b\" \"\"] texture Kd=[\"t\"]"}));
}

TEST(Parser, EscapesInStrings) {
    EXPECT_EQ(calls(R"(Shape "a\"b" "string filename" "dir\\file.exr" "string s" ["x\ty"])"),
              (Strings{"Shape \"a\"b\" string filename=[\"dir\\file.exr\"] "
                       "string s=[\"x\ty\"]"}));
    // Spaces and escapes in directive arguments.
    EXPECT_EQ(calls(R"(NamedMaterial "with space \"q\"")"),
              (Strings{"NamedMaterial \"with space \"q\"\""}));
}

TEST(Parser, NumberForms) {
    EXPECT_EQ(calls("Shape \"x\" \"float f\" [1 -2 +3 .5 -.5 5. 1e3 1E-2 -2.5e+1 0 -0 1e-400]"),
              (Strings{"Shape \"x\" float f=[1 -2 3 0.5 -0.5 5 1000 0.01 -25 0 -0 0]"}));
    EXPECT_EQ(calls("Shape \"x\" \"integer i\" [0 -7 +7 2147483647 -2147483648 1e3 4.0]"),
              (Strings{"Shape \"x\" integer i=[0 -7 7 2147483647 -2147483648 1000 4]"}));
    EXPECT_EQ(calls("Translate 1e-3 -0 +2"), (Strings{"Translate 0.001 -0 2"}));
}

TEST(Parser, ValuesWithAndWithoutBrackets) {
    EXPECT_EQ(calls("Shape \"s\" \"float radius\" 2 \"string name\" \"n\" \"integer k\" -4\n"
                    "Shape \"s\" \"float radius\" [2] \"string name\" [\"n\"] \"integer k\" [-4]\n"
                    "Shape \"s\" \"float radius\" [ 2 ] \"string name\" [ \"n\" ]\n"
                    "Shape \"s\" \"float radius\"[2]\"string name\"[\"n\"]"),
              (Strings{"Shape \"s\" float radius=[2] string name=[\"n\"] integer k=[-4]",
                       "Shape \"s\" float radius=[2] string name=[\"n\"] integer k=[-4]",
                       "Shape \"s\" float radius=[2] string name=[\"n\"]",
                       "Shape \"s\" float radius=[2] string name=[\"n\"]"}));
    // Without brackets only one value is taken; the next number is a stray token.
    EXPECT_EQ(firstError("Shape \"s\" \"float f\" 1 2"),
              "1:23: unexpected number 2; expected a directive");
}

TEST(Parser, DeclarationWhitespace) {
    EXPECT_EQ(calls("Shape \"s\" \"  float \t radius  \" 1"),
              (Strings{"Shape \"s\" float radius=[1]"}));
}

TEST(Parser, CommentsEverywhere) {
    EXPECT_EQ(calls("# header\n"
                    "Shape # after directive\n"
                    "  \"trianglemesh\" # after type\n"
                    "  \"integer indices\" # after declaration\n"
                    "  [ 0 1 # inside brackets\n"
                    "    2 ]# right after bracket\n"
                    "  \"point P\" [0 0 0 1 0 0 0 1 0] # trailing\n"
                    "#Shape \"commented out\"\n"
                    "Translate 1 # between numbers\n 2 3\n"
                    "# last line without newline"),
              (Strings{"Shape \"trianglemesh\" integer indices=[0 1 2] "
                       "point3 P=[0 0 0 1 0 0 0 1 0]",
                       "Translate 1 2 3"}));
}

TEST(Parser, RepeatedParameterNamesLastWins) {
    EXPECT_EQ(calls("Sampler \"halton\" \"integer pixelsamples\" 8 \"float x\" 1 "
                    "\"integer pixelsamples\" [64]"),
              (Strings{"Sampler \"halton\" integer pixelsamples=[64] float x=[1]"}));
    // Also across types: the later declaration replaces the earlier one.
    auto r = parse("Shape \"s\" \"float radius\" 1 \"integer radius\" 2");
    ASSERT_TRUE(r->ok);
    const auto& ps = r->sink.paramLists.at(0).params();
    ASSERT_EQ(ps.size(), 1u);
    EXPECT_EQ(ps[0].type, ParamType::Integer);
    EXPECT_EQ(ps[0].loc.col, 28);
}

TEST(Parser, RepeatedDirectivesAreAllDelivered) {
    // metal-spheres-envmap has three Sampler lines; the sink decides which one wins.
    EXPECT_EQ(calls("Sampler \"halton\" \"integer pixelsamples\" 8\n"
                    "Sampler \"halton\" \"integer pixelsamples\" 64\n"),
              (Strings{"Sampler \"halton\" integer pixelsamples=[8]",
                       "Sampler \"halton\" integer pixelsamples=[64]"}));
}

TEST(Parser, LargeArrays) {
    std::string text = "MakeNamedMedium \"m\" \"float density\" [";
    for (int i = 0; i < 100000; ++i) text += i % 2 ? " 0.5" : " 1";
    text += "] \"integer nx\" 10";
    auto r = parse(text, false);
    ASSERT_TRUE(r->ok);
    const Param* p = r->sink.paramLists.at(0).find("density");
    ASSERT_TRUE(p);
    ASSERT_EQ(p->numbers.size(), 100000u);
    EXPECT_EQ(p->numbers[0], 1.0);
    EXPECT_EQ(p->numbers[99999], 0.5);
    EXPECT_TRUE(r->sink.paramLists[0].find("nx"));
}

// ---------------------------------------------------------------- locations

TEST(Parser, DirectiveAndParameterLocations) {
    auto r = parse("WorldBegin\n"
                   "\tAttributeBegin\n"
                   "\t\tShape \"sphere\"\t\"float radius\" [3]\n"
                   "  \"float zmin\" -1\n");
    ASSERT_TRUE(r->ok);
    EXPECT_EQ(r->sink.lines,
              (Strings{"WorldBegin @t.pbrt:1:1", "AttributeBegin @t.pbrt:2:2",
                       "Shape \"sphere\" float radius=[3] float zmin=[-1] @t.pbrt:3:3",
                       "EndOfFiles @t.pbrt:4:16"}));
    const auto& ps = r->sink.paramLists.at(0).params();
    ASSERT_EQ(ps.size(), 2u);
    EXPECT_EQ(ps[0].loc.str(), "t.pbrt:3:18");
    EXPECT_EQ(ps[1].loc.str(), "t.pbrt:4:3");
}

TEST(Parser, CrLfLocations) {
    auto r = parse("WorldBegin\r\n\r\n  Shape \"sphere\" \"float radius\"\r\n [3]\r\n");
    ASSERT_TRUE(r->ok);
    EXPECT_EQ(r->sink.lines,
              (Strings{"WorldBegin @t.pbrt:1:1", "Shape \"sphere\" float radius=[3] @t.pbrt:3:3",
                       "EndOfFiles @t.pbrt:4:4"}));
    EXPECT_EQ(r->sink.paramLists.at(0).params().at(0).loc.str(), "t.pbrt:3:18");
    EXPECT_EQ(firstError("WorldBegin\r\n\tFoo\r\n"), "2:2: unknown directive \"Foo\"");
}

TEST(Parser, ErrorLocationsCountTabsAsOneColumn) {
    EXPECT_EQ(firstError("\t\t\"float fov\" 3"),
              "1:3: unexpected string \"float fov\"; expected a directive");
    EXPECT_EQ(firstError("Shape\t\"s\"\t\"float r\"\t\"x\""),
              "1:21: parameter \"float r\" expects a number, found string \"x\"");
}

// ---------------------------------------------------------------- Include

TEST(Parser, IncludeRelativeToTheIncludingFileWithNestedDirectories) {
    ScratchDir dir;
    dir.write("main.pbrt", "WorldBegin\nInclude \"sub/a.pbrt\"\nShape \"main\"\n");
    dir.write("sub/a.pbrt", "Shape \"a\"\n  Include \"deeper/b.pbrt\"\nShape \"a2\"\n");
    dir.write("sub/deeper/b.pbrt", "Shape \"b\"\nInclude \"../c.pbrt\"\n");
    dir.write("sub/c.pbrt", "# c\n\tShape \"c\"\n");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_TRUE(r->ok);
    EXPECT_EQ(r->errors(), Strings{});
    EXPECT_EQ(r->sink.lines,
              (Strings{"WorldBegin @main.pbrt:1:1", "Shape \"a\" @sub/a.pbrt:1:1",
                       "Shape \"b\" @sub/deeper/b.pbrt:1:1",
                       "Shape \"c\" @sub/deeper/../c.pbrt:2:2", "Shape \"a2\" @sub/a.pbrt:3:1",
                       "Shape \"main\" @main.pbrt:3:1", "EndOfFiles @main.pbrt:3:7"}));
}

TEST(Parser, IncludeAbsolutePathAndSameFileTwice) {
    ScratchDir dir;
    std::string geo = dir.write("geo/thing.pbrt", "Shape \"thing\"\n");
    dir.write("main.pbrt",
              "Include \"" + geo + "\"\nTranslate 1 0 0\nInclude \"geo/thing.pbrt\"\n");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_TRUE(r->ok);
    EXPECT_EQ(r->sink.lines,
              (Strings{"Shape \"thing\" @geo/thing.pbrt:1:1", "Translate 1 0 0 @main.pbrt:2:1",
                       "Shape \"thing\" @geo/thing.pbrt:1:1", "EndOfFiles @main.pbrt:3:9"}));
}

TEST(Parser, IncludeFromParseStringUsesTheNamesDirectory) {
    ScratchDir dir;
    dir.write("inc.pbrt", "Shape \"inc\"");
    test::RecordingSink sink;
    sink.stripPrefix = dir.prefix();
    Diagnostics diag;
    diag.setStream(nullptr);
    EXPECT_TRUE(parseString("Include \"inc.pbrt\"", dir.path("virtual.pbrt"), sink, diag));
    EXPECT_EQ(sink.lines, (Strings{"Shape \"inc\" @inc.pbrt:1:1", "EndOfFiles @virtual.pbrt:1:9"}));
}

TEST(Parser, ImportIsTreatedAsIncludeWithAWarning) {
    ScratchDir dir;
    dir.write("inc.pbrt", "Shape \"inc\"");
    dir.write("main.pbrt", "Import \"inc.pbrt\"");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_TRUE(r->ok);
    ASSERT_EQ(r->warnings().size(), 1u);
    EXPECT_EQ(r->diag.all()[0].loc.str(), dir.path("main.pbrt") + ":1:1");
    EXPECT_NE(r->diag.all()[0].message.find("Import"), std::string::npos);
    EXPECT_EQ(r->calls(), (Strings{"Shape \"inc\" @inc.pbrt:1:1"}));
}

TEST(Parser, ParametersAfterAnIncludeContinueTheIncludedFilesLastDirective) {
    ScratchDir dir;
    dir.write("geometry/medium.pbrt",
              "MakeNamedMedium \"smoke\" \"string type\" \"heterogeneous\"\n"
              "  \"float density\" [ 1 2 3 ]\n");
    dir.write("main.pbrt", "TransformBegin\n"
                           "\tInclude \"geometry/medium.pbrt\"\n"
                           "\t  \"color sigma_a\" [10 10 10] \"color sigma_s\" [90 90 90]\n"
                           "TransformEnd\n");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_TRUE(r->ok);
    EXPECT_EQ(r->errors(), Strings{});
    EXPECT_EQ(r->sink.lines,
              (Strings{"TransformBegin @main.pbrt:1:1",
                       "MakeNamedMedium \"smoke\" string type=[\"heterogeneous\"] "
                       "float density=[1 2 3] rgb sigma_a=[10 10 10] rgb sigma_s=[90 90 90] "
                       "@geometry/medium.pbrt:1:1",
                       "TransformEnd @main.pbrt:4:1", "EndOfFiles @main.pbrt:4:1"}));
    // Each parameter keeps the location of the file it was written in.
    const auto& ps = r->sink.paramLists.at(0).params();
    ASSERT_EQ(ps.size(), 4u);
    EXPECT_EQ(ps[1].loc.str(), dir.path("geometry/medium.pbrt") + ":2:3");
    EXPECT_EQ(ps[2].loc.str(), dir.path("main.pbrt") + ":3:4");
    EXPECT_EQ(ps[3].loc.str(), dir.path("main.pbrt") + ":3:31");
}

TEST(Parser, ParametersAfterAnIncludeAlsoAttachToAParameterlessDirective) {
    ScratchDir dir;
    dir.write("s.pbrt", "Shape \"sphere\"");
    dir.write("main.pbrt", "Include \"s.pbrt\" \"float radius\" 2");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_TRUE(r->ok);
    EXPECT_EQ(r->calls(), (Strings{"Shape \"sphere\" float radius=[2] @s.pbrt:1:1"}));
    // ... and a directive's values may even continue across the file end.
    dir.write("t.pbrt", "Translate 1 2");
    dir.write("main2.pbrt", "Include \"t.pbrt\" 3");
    auto r2 = parseFileIn(dir, "main2.pbrt");
    EXPECT_TRUE(r2->ok);
    EXPECT_EQ(r2->calls(), (Strings{"Translate 1 2 3 @t.pbrt:1:1"}));
}

TEST(Parser, SpectrumInlineAndFromSpdFile) {
    ScratchDir dir;
    dir.write("spds/Ag.eta.spd", "298.7570554 1.519\n302.4004341 1.496\n");
    dir.write("main.pbrt",
              "Material \"metal\" \"spectrum eta\" \"spds/Ag.eta.spd\" "
              "\"spectrum k\" [300 3.5 800 5.25]\n"
              "Material \"metal\" \"spectrum eta\" [\"spds/Ag.eta.spd\"]\n");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_TRUE(r->ok);
    EXPECT_EQ(r->errors(), Strings{});
    EXPECT_EQ(r->calls(),
              (Strings{"Material \"metal\" spectrum eta=\"spds/Ag.eta.spd\"[298.7570554 1.519 "
                       "302.4004341 1.496] spectrum k=[300 3.5 800 5.25] @main.pbrt:1:1",
                       "Material \"metal\" spectrum eta=\"spds/Ag.eta.spd\"[298.7570554 1.519 "
                       "302.4004341 1.496] @main.pbrt:2:1"}));
    const Param* eta = r->sink.paramLists.at(0).find("eta");
    ASSERT_TRUE(eta);
    EXPECT_EQ(eta->spectrumFile, dir.path("spds/Ag.eta.spd"));
    EXPECT_EQ(eta->numbers.size(), 4u);
    EXPECT_TRUE(r->sink.paramLists.at(0).find("k")->spectrumFile.empty());
}

TEST(Parser, SpdFileIsRelativeToTheFileThatNamesIt) {
    ScratchDir dir;
    dir.write("mat/spds/x.spd", "400 1 500 2\n");
    dir.write("mat/m.pbrt", "Material \"metal\" \"spectrum k\" \"spds/x.spd\"\n");
    dir.write("main.pbrt", "Include \"mat/m.pbrt\"\n");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_TRUE(r->ok);
    EXPECT_EQ(r->calls(), (Strings{"Material \"metal\" spectrum k=\"mat/spds/x.spd\"[400 1 500 2] "
                                   "@mat/m.pbrt:1:1"}));
}

TEST(Parser, SharedSceneCloudParsesWithIncludeContinuation) {
    RLPBRT_REQUIRE_SHARED();
    std::string path = rlpbrt::test::sharedDir() + "/scenes/cloud/cloud.pbrt";
    Parsed r;
    r.diag.setStream(nullptr);
    r.sink.maxValues = 16;
    r.ok = parseFile(path, r.sink, r.diag);
    EXPECT_TRUE(r.ok);
    EXPECT_EQ(r.errors(), Strings{});
    int media = 0;
    for (const auto& line : r.sink.lines)
        if (line.rfind("MakeNamedMedium \"smoke\"", 0) == 0) {
            ++media;
            EXPECT_NE(line.find("@" + rlpbrt::test::sharedDir() +
                                "/scenes/cloud/geometry/density_render.70.pbrt:1:1"),
                      std::string::npos);
        }
    EXPECT_EQ(media, 1);
    const ParamList* medium = nullptr;
    for (const auto& pl : r.sink.paramLists)
        if (pl.find("density")) medium = &pl;
    ASSERT_TRUE(medium);
    EXPECT_EQ(medium->find("density")->numbers.size(), 100u * 100u * 40u);
    EXPECT_EQ(medium->getInt("nx", 0), 100);
    const Param* sa = medium->find("sigma_a");
    const Param* ss = medium->find("sigma_s");
    ASSERT_TRUE(sa && ss);
    EXPECT_EQ(sa->numbers, (std::vector<double>{10, 10, 10}));
    EXPECT_EQ(ss->numbers, (std::vector<double>{90, 90, 90}));
    EXPECT_EQ(*sa->loc.file, path);
}

TEST(Parser, AllSharedScenesParseWithoutErrors) {
    RLPBRT_REQUIRE_SHARED();
    std::string root = rlpbrt::test::sharedDir() + "/scenes";
    int files = 0;
    for (const auto& scene : fs::directory_iterator(root)) {
        if (!scene.is_directory()) continue;
        for (const auto& f : fs::directory_iterator(scene.path())) {
            if (f.path().extension() != ".pbrt") continue;
            // Entry files only (the others are included by them).
            std::ifstream in(f.path());
            std::string text((std::istreambuf_iterator<char>(in)), {});
            if (text.find("WorldBegin") == std::string::npos) continue;
            Parsed r;
            r.diag.setStream(nullptr);
            r.sink.maxValues = 16;
            r.ok = parseFile(f.path().string(), r.sink, r.diag);
            EXPECT_TRUE(r.ok) << f.path();
            EXPECT_EQ(r.errors(), Strings{}) << f.path();
            EXPECT_GT(r.sink.lines.size(), 5u) << f.path();
            ++files;
        }
    }
    EXPECT_GE(files, 20);
}

// ---------------------------------------------------------------- errors

TEST(ParserErrors, ExactMessages) {
    struct Case {
        const char* text;
        const char* error;
    };
    const Case cases[] = {
        {"Foo 1 2", "1:1: unknown directive \"Foo\""},
        {"\n  3", "2:3: unexpected number 3; expected a directive"},
        {"]", "1:1: unexpected ']'; expected a directive"},
        {"[ 1 ]", "1:1: unexpected '['; expected a directive"},
        {"Shape \"s\" \"flaot r\" 1",
         "1:11: unknown parameter type \"flaot\" in \"flaot r\""},
        {"Shape \"s\" \"float\" 1",
         "1:11: malformed parameter declaration \"float\"; expected \"type name\""},
        {"Shape \"s\" \"float a b\" 1",
         "1:11: malformed parameter declaration \"float a b\"; expected \"type name\""},
        {"Shape \"s\" \"\" 1",
         "1:11: malformed parameter declaration \"\"; expected \"type name\""},
        {"Shape \"s\" \"float r\"\nWorldEnd", "1:11: parameter \"r\" has no value"},
        {"Shape \"s\" \"float r\"", "1:11: parameter \"r\" has no value"},
        {"Shape \"s\" \"float r\" []", "1:11: parameter \"r\" has no value"},
        {"Shape \"s\" \"float r\" \"x\"",
         "1:21: parameter \"float r\" expects a number, found string \"x\""},
        {"Shape \"s\" \"float r\" [1 true]",
         "1:24: parameter \"float r\" expects a number, found 'true'"},
        {"Shape \"s\" \"string n\" 5",
         "1:22: parameter \"string n\" expects a quoted string, found number 5"},
        {"Shape \"s\" \"texture n\" [5]",
         "1:24: parameter \"texture n\" expects a quoted string, found number 5"},
        {"Shape \"s\" \"bool b\" 1",
         "1:20: parameter \"bool b\" expects true or false, found number 1"},
        {"Shape \"s\" \"bool b\" \"yes\"",
         "1:20: parameter \"bool b\" expects true or false, found string \"yes\""},
        {"Shape \"s\" \"integer n\" 1.5", "1:23: parameter \"n\" expects an integer, found 1.5"},
        {"Shape \"s\" \"integer n\" [1 2147483648]",
         "1:26: parameter \"n\" expects an integer, found 2147483648"},
        {"Shape \"s\" \"float r\" 1.2.3", "1:21: invalid number \"1.2.3\""},
        {"Shape \"s\" \"float r\" nan",
         "1:21: parameter \"float r\" expects a number, found 'nan'"},
        {"Shape \"s\" \"float r\" [1 inf 2]",
         "1:24: parameter \"float r\" expects a number, found 'inf'"},
        {"Shape \"s\" \"bool b\" [ture]",
         "1:21: parameter \"bool b\" expects true or false, found 'ture'"},
        {"Shape \"s\" \"string s\" [x]",
         "1:23: parameter \"string s\" expects a quoted string, found 'x'"},
        {"Shape \"s\" \"float r\" ]", "1:11: parameter \"r\" has no value"},
        {"Shape \"s\" \"float r\" -", "1:21: invalid number \"-\""},
        {"Shape \"s\" \"float r\" +-1", "1:21: invalid number \"+-1\""},
        {"Shape \"s\" \"float r\" 1e", "1:21: invalid number \"1e\""},
        {"Shape \"s\" \"float r\" 0x10", "1:21: invalid number \"0x10\""},
        {"Shape \"s\" \"float r\" 1e999", "1:21: number 1e999 is out of range"},
        {"Shape \"s\" \"float r\" 1e39", "1:21: number 1e39 is out of range"},
        {"Shape \"s\" \"float r\" -nan", "1:21: number -nan is not finite"},
        {"Shape \"s\" \"float r\" +inf", "1:21: number +inf is not finite"},
        {"Translate 1 2 1e999", "1:15: number 1e999 is out of range"},
        {"Translate 1 2 1e39", "1:15: number 1e39 is out of range"},
        {"Shape \"s\" \"float r\" [1 [2] 3]", "1:24: nested '[' in a parameter value"},
        {"Shape \"s\" \"float r\" [1 2\n", "1:21: unterminated '[': end of input before ']'"},
        {"Shape \"s\" \"float r\" [1 2\nShape \"t\"",
         "2:1: expected ']' to close the '[' at line 1, found 'Shape'"},
        {"Shape \"s\" \"string n\" \"abc\nShape \"t\"", "1:22: unterminated string"},
        {"Shape \"s\" \"rgb Kd\" [1 2 3 4]",
         "1:11: parameter \"rgb Kd\" needs a multiple of 3 values, got 4"},
        {"Shape \"s\" \"point2 uv\" [1 2 3]",
         "1:11: parameter \"point2 uv\" needs a multiple of 2 values, got 3"},
        {"LightSource \"l\" \"blackbody I\" [5000 1 6000]",
         "1:17: parameter \"blackbody I\" needs a multiple of 2 values, got 3"},
        {"Shape \"s\" \"spectrum s\" [400 1 500]",
         "1:11: parameter \"spectrum s\" needs a multiple of 2 values, got 3"},
        {"Shape \"s\" \"spectrum s\" [400 1 \"f.spd\"]",
         "1:31: parameter \"spectrum s\" expects either numbers or one .spd file name, found "
         "string \"f.spd\""},
        {"Transform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0]",
         "1:41: \"Transform\" expects a number, found ']'"},
        {"ConcatTransform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 1]",
         "1:50: expected ']' after 16 matrix values"},
        {"LookAt 0 0 5 0 0 0 0 1\nCamera \"perspective\"",
         "2:1: \"LookAt\" expects a number, found 'Camera'"},
        {"LookAt 0 0 5 0 0 0 0 1", "1:1: \"LookAt\" expects a number"},
        {"Translate 1 \"2\" 3", "1:13: \"Translate\" expects a number, found string \"2\""},
        {"Rotate 90 0 0 x", "1:15: \"Rotate\" expects a number, found 'x'"},
        {"ActiveTransform Both", "1:17: ActiveTransform expects StartTime, EndTime or All"},
        {"ActiveTransform \"All\"", "1:17: ActiveTransform expects StartTime, EndTime or All"},
        {"ActiveTransform", "1:1: ActiveTransform expects StartTime, EndTime or All"},
        {"Shape 1", "1:7: \"Shape\" expects a shape type, found number 1"},
        {"Shape", "1:1: \"Shape\" expects a shape type"},
        {"Texture \"t\" \"float\"", "1:1: \"Texture\" expects a texture class"},
        {"NamedMaterial", "1:1: \"NamedMaterial\" expects a material name"},
        {"Include", "1:1: \"Include\" expects a file name"},
        {"CoordSysTransform camera", "1:19: \"CoordSysTransform\" expects a name, found 'camera'"},
        {"A\x01", "1:1: unknown directive \"A\""},
        {"\x01", "1:1: unexpected control character (code 1)"},
    };
    for (const auto& c : cases) EXPECT_EQ(firstError(c.text), c.error) << c.text;
}

TEST(ParserErrors, LongTokensAreShortenedInMessages) {
    std::string word(100, 'x');
    EXPECT_EQ(firstError(word), "1:1: unknown directive \"" + std::string(37, 'x') + "...\"");
}

TEST(ParserErrors, ParsingGoesOnAfterRecoverableErrors) {
    auto r = parse("Foo 1 2 [3] \"x\"\n"
                   "Shape \"a\" \"float r\" \"bad\" \"float s\" 2\n"
                   "Translate 1 x\n"
                   "Shape \"b\" \"integer n\" [1 2.5 3] \"flaot q\" [1 2] \"rgb c\" [1 2 3]\n"
                   "Shape \"c\"\n");
    EXPECT_FALSE(r->ok);
    EXPECT_EQ(r->errors(),
              (Strings{"t.pbrt:1:1: error: unknown directive \"Foo\"",
                       "t.pbrt:2:21: error: parameter \"float r\" expects a number, found string "
                       "\"bad\"",
                       "t.pbrt:3:13: error: \"Translate\" expects a number, found 'x'",
                       "t.pbrt:3:13: error: unknown directive \"x\"",
                       "t.pbrt:4:26: error: parameter \"n\" expects an integer, found 2.5",
                       "t.pbrt:4:33: error: unknown parameter type \"flaot\" in \"flaot q\""}));
    // Bad parameters are dropped; the directives and the good parameters are delivered.
    EXPECT_EQ(r->calls(), (Strings{"Shape \"a\" float s=[2] @t.pbrt:2:1",
                                   "Shape \"b\" rgb c=[1 2 3] @t.pbrt:4:1",
                                   "Shape \"c\" @t.pbrt:5:1"}));
}

TEST(ParserErrors, SinkErrorsMakeTheParseFail) {
    struct FailingSink : test::RecordingSink {
        Diagnostics* diag = nullptr;
        void worldEnd(FileLoc loc) override { diag->error(loc, "sink says no"); }
    };
    FailingSink sink;
    Diagnostics diag;
    diag.setStream(nullptr);
    sink.diag = &diag;
    EXPECT_TRUE(parseString("WorldBegin", "t.pbrt", sink, diag));
    EXPECT_FALSE(parseString("WorldEnd", "t.pbrt", sink, diag));
    // Errors reported before the parse started do not count against it.
    EXPECT_TRUE(parseString("WorldBegin", "t.pbrt", sink, diag));
}

TEST(ParserErrors, FatalErrorsFromTheSinkStopTheParse) {
    struct FatalSink : test::RecordingSink {
        Diagnostics* diag = nullptr;
        void worldBegin(FileLoc loc) override { diag->fatal(loc, "cannot go on"); }
    };
    FatalSink sink;
    Diagnostics diag;
    diag.setStream(nullptr);
    sink.diag = &diag;
    EXPECT_FALSE(parseString("Shape \"a\"\nWorldBegin\nShape \"b\"", "t.pbrt", sink, diag));
    EXPECT_EQ(sink.lines, (Strings{"Shape \"a\" @t.pbrt:1:1"}));
    ASSERT_EQ(diag.errorCount(), 1);
    EXPECT_EQ(diag.all()[0].str(), "t.pbrt:2:1: error: cannot go on");
}

TEST(ParserErrors, MissingFiles) {
    Diagnostics diag;
    diag.setStream(nullptr);
    test::RecordingSink sink;
    EXPECT_FALSE(parseFile("/nonexistent/dir/scene.pbrt", sink, diag));
    ASSERT_EQ(diag.errorCount(), 1);
    EXPECT_EQ(diag.all()[0].str(), "/nonexistent/dir/scene.pbrt: error: cannot open file "
                                   "\"/nonexistent/dir/scene.pbrt\"");
    EXPECT_TRUE(sink.lines.empty());

    ScratchDir dir;
    dir.write("main.pbrt", "Shape \"a\"\n  Include \"nope.pbrt\"\nShape \"b\"\n");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_FALSE(r->ok);
    EXPECT_EQ(r->errors(), (Strings{dir.path("main.pbrt") + ":2:3: error: cannot open file \"" +
                                    dir.path("nope.pbrt") + "\""}));
    EXPECT_EQ(r->calls(), (Strings{"Shape \"a\" @main.pbrt:1:1", "Shape \"b\" @main.pbrt:3:1"}));
}

TEST(ParserErrors, MissingSpdFile) {
    ScratchDir dir;
    dir.write("main.pbrt", "Material \"metal\" \"spectrum eta\" \"spds/none.spd\"\n"
                           "  \"float roughness\" 0.1\n");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_FALSE(r->ok);
    ASSERT_GE(r->errors().size(), 1u);
    EXPECT_EQ(r->diag.all()[0].loc.str(), dir.path("main.pbrt") + ":1:33");
    EXPECT_NE(r->diag.all()[0].message.find(dir.path("spds/none.spd")), std::string::npos);
    // The material is still delivered, without the broken parameter.
    EXPECT_EQ(r->calls(),
              (Strings{"Material \"metal\" float roughness=[0.1] @main.pbrt:1:1"}));
}

TEST(ParserErrors, CyclicIncludeIsDetected) {
    ScratchDir dir;
    dir.write("a.pbrt", "Shape \"a\"\nInclude \"sub/b.pbrt\"\n");
    dir.write("sub/b.pbrt", "Shape \"b\"\n Include \"../a.pbrt\"\nShape \"b2\"\n");
    auto r = parseFileIn(dir, "a.pbrt");
    EXPECT_FALSE(r->ok);
    EXPECT_EQ(r->errors(), (Strings{dir.path("sub/b.pbrt") +
                                    ":2:2: error: cyclic Include of \"../a.pbrt\""}));
    EXPECT_EQ(r->calls(), (Strings{"Shape \"a\" @a.pbrt:1:1", "Shape \"b\" @sub/b.pbrt:1:1",
                                   "Shape \"b2\" @sub/b.pbrt:3:1"}));
    // A file including itself.
    dir.write("self.pbrt", "Include \"./self.pbrt\"");
    auto s = parseFileIn(dir, "self.pbrt");
    EXPECT_EQ(s->errors(),
              (Strings{dir.path("self.pbrt") + ":1:1: error: cyclic Include of \"./self.pbrt\""}));
}

TEST(ParserErrors, IncludeDepthIsLimited) {
    ScratchDir dir;
    for (int i = 0; i < 80; ++i)
        dir.write("d" + std::to_string(i) + ".pbrt",
                  "Shape \"s" + std::to_string(i) + "\"\nInclude \"d" + std::to_string(i + 1) +
                      ".pbrt\"\n");
    auto r = parseFileIn(dir, "d0.pbrt");
    EXPECT_FALSE(r->ok);
    // d0 is at depth 1, so d63 is the 64th open file and may not include another one.
    EXPECT_EQ(r->errors(), (Strings{dir.path("d63.pbrt") +
                                    ":2:1: error: Include nested more than 64 levels deep"}));
    EXPECT_EQ(r->calls().size(), 64u);

    ParseLimits limits;
    limits.maxIncludeDepth = 3;
    Parsed p;
    p.diag.setStream(nullptr);
    EXPECT_FALSE(parseFile(dir.path("d0.pbrt"), p.sink, p.diag, limits));
    EXPECT_EQ(p.errors(), (Strings{dir.path("d2.pbrt") +
                                   ":2:1: error: Include nested more than 3 levels deep"}));
}

TEST(ParserErrors, ExponentialIncludeFanOutIsStopped) {
    // Each level includes the next one twice: 2^40 inclusions unless the parser stops.
    ScratchDir dir;
    for (int i = 0; i < 40; ++i) {
        std::string next = "Include \"f" + std::to_string(i + 1) + ".pbrt\"\n";
        dir.write("f" + std::to_string(i) + ".pbrt", next + next);
    }
    dir.write("f40.pbrt", "Identity\n");
    auto r = parseFileIn(dir, "f0.pbrt");
    EXPECT_FALSE(r->ok);
    ASSERT_EQ(r->errors().size(), 1u);
    EXPECT_NE(r->errors()[0].find("too many Includes"), std::string::npos) << r->errors()[0];
}

TEST(ParserErrors, IncludeOfADirectory) {
    ScratchDir dir;
    dir.write("geo/x.pbrt", "");
    dir.write("main.pbrt", "Include \"geo\"\n");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_FALSE(r->ok);
    EXPECT_EQ(r->errors(), (Strings{dir.path("main.pbrt") + ":1:1: error: \"" + dir.path("geo") +
                                    "\" is a directory, not a scene file"}));
}

TEST(ParserErrors, ErrorsInIncludedFilesHaveTheirLocation) {
    ScratchDir dir;
    dir.write("inc/bad.pbrt", "\n\n   Bogus\n");
    dir.write("main.pbrt", "Include \"inc/bad.pbrt\"\n");
    auto r = parseFileIn(dir, "main.pbrt");
    EXPECT_EQ(r->errors(),
              (Strings{dir.path("inc/bad.pbrt") + ":3:4: error: unknown directive \"Bogus\""}));
}

TEST(Parser, FiftyThousandDirectives) {
    // Nothing may be quadratic in the number of directives (counts checked, not time).
    std::string text;
    text.reserve(4 << 20);
    const int n = 12500;
    for (int i = 0; i < n; ++i) {
        text += "AttributeBegin\n  Translate " + std::to_string(i) + " 0 0\n";
        text += "  Shape \"sphere\" \"float radius\" [" + std::to_string(i % 7 + 1) +
                "] \"rgb c\" [1 2 3]\nAttributeEnd\n";
    }
    auto r = parse(text, false);
    ASSERT_TRUE(r->ok);
    ASSERT_EQ(r->sink.lines.size(), 4u * n + 1);
    EXPECT_EQ(r->sink.paramLists.size(), std::size_t(n));
    EXPECT_EQ(r->sink.lines[4 * 9999 + 1], "Translate 9999 0 0");
    EXPECT_EQ(r->sink.lines[4 * n - 2], "Shape \"sphere\" float radius=[" +
                                            std::to_string((n - 1) % 7 + 1) + "] rgb c=[1 2 3]");

    // The same number of errors is reported one by one, and parsing goes on.
    std::string bad;
    for (int i = 0; i < 50000; ++i) bad += "Bogus 1 2\n";
    bad += "WorldBegin\n";
    auto e = parse(bad, false);
    EXPECT_EQ(e->diag.errorCount(), 50000);
    EXPECT_EQ(e->calls(), Strings{"WorldBegin"});
}

}  // namespace
}  // namespace rlpbrt
