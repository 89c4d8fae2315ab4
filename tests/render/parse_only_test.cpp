// Every entry file in ../shared/scenes (main files, variants, *.small.pbrt; not the
// fragments they Include) passes `rlpbrt --parse-only` with exit 0, and its summary counts
// are the ones the scene files define (verified against scene-features.md: e.g. breakfast has
// 49 plymeshes + 2 trianglemeshes, 266,296 quads + 664 triangles in PLY plus 4 wall triangles;
// buddha-fractal places 25,250 instances of a 29,890-triangle object; conference-room has
// 2,188 trianglemeshes, 761 cylinders, 536 spheres and 62 disks; materials include the
// default material).
#include <cstdio>
#include <regex>
#include <string>

#include "shared_data.h"

namespace {

struct Expected {
    const char* file;
    int shapes, triangles, instances, lights, materials, textures;
};

const Expected kScenes[] = {
    {"breakfast/breakfast-lamps.pbrt", 53, 533260, 0, 2, 17, 4},
    {"breakfast/breakfast.pbrt", 51, 533260, 0, 1, 17, 4},
    {"breakfast/breakfast.small.pbrt", 51, 533260, 0, 1, 17, 4},
    {"breakfast/f16-8a.pbrt", 53, 533260, 0, 2, 17, 4},
    {"breakfast/f16-8b.pbrt", 53, 533260, 0, 2, 17, 4},
    {"buddha-fractal/buddha-fractal.pbrt", 2, 29892, 25250, 1, 3, 0},
    {"buddha-fractal/buddha-fractal.small.pbrt", 2, 29892, 25250, 1, 3, 0},
    {"caustic-glass/f16-11a.pbrt", 2, 88066, 0, 2, 3, 0},
    {"caustic-glass/f16-11b.pbrt", 2, 88066, 0, 2, 3, 0},
    {"caustic-glass/f16-9a.pbrt", 2, 88066, 0, 2, 3, 0},
    {"caustic-glass/f16-9b.pbrt", 2, 88066, 0, 2, 3, 0},
    {"caustic-glass/f16-9c.pbrt", 2, 88066, 0, 2, 3, 0},
    {"caustic-glass/glass.pbrt", 2, 88066, 0, 2, 3, 0},
    {"caustic-glass/glass.small.pbrt", 2, 88066, 0, 2, 3, 0},
    {"cloud/cloud.pbrt", 2, 12, 0, 1, 4, 0},
    {"cloud/cloud.small.pbrt", 2, 12, 0, 1, 4, 0},
    {"cloud/f15-4a.pbrt", 2, 12, 0, 1, 4, 0},
    {"cloud/f15-4b.pbrt", 2, 12, 0, 1, 4, 0},
    {"cloud/f15-4c.pbrt", 2, 12, 0, 1, 4, 0},
    {"cloud/smoke.pbrt", 2, 12, 0, 1, 4, 0},
    {"conference-room/conference_room.pbrt", 3547, 122292, 0, 336, 49, 0},
    {"conference-room/conference_room.small.pbrt", 3547, 122292, 0, 336, 49, 0},
    {"cornell-box/scene.pbrt", 8, 36, 0, 2, 9, 0},
    {"cornell-box/scene.small.pbrt", 8, 36, 0, 2, 9, 0},
    {"killeroo-simple/killeroo-simple.pbrt", 5, 66532, 0, 1, 5, 0},
    {"killeroo-simple/killeroo-simple.small.pbrt", 5, 66532, 0, 1, 5, 0},
    {"metal-spheres-envmap/f8-22.pbrt", 3, 2, 0, 1, 4, 1},
    {"metal-spheres-envmap/f8-22.small.pbrt", 3, 2, 0, 1, 4, 1},
    {"veach-bidir/bidir.pbrt", 11, 3392, 0, 4, 10, 0},
    {"veach-bidir/bidir.small.pbrt", 11, 3392, 0, 4, 10, 0},
    {"veach-mis/mis.pbrt", 10, 12, 0, 5, 11, 0},
    {"veach-mis/mis.small.pbrt", 10, 12, 0, 5, 11, 0},
};

int grab(const std::string& text, const char* pattern) {
    std::smatch m;
    if (!std::regex_search(text, m, std::regex(pattern))) return -1;
    return std::stoi(m[1].str());
}

class ParseOnly : public ::testing::TestWithParam<Expected> {};

TEST_P(ParseOnly, SummaryCounts) {
    RLPBRT_REQUIRE_SHARED();
    const Expected& e = GetParam();
    std::string cmd = std::string(RLPBRT_BINARY) + " --parse-only " +
                      rlpbrt::test::sharedDir() + "/scenes/" + e.file + " 2>/dev/null";
    FILE* p = popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string out;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof(buf), p)) > 0) out.append(buf, n);
    int status = pclose(p);
    ASSERT_EQ(status, 0) << out;
    EXPECT_EQ(grab(out, R"(shapes: (\d+))"), e.shapes);
    EXPECT_EQ(grab(out, R"(shapes: \d+ \((\d+) triangles)"), e.triangles);
    EXPECT_EQ(grab(out, R"(instances: (\d+))"), e.instances);
    EXPECT_EQ(grab(out, R"(lights: (\d+))"), e.lights);
    EXPECT_EQ(grab(out, R"(materials: (\d+))"), e.materials);
    EXPECT_EQ(grab(out, R"(textures: (\d+))"), e.textures);
    EXPECT_GE(grab(out, R"(ignored features: (\d+))"), 0);
}

INSTANTIATE_TEST_SUITE_P(Scenes, ParseOnly, ::testing::ValuesIn(kScenes),
                         [](const ::testing::TestParamInfo<Expected>& info) {
                             std::string n = info.param.file;
                             for (char& c : n)
                                 if (!isalnum(static_cast<unsigned char>(c))) c = '_';
                             return n;
                         });

}  // namespace
