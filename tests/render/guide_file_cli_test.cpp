// --guide-save / --guide-load through the command line: a saved field loads into a new run of
// the same scene and backend; another scene, another backend or a bad file is an error with a
// clear message and exit status 1; --stats reports the vdb grid's active voxels. The command
// line runs the guided-or-plain trial only when asked (auto=N), and guides throughout by default.
#include <sys/stat.h>
#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "cli_run.h"

namespace {

using rlpbrt::test::CliRun;
CliRun run(const std::string& args) { return rlpbrt::test::runCli(args); }

// A 24x24 box room lit by a quad; `wide` moves a wall so the bounds change.
std::string writeScene(const std::string& path, bool wide) {
    std::ofstream f(path);
    f << "LookAt 0 0.5 3  0 0.5 0  0 1 0\nCamera \"perspective\" \"float fov\" 50\n"
         "Film \"image\" \"integer xresolution\" 24 \"integer yresolution\" 24\n"
         "Sampler \"random\" \"integer pixelsamples\" 2\nWorldBegin\n"
         "AttributeBegin\n  AreaLightSource \"diffuse\" \"rgb L\" [8 8 8]\n"
         "  Shape \"trianglemesh\" \"point P\" [-0.2 0.99 -0.2  0.2 0.99 -0.2  0.2 0.99 0.2  "
         "-0.2 0.99 0.2] \"integer indices\" [0 1 2 0 2 3]\nAttributeEnd\n"
         "Material \"matte\"\n";
    const float x = wide ? 1.5f : 1.f;
    f << "Shape \"trianglemesh\" \"point P\" [-1 0 -1  " << x << " 0 -1  " << x << " 0 1  -1 0 1  -1 1 -1  "
      << x << " 1 -1  " << x << " 1 1  -1 1 1] \"integer indices\" [0 1 2 0 2 3  4 6 5 4 7 6  "
         "0 4 5 0 5 1  0 3 7 0 7 4]\nWorldEnd\n";
    return path;
}

std::string slurp(const std::string& path) {
    std::ifstream f(path);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

TEST(GuideFileCli, SaveLoadAndMismatchErrors) {
    char tmpl[] = "/tmp/rlpbrt-guidefile-XXXXXX";
    const std::string dir = mkdtemp(tmpl) ? tmpl : "/tmp";
    const std::string a = writeScene(dir + "/a.pbrt", false);
    const std::string b = writeScene(dir + "/b.pbrt", true);
    const std::string out = " -o " + dir + "/out.exr --nthreads 1 ";
    const std::string vdbFile = dir + "/field.vdb", hemiFile = dir + "/field.hemi";

    CliRun save = run(a + out + "--guide=vdb --guide-save " + vdbFile + " --stats " + dir +
                   "/s.json --quiet");
    ASSERT_EQ(save.status, 0) << save.output;
    struct stat st;
    ASSERT_EQ(stat(vdbFile.c_str(), &st), 0);
    EXPECT_GT(st.st_size, 1000);
    const std::string json = slurp(dir + "/s.json");
    EXPECT_NE(json.find("\"guide_active_voxels\""), std::string::npos) << json;

    CliRun load = run(a + out + "--guide=vdb --guide-load " + vdbFile + " --quiet");
    EXPECT_EQ(load.status, 0) << load.output;

    CliRun otherScene = run(b + out + "--guide=vdb --guide-load " + vdbFile + " --quiet");
    EXPECT_EQ(otherScene.status, 1) << otherScene.output;
    EXPECT_NE(otherScene.output.find("another scene"), std::string::npos) << otherScene.output;

    CliRun otherVoxel =
        run(a + out + "--guide=vdb --guide-param voxel=3 --guide-load " + vdbFile + " --quiet");
    EXPECT_EQ(otherVoxel.status, 1) << otherVoxel.output;
    EXPECT_NE(otherVoxel.output.find("voxel size"), std::string::npos) << otherVoxel.output;

    CliRun otherBackend = run(a + out + "--guide=hemi --guide-load " + vdbFile + " --quiet");
    EXPECT_EQ(otherBackend.status, 1) << otherBackend.output;
    EXPECT_NE(otherBackend.output.find("'vdb' guiding field"), std::string::npos)
        << otherBackend.output;

    CliRun hemiSave = run(a + out + "--guide=hemi --guide-save " + hemiFile + " --quiet");
    ASSERT_EQ(hemiSave.status, 0) << hemiSave.output;
    CliRun hemiLoad = run(a + out + "--guide=hemi --guide-load " + hemiFile + " --quiet");
    EXPECT_EQ(hemiLoad.status, 0) << hemiLoad.output;
    CliRun hemiIntoVdb = run(a + out + "--guide=vdb --guide-load " + hemiFile + " --quiet");
    EXPECT_EQ(hemiIntoVdb.status, 1) << hemiIntoVdb.output;
    EXPECT_NE(hemiIntoVdb.output.find("'hemi' guiding field"), std::string::npos)
        << hemiIntoVdb.output;

    CliRun missing = run(a + out + "--guide=vdb --guide-load " + dir + "/nope.vdb --quiet");
    EXPECT_EQ(missing.status, 1) << missing.output;
    CliRun noBackend = run(a + out + "--guide-load " + vdbFile + " --quiet");
    EXPECT_EQ(noBackend.status, 1) << noBackend.output;

    for (const char* f : {"a.pbrt", "b.pbrt", "out.exr", "s.json", "field.vdb", "field.hemi"})
        std::remove((dir + "/" + f).c_str());
    rmdir(dir.c_str());
}

TEST(GuideFileCli, TheTrialRunsWhenAsked) {
    char tmpl[] = "/tmp/rlpbrt-guideauto-XXXXXX";
    const std::string dir = mkdtemp(tmpl) ? tmpl : "/tmp";
    const std::string scene = writeScene(dir + "/a.pbrt", false);
    const std::string stats = dir + "/s.json";
    const std::string a = scene + " --spp 32 --nthreads 1 --quiet -o " + dir + "/out.exr --stats " +
                          stats + " ";
    // At 32 spp: guided passes to 19 spp (the trial's guided pass is 13..19), a plain pass
    // to 25, then one way or the other.
    CliRun asked = run(a + "--guide=hemi --guide-param auto=16");
    ASSERT_EQ(asked.status, 0) << asked.output;
    std::string json = slurp(stats);
    EXPECT_TRUE(json.find("\"guide_auto\": \"kept\"") != std::string::npos ||
                json.find("\"guide_auto\": \"off\"") != std::string::npos)
        << json;
    EXPECT_NE(json.find("\"guide_auto_plain_cost\""), std::string::npos) << json;
    EXPECT_NE(json.find("\"guide_auto_plain_spp\": 6"), std::string::npos) << json;
    // auto=0, and the default, never run it.
    for (const char* always : {"--guide=vdb --guide-param auto=0", "--guide=hemi"}) {
        CliRun guided = run(a + always);
        ASSERT_EQ(guided.status, 0) << guided.output;
        json = slurp(stats);
        EXPECT_NE(json.find("\"guide_auto\": \"not run\""), std::string::npos) << always << json;
        EXPECT_NE(json.find("\"guide_guided_spp\": 32"), std::string::npos) << always << json;
    }
    CliRun bad = run(a + "--guide=hemi --guide-param auto=x");
    EXPECT_EQ(bad.status, 1) << bad.output;
    EXPECT_NE(bad.output.find("auto must be"), std::string::npos) << bad.output;
    for (const char* f : {"a.pbrt", "out.exr", "s.json"}) std::remove((dir + "/" + f).c_str());
    rmdir(dir.c_str());
}

// --stats reports guiding's cost (render/guide_clock.h): vertices with a guide, the guide's
// time per such vertex from the timed paths, the updates between passes and the share of the
// render; a plain render has none of these.
double number(const std::string& json, const std::string& key) {
    const size_t at = json.find("\"" + key + "\": ");
    if (at == std::string::npos) return -1.0;
    return std::stod(json.substr(at + key.size() + 4));
}

TEST(GuideFileCli, StatsReportTheGuidesCost) {
    char tmpl[] = "/tmp/rlpbrt-guidecost-XXXXXX";
    const std::string dir = mkdtemp(tmpl) ? tmpl : "/tmp";
    const std::string scene = writeScene(dir + "/a.pbrt", false);
    const std::string stats = dir + "/s.json";
    const std::string a = scene + " --spp 16 --nthreads 1 --quiet -o " + dir + "/out.exr --stats " +
                          stats + " ";
    for (const char* g : {"hemi", "vdb"}) {
        CliRun guided = run(a + "--guide=" + g);
        ASSERT_EQ(guided.status, 0) << guided.output;
        const std::string json = slurp(stats);
        const double vertices = number(json, "guide_guided_vertices");
        const double all = number(json, "mean_path_length") * number(json, "paths");
        EXPECT_GT(vertices, 0.0) << g << json;
        EXPECT_LE(vertices, all + 0.5) << g << json;  // one surface vertex has one lookup
        const double ns = number(json, "guide_ns_per_guided_vertex");
        EXPECT_GT(ns, 0.0) << g << json;
        EXPECT_LT(ns, 1e6) << g << json;  // a lookup and a sample take ns to us, never a ms
        EXPECT_GT(number(json, "guide_end_pass_seconds"), 0.0) << g << json;
        const double share = number(json, "guide_time_share");
        EXPECT_GT(share, 0.0) << g << json;
        EXPECT_LT(share, 1.0) << g << json;
    }
    CliRun plain = run(a + "--guide=none");
    ASSERT_EQ(plain.status, 0) << plain.output;
    EXPECT_EQ(slurp(stats).find("guide_ns_per_guided_vertex"), std::string::npos);
    for (const char* f : {"a.pbrt", "out.exr", "s.json"}) std::remove((dir + "/" + f).c_str());
    rmdir(dir.c_str());
}

// learn=N: the guide learns in the first N spp only (a render of N spp saves the same field
// as one of more spp with learn=N), learn=0 renders with a loaded field and leaves it as it
// was, --stats reports the learning spp, and bad values are errors.
TEST(GuideFileCli, LearningStopsAtTheLearnBudget) {
    char tmpl[] = "/tmp/rlpbrt-guidelearn-XXXXXX";
    const std::string dir = mkdtemp(tmpl) ? tmpl : "/tmp";
    const std::string scene = writeScene(dir + "/a.pbrt", false);
    const std::string stats = dir + "/s.json";
    const std::string a = scene + " --nthreads 1 --quiet --seed 4 -o " + dir +
                          "/out.exr --stats " + stats + " --guide=hemi ";
    const std::string f4 = dir + "/f4.hemi", f12 = dir + "/f12.hemi", f0 = dir + "/f0.hemi";
    CliRun four = run(a + "--spp 4 --guide-save " + f4);
    ASSERT_EQ(four.status, 0) << four.output;
    std::string json = slurp(stats);
    EXPECT_NE(json.find("\"guide_learning_spp\": 4,"), std::string::npos) << json;
    CliRun twelve = run(a + "--spp 12 --guide-param learn=4 --guide-save " + f12);
    ASSERT_EQ(twelve.status, 0) << twelve.output;
    json = slurp(stats);
    EXPECT_NE(json.find("\"guide_learning_spp\": 4,"), std::string::npos) << json;
    EXPECT_NE(json.find("\"guide_guided_spp\": 12,"), std::string::npos) << json;
    EXPECT_NE(json.find("\"spp\": 12,"), std::string::npos) << json;
    const std::string saved4 = slurp(f4);
    EXPECT_GT(saved4.size(), 1000u);
    EXPECT_EQ(saved4, slurp(f12));
    // Learning everything (the default) changes the field after 4 spp.
    CliRun all = run(a + "--spp 12 --guide-param learn=all --guide-save " + f0);
    ASSERT_EQ(all.status, 0) << all.output;
    EXPECT_NE(saved4, slurp(f0));
    json = slurp(stats);
    EXPECT_NE(json.find("\"guide_learning_spp\": 12,"), std::string::npos) << json;

    CliRun frozen = run(a + "--spp 6 --guide-param learn=0 --guide-load " + f4 +
                        " --guide-save " + f0);
    ASSERT_EQ(frozen.status, 0) << frozen.output;
    EXPECT_EQ(frozen.output.find("warning"), std::string::npos) << frozen.output;
    EXPECT_EQ(saved4, slurp(f0));
    json = slurp(stats);
    EXPECT_NE(json.find("\"guide_learning_spp\": 0,"), std::string::npos) << json;

    CliRun untrained = run(a + "--spp 1 --guide-param learn=0");
    EXPECT_EQ(untrained.status, 0) << untrained.output;
    EXPECT_NE(untrained.output.find("warning: learn=0 without --guide-load"), std::string::npos)
        << untrained.output;
    for (const char* bad : {"-1", "x", "1.5", "", "16777217"}) {
        CliRun r = run(a + "--spp 1 --guide-param learn=" + std::string(bad));
        EXPECT_EQ(r.status, 1) << bad << r.output;
        EXPECT_NE(r.output.find("learn must be"), std::string::npos) << bad << r.output;
    }
    for (const char* f : {"a.pbrt", "out.exr", "s.json", "f4.hemi", "f12.hemi", "f0.hemi"})
        std::remove((dir + "/" + f).c_str());
    rmdir(dir.c_str());
}

}  // namespace
