// Tests of typed parameter lists: type names and synonyms, arities, replacement of repeated
// names, getters with defaults, type-mismatch errors, "used" tracking, file name resolution.
#include "parser/params.h"

#include <gtest/gtest.h>

#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace rlpbrt {
namespace {

using Strings = std::vector<std::string>;

Param num(ParamType t, const std::string& name, std::vector<double> v, FileLoc loc = {}) {
    Param p;
    p.type = t;
    p.name = name;
    p.numbers = std::move(v);
    p.loc = loc;
    return p;
}

Param str(ParamType t, const std::string& name, Strings v, FileLoc loc = {}) {
    Param p;
    p.type = t;
    p.name = name;
    p.strings = std::move(v);
    p.loc = loc;
    return p;
}

Param boolean(const std::string& name, std::vector<uint8_t> v) {
    Param p;
    p.type = ParamType::Bool;
    p.name = name;
    p.bools = std::move(v);
    return p;
}

Strings messages(const Diagnostics& d) {
    Strings out;
    for (const auto& x : d.all()) out.push_back(x.str());
    return out;
}

TEST(ParamTypes, NamesAndSynonyms) {
    struct Case {
        const char* name;
        ParamType type;
    };
    const Case cases[] = {
        {"integer", ParamType::Integer}, {"float", ParamType::Float},
        {"point2", ParamType::Point2},   {"vector2", ParamType::Vector2},
        {"point3", ParamType::Point3},   {"point", ParamType::Point3},
        {"vector3", ParamType::Vector3}, {"vector", ParamType::Vector3},
        {"normal3", ParamType::Normal3}, {"normal", ParamType::Normal3},
        {"rgb", ParamType::RGB},         {"color", ParamType::RGB},
        {"xyz", ParamType::XYZ},         {"blackbody", ParamType::Blackbody},
        {"spectrum", ParamType::Spectrum}, {"bool", ParamType::Bool},
        {"string", ParamType::String},   {"texture", ParamType::Texture},
    };
    for (const auto& c : cases) {
        ParamType t = ParamType::Bool;
        EXPECT_TRUE(parseParamType(c.name, &t)) << c.name;
        EXPECT_EQ(t, c.type) << c.name;
    }
    for (const char* bad : {"", "Float", "int", "point4", "colour", "bool ", "spectra"}) {
        ParamType t;
        EXPECT_FALSE(parseParamType(bad, &t)) << bad;
    }
}

TEST(ParamTypes, NamesRoundTripAndArities) {
    const ParamType all[] = {ParamType::Integer, ParamType::Float,   ParamType::Point2,
                             ParamType::Vector2, ParamType::Point3,  ParamType::Vector3,
                             ParamType::Normal3, ParamType::RGB,     ParamType::XYZ,
                             ParamType::Blackbody, ParamType::Spectrum, ParamType::Bool,
                             ParamType::String,  ParamType::Texture};
    const int arity[] = {1, 1, 2, 2, 3, 3, 3, 3, 3, 2, 2, 1, 1, 1};
    for (std::size_t i = 0; i < std::size(all); ++i) {
        ParamType back;
        ASSERT_TRUE(parseParamType(paramTypeName(all[i]), &back)) << paramTypeName(all[i]);
        EXPECT_EQ(back, all[i]);
        EXPECT_EQ(paramTypeArity(all[i]), arity[i]) << paramTypeName(all[i]);
        bool spectral = all[i] == ParamType::RGB || all[i] == ParamType::XYZ ||
                        all[i] == ParamType::Blackbody || all[i] == ParamType::Spectrum;
        EXPECT_EQ(isSpectral(all[i]), spectral);
    }
}

TEST(Param, SizeCountsTheValuesOfItsKind) {
    EXPECT_EQ(num(ParamType::Point3, "P", {1, 2, 3, 4, 5, 6}).size(), 6u);
    EXPECT_EQ(str(ParamType::String, "s", {"a", "b"}).size(), 2u);
    EXPECT_EQ(str(ParamType::Texture, "t", {"a"}).size(), 1u);
    EXPECT_EQ(boolean("b", {1, 0, 1}).size(), 3u);
    EXPECT_EQ(num(ParamType::Float, "f", {}).size(), 0u);
}

TEST(ParamList, AddReplacesARepeatedNameInPlace) {
    ParamList pl;
    EXPECT_TRUE(pl.empty());
    pl.add(num(ParamType::Float, "a", {1}));
    pl.add(num(ParamType::Float, "b", {2}));
    pl.add(num(ParamType::Integer, "a", {3}));
    ASSERT_EQ(pl.params().size(), 2u);
    EXPECT_EQ(pl.params()[0].name, "a");
    EXPECT_EQ(pl.params()[0].type, ParamType::Integer);
    EXPECT_EQ(pl.params()[1].name, "b");
    EXPECT_EQ(pl.getInt("a", 0), 3);
    EXPECT_TRUE(pl.has("b"));
    EXPECT_FALSE(pl.has("c"));
    EXPECT_EQ(pl.find("c"), nullptr);
    // find() does not mark parameters as used.
    EXPECT_FALSE(pl.find("b")->used);
}

TEST(ParamList, ScalarGettersAndDefaults) {
    ParamList pl;
    pl.add(num(ParamType::Float, "f", {2.5, 7}));
    pl.add(num(ParamType::Integer, "i", {-4, 9}));
    pl.add(boolean("b", {0, 1}));
    pl.add(str(ParamType::String, "s", {"first", "second"}));
    pl.add(str(ParamType::Texture, "t", {"tex"}));
    pl.add(num(ParamType::Point3, "p", {1, 2, 3, 4, 5, 6}));
    pl.add(num(ParamType::Vector3, "v", {0, 0, 1}));
    pl.add(num(ParamType::Normal3, "n", {0, 1, 0}));
    pl.add(num(ParamType::Point2, "uv", {0.25, 0.75}));

    EXPECT_EQ(pl.getFloat("f", 0), 2.5f);
    EXPECT_EQ(pl.getInt("i", 0), -4);
    EXPECT_EQ(pl.getBool("b", true), false);
    EXPECT_EQ(pl.getString("s", ""), "first");
    EXPECT_EQ(pl.getTexture("t"), "tex");
    EXPECT_EQ(pl.getPoint3("p", {}), (Float3{1, 2, 3}));
    EXPECT_EQ(pl.getVector3("v", {}), (Float3{0, 0, 1}));
    EXPECT_EQ(pl.getNormal3("n", {}), (Float3{0, 1, 0}));
    EXPECT_EQ(pl.getPoint2("uv", {}), (Float2{0.25f, 0.75f}));

    EXPECT_EQ(pl.getFloat("missing", 1.5f), 1.5f);
    EXPECT_EQ(pl.getInt("missing", 7), 7);
    EXPECT_EQ(pl.getBool("missing", true), true);
    EXPECT_EQ(pl.getString("missing", "def"), "def");
    EXPECT_EQ(pl.getTexture("missing"), "");
    EXPECT_EQ(pl.getPoint3("missing", (Float3{9, 8, 7})), (Float3{9, 8, 7}));
    EXPECT_EQ(pl.getPoint2("missing", (Float2{1, 2})), (Float2{1, 2}));
    EXPECT_EQ(pl.getFilename("missing"), "");
    for (const auto& p : pl.params()) EXPECT_TRUE(p.used) << p.name;
}

TEST(ParamList, EmptyValueListsGiveTheDefault) {
    ParamList pl;
    pl.add(num(ParamType::Float, "f", {}));
    pl.add(num(ParamType::Point3, "p", {}));
    EXPECT_EQ(pl.getFloat("f", 3), 3.0f);
    EXPECT_EQ(pl.getPoint3("p", (Float3{1, 1, 1})), (Float3{1, 1, 1}));
}

TEST(ParamList, ArrayGetters) {
    ParamList pl;
    pl.add(num(ParamType::Float, "f", {1, 2, 3}));
    pl.add(num(ParamType::Integer, "i", {0, 1, 2, 2, 3, 0}));
    pl.add(num(ParamType::Point3, "P", {0, 0, 0, 1, 0, 0}));
    pl.add(num(ParamType::Normal3, "N", {0, 0, 1}));
    pl.add(num(ParamType::Vector3, "S", {1, 0, 0, 0, 1, 0, 0, 0, 1}));
    pl.add(num(ParamType::Point2, "uv", {0, 0, 1, 0, 1, 1}));
    pl.add(str(ParamType::String, "names", {"a", "b"}));
    EXPECT_EQ(pl.getFloats("f"), (std::vector<float>{1, 2, 3}));
    EXPECT_EQ(pl.getInts("i"), (std::vector<int>{0, 1, 2, 2, 3, 0}));
    EXPECT_EQ(pl.getPoint3s("P"), (std::vector<Float3>{{0, 0, 0}, {1, 0, 0}}));
    EXPECT_EQ(pl.getNormal3s("N"), (std::vector<Float3>{{0, 0, 1}}));
    EXPECT_EQ(pl.getVector3s("S").size(), 3u);
    EXPECT_EQ(pl.getVector3s("S")[2], (Float3{0, 0, 1}));
    EXPECT_EQ(pl.getPoint2s("uv"), (std::vector<Float2>{{0, 0}, {1, 0}, {1, 1}}));
    EXPECT_EQ(pl.getStrings("names"), (Strings{"a", "b"}));
    EXPECT_TRUE(pl.getFloats("none").empty());
    EXPECT_TRUE(pl.getPoint3s("none").empty());
    EXPECT_TRUE(pl.getStrings("none").empty());
}

TEST(ParamList, TypeMismatchReportsAtTheParameterAndReturnsTheDefault) {
    Diagnostics diag;
    diag.setStream(nullptr);
    const std::string* file = diag.intern("scene.pbrt");
    ParamList pl(&diag);
    pl.add(num(ParamType::Integer, "radius", {2}, {file, 4, 9}));
    pl.add(num(ParamType::Point3, "P", {1, 2, 3}, {file, 5, 3}));
    pl.add(str(ParamType::String, "Kd", {"tex"}, {file, 6, 1}));
    EXPECT_EQ(pl.getFloat("radius", 1.0f), 1.0f);
    EXPECT_EQ(pl.getVector3("P", (Float3{0, 0, 0})), (Float3{0, 0, 0}));
    EXPECT_EQ(pl.getSpectral("Kd"), nullptr);
    EXPECT_EQ(pl.getTexture("Kd"), "");
    EXPECT_EQ(messages(diag),
              (Strings{"scene.pbrt:4:9: error: parameter \"radius\" has type integer, "
                       "expected float",
                       "scene.pbrt:5:3: error: parameter \"P\" has type point3, expected vector3",
                       "scene.pbrt:6:1: error: parameter \"Kd\" has type string, expected rgb or "
                       "xyz or blackbody or spectrum",
                       "scene.pbrt:6:1: error: parameter \"Kd\" has type string, expected "
                       "texture"}));
    // A mismatched read still counts as a use (no extra "unused" warning).
    for (const auto& p : pl.params()) EXPECT_TRUE(p.used);
    // Without Diagnostics a mismatch is silent.
    ParamList quiet;
    quiet.add(num(ParamType::Integer, "radius", {2}));
    EXPECT_EQ(quiet.getFloat("radius", 5.0f), 5.0f);
}

TEST(ParamList, IntegersOutsideIntRangeAreErrors) {
    Diagnostics diag;
    diag.setStream(nullptr);
    ParamList pl(&diag);
    pl.add(num(ParamType::Integer, "big", {3e9}));
    pl.add(num(ParamType::Integer, "arr", {1, -3e9}));
    pl.add(num(ParamType::Integer, "ok", {-2147483648.0, 2147483647.0}));
    EXPECT_EQ(pl.getInt("big", 5), 5);
    EXPECT_TRUE(pl.getInts("arr").empty());
    EXPECT_EQ(pl.getInts("ok"), (std::vector<int>{-2147483647 - 1, 2147483647}));
    ASSERT_EQ(diag.errorCount(), 2);
    EXPECT_EQ(diag.all()[0].message, "integer parameter \"big\" is out of range");
    EXPECT_EQ(diag.all()[1].message, "integer parameter \"arr\" is out of range");
}

TEST(ParamList, SpectralGetterAcceptsEverySpectralType) {
    ParamList pl;
    pl.add(num(ParamType::RGB, "a", {1, 2, 3}));
    pl.add(num(ParamType::XYZ, "b", {1, 2, 3}));
    pl.add(num(ParamType::Blackbody, "c", {5000, 1}));
    pl.add(num(ParamType::Spectrum, "d", {400, 1, 500, 2}));
    for (const char* n : {"a", "b", "c", "d"}) {
        const Param* p = pl.getSpectral(n);
        ASSERT_NE(p, nullptr) << n;
        EXPECT_EQ(p->name, n);
        EXPECT_TRUE(p->used);
    }
    EXPECT_EQ(pl.getSpectral("missing"), nullptr);
}

TEST(ParamList, BoolAndStringArrays) {
    ParamList pl;
    pl.add(boolean("b", {1}));
    EXPECT_TRUE(pl.getBool("b", false));
    pl.add(boolean("b", {0}));
    EXPECT_FALSE(pl.getBool("b", true));
}

TEST(ParamList, FilenamesAreRelativeToTheirFile) {
    Diagnostics diag;
    ParamList pl(&diag);
    pl.add(str(ParamType::String, "mapname", {"textures/sky.exr"},
               {diag.intern("/scenes/cloud/cloud.pbrt"), 3, 1}));
    pl.add(str(ParamType::String, "abs", {"/data/x.ply"}, {diag.intern("/scenes/a.pbrt"), 1, 1}));
    pl.add(str(ParamType::String, "nodir", {"x.ply"}, {diag.intern("a.pbrt"), 1, 1}));
    pl.add(str(ParamType::String, "empty", {""}, {diag.intern("/scenes/a.pbrt"), 1, 1}));
    pl.add(str(ParamType::String, "noloc", {"y.ply"}));
    EXPECT_EQ(pl.getFilename("mapname"), "/scenes/cloud/textures/sky.exr");
    EXPECT_EQ(pl.getFilename("abs"), "/data/x.ply");
    EXPECT_EQ(pl.getFilename("nodir"), "x.ply");
    EXPECT_EQ(pl.getFilename("empty"), "");
    EXPECT_EQ(pl.getFilename("noloc"), "y.ply");
    EXPECT_EQ(diag.errorCount(), 0);
}

TEST(ParamList, ReportUnusedWarnsAtEachUnreadParameter) {
    Diagnostics diag;
    diag.setStream(nullptr);
    const std::string* f = diag.intern("s.pbrt");
    ParamList pl(&diag);
    pl.add(num(ParamType::Float, "radius", {1}, {f, 2, 5}));
    pl.add(num(ParamType::Float, "zmin", {1}, {f, 3, 5}));
    pl.add(num(ParamType::RGB, "Kd", {1, 1, 1}, {f, 4, 5}));
    pl.getFloat("radius", 0);
    pl.reportUnused("shape \"sphere\"");
    EXPECT_EQ(messages(diag),
              (Strings{"s.pbrt:3:5: warning: parameter \"float zmin\" is not used by shape "
                       "\"sphere\"",
                       "s.pbrt:4:5: warning: parameter \"rgb Kd\" is not used by shape "
                       "\"sphere\""}));
    EXPECT_EQ(diag.errorCount(), 0);

    Diagnostics diag2;
    diag2.setStream(nullptr);
    pl.setDiagnostics(&diag2);
    EXPECT_EQ(pl.diagnostics(), &diag2);
    pl.markAllUsed();
    pl.reportUnused("x");
    EXPECT_EQ(diag2.warningCount(), 0);
}

TEST(Diagnostics, FormatsAndCounts) {
    Diagnostics diag;
    std::ostringstream os;
    diag.setStream(&os);
    const std::string* f = diag.intern("a/b.pbrt");
    EXPECT_EQ(diag.intern("a/b.pbrt"), f);
    EXPECT_NE(diag.intern("a/c.pbrt"), f);
    diag.error({f, 3, 7}, "bad thing");
    diag.warning({f, 0, 0}, "odd thing");
    diag.warning({}, "nowhere");
    EXPECT_EQ(diag.errorCount(), 1);
    EXPECT_EQ(diag.warningCount(), 2);
    EXPECT_EQ(os.str(), "a/b.pbrt:3:7: error: bad thing\na/b.pbrt: warning: odd thing\n"
                        "<unknown>: warning: nowhere\n");
    EXPECT_EQ((FileLoc{f, 1, 1}).directory(), "a/");
    EXPECT_EQ((FileLoc{diag.intern("x.pbrt"), 1, 1}).directory(), "");
    EXPECT_EQ(FileLoc{}.directory(), "");
    EXPECT_THROW(diag.fatal({f, 1, 2}, "stop"), FatalError);
    EXPECT_EQ(diag.errorCount(), 2);
    try {
        diag.fatal({f, 1, 2}, "stop");
    } catch (const FatalError& e) {
        EXPECT_STREQ(e.what(), "a/b.pbrt:1:2: error: stop");
    }
}

TEST(Diagnostics, RepeatedWarningsAndIgnoredFeatures) {
    Diagnostics diag;
    std::ostringstream os;
    diag.setStream(&os);
    for (int i = 0; i < 10; ++i) diag.warning({}, "same");
    EXPECT_EQ(diag.warningCount(), 10);
    std::string out = os.str();
    std::size_t printed = 0;
    for (std::size_t p = out.find("warning: same"); p != std::string::npos;
         p = out.find("warning: same", p + 1))
        ++printed;
    EXPECT_EQ(printed, std::size_t(Diagnostics::kMaxRepeats));
    EXPECT_NE(out.find("note: further identical warnings are not shown"), std::string::npos);

    Diagnostics d2;
    d2.setStream(nullptr);
    d2.ignored({}, "film \"gbuffer\"");
    d2.ignored({}, "accelerator");
    d2.ignored({}, "film \"gbuffer\"");
    ASSERT_EQ(d2.ignoredFeatures().size(), 2u);
    EXPECT_EQ(d2.ignoredFeatures()[0], (std::pair<std::string, int>{"film \"gbuffer\"", 2}));
    EXPECT_EQ(d2.ignoredFeatures()[1], (std::pair<std::string, int>{"accelerator", 1}));
    EXPECT_EQ(d2.warningCount(), 2);  // once per distinct feature
}

}  // namespace
}  // namespace rlpbrt
