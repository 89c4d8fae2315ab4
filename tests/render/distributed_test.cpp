// Distributed renders (docs/DISTRIBUTED.md) through mpirun: two ranks draw the same samples as
// one process and give its image (none: bit for bit, by construction; hemi and vdb: up to the
// order of the guide's floating-point sums, which for these scenes is also bit for bit); a
// scene error is printed once, fails the job and writes nothing; --time ends on time on all
// ranks. Open MPI refuses to run as root unless told: the command sets its two variables.
#include <sys/stat.h>

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_run.h"

namespace {

using rlpbrt::test::CliRun;

// The environment of the ranks: Open MPI as root, and, in the sanitizer build
// (scripts/sanitize.sh), no LeakSanitizer in the ranks: Open MPI leaves allocations of its
// plugins at MPI_Finalize, unloaded by then, so their stacks cannot be suppressed by name.
// (The guiding side of a distributed render is leak-checked in-process: SharedPass.)
const char* kRankEnv = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
                       "ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0\" ";

std::string mpirun(int ranks) {
    // (timeout: a job whose ranks disagree would wait forever in a collective)
    return std::string(kRankEnv) + "timeout 120 " + RLPBRT_MPIEXEC + " --oversubscribe -np " +
           std::to_string(ranks) + " " + RLPBRT_BINARY + " ";
}

#define REQUIRE_MPIRUN()                                                       \
    do {                                                                       \
        struct stat st_;                                                       \
        if (std::string(RLPBRT_MPIEXEC).empty() || stat(RLPBRT_MPIEXEC, &st_) != 0) \
            GTEST_SKIP() << "mpirun not found (CMake's MPIEXEC_EXECUTABLE)";   \
    } while (0)

std::string tempDir() {
    char tmpl[] = "/tmp/rlpbrt-distributed-XXXXXX";
    return mkdtemp(tmpl) ? tmpl : "/tmp";
}

// A 40x40 box room lit by a quad and a dim point light (3x3 sample tiles of 16 pixels, so both
// ranks render several); `fog` fills it with a scattering medium (the vdb backend's volume
// tables then learn too).
std::string writeRoom(const std::string& path, bool fog) {
    std::ofstream f(path);
    if (fog)
        f << "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" "
             "\"rgb sigma_a\" [0.1 0.1 0.1] \"rgb sigma_s\" [0.6 0.6 0.6]\n"
             "MediumInterface \"\" \"fog\"\n";
    f << "LookAt 0 0.5 0.9  0 0.5 0  0 1 0\nCamera \"perspective\" \"float fov\" 70\n"
         "Film \"image\" \"integer xresolution\" 40 \"integer yresolution\" 40\n"
         "Sampler \"sobol\" \"integer pixelsamples\" 8\n"
         "Integrator \"" << (fog ? "volpath" : "path") << "\" \"integer maxdepth\" 8\nWorldBegin\n"
         "AttributeBegin\n  AreaLightSource \"diffuse\" \"rgb L\" [8 8 8]\n"
         "  Shape \"trianglemesh\" \"point P\" [-0.2 0.99 -0.2  0.2 0.99 -0.2  0.2 0.99 0.2  "
         "-0.2 0.99 0.2] \"integer indices\" [0 1 2 0 2 3]\nAttributeEnd\n"
         // A second emitter: hemi's learned light choice is summed across ranks too.
         "LightSource \"point\" \"point from\" [0.6 0.3 0.4] \"rgb I\" [0.2 0.2 0.2]\n"
         "Material \"matte\"\n";
    if (fog) f << "MediumInterface \"fog\" \"\"\n";
    f << "Shape \"trianglemesh\" \"point P\" [-1 0 -1  1 0 -1  1 0 1  -1 0 1  -1 1 -1  "
         "1 1 -1  1 1 1  -1 1 1] \"integer indices\" [0 1 2 0 2 3  4 6 5 4 7 6  "
         "0 4 5 0 5 1  0 3 7 0 7 4  1 5 6 1 6 2  3 2 6 3 6 7]\nWorldEnd\n";
    return path;
}

// A PFM image's floats (empty if unreadable).
std::vector<float> readPfm(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::string magic;
    int w = 0, h = 0;
    double scale = 0.0;
    if (!(f >> magic >> w >> h >> scale) || magic != "PF" || scale >= 0.0) return {};
    f.get();
    std::vector<float> px(size_t(w) * size_t(h) * 3);
    f.read(reinterpret_cast<char*>(px.data()), std::streamsize(px.size() * sizeof(float)));
    return f ? px : std::vector<float>();
}

std::string slurp(const std::string& path) {
    std::ifstream f(path);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

size_t count(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
    return n;
}

// The number after "key": in a JSON text (-1 if absent).
double jsonNumber(const std::string& json, const std::string& key) {
    const size_t p = json.find(key + ":");
    return p == std::string::npos ? -1.0 : std::atof(json.c_str() + p + key.size() + 1);
}

struct Case {
    const char* guide;
    bool fog;
    const char* extra;  // more arguments
    const char* name;
};

// Spot lobes that form within a few spp in the room (every direction that finds 1x its
// stratum's estimate is a candidate, from the first pass on).
constexpr const char* kSpots =
    "--guide-param spots=4 --guide-param spot-outlier=1 --guide-param warmup=0";

class TwoRanks : public ::testing::TestWithParam<Case> {};

TEST_P(TwoRanks, EqualOneProcess) {
    REQUIRE_MPIRUN();
    const Case c = GetParam();
    const std::string dir = tempDir();
    const std::string scene = writeRoom(dir + "/room.pbrt", c.fog);
    const bool ownSpp = std::string(c.extra).find("--spp") != std::string::npos;
    const std::string args = scene + (ownSpp ? "" : " --spp 8") + " --seed 3 --quiet --guide " +
                             c.guide + " " + c.extra;
    // hemi's saved field has no random file id (vdb's grid has one): compared byte for byte.
    const bool hemi = std::string(c.guide) == "hemi";
    CliRun one = rlpbrt::test::runCli(args + " --nthreads 2 -o " + dir + "/one.pfm --stats " +
                                      dir + "/one.json" +
                                      (hemi ? " --guide-save " + dir + "/one.guide" : ""));
    ASSERT_EQ(one.status, 0) << one.output;
    CliRun two = rlpbrt::test::runCommand(mpirun(2) + args + " --nthreads 1 -o " + dir +
                                          "/two.pfm --stats " + dir + "/two.json" +
                                          (hemi ? " --guide-save " + dir + "/two.guide" : ""));
    ASSERT_EQ(two.status, 0) << two.output;
    const std::string stats = slurp(dir + "/two.json");
    EXPECT_NE(stats.find("\"ranks\": 2"), std::string::npos) << stats;
    EXPECT_EQ(stats.find("\"bytes_exchanged\": 0,"), std::string::npos) << stats;
    // hemi's ranks learn the choice between the room's two emitters together.
    if (hemi) {
        EXPECT_NE(stats.find("lights=learned (2 emitters)"), std::string::npos) << stats;
    }
    // The time in the collectives, and the part of it spent waiting for the other rank.
    const double exchange = jsonNumber(stats, "\"exchange_seconds\"");
    const double waiting = jsonNumber(stats, "\"exchange_wait_seconds\"");
    EXPECT_GT(exchange, 0.0) << stats;
    EXPECT_GE(waiting, 0.0) << stats;
    EXPECT_LE(waiting, exchange) << stats;
    // The ranks drew the samples of one process between them, no more (rays and paths are
    // summed over the ranks), and the guide applied as many records.
    const std::string oneStats = slurp(dir + "/one.json");
    // The auto trial (auto=N) runs on several ranks too; at a fixed sample count it compares
    // variances per sample (summed over the ranks' pixels): the verdict of one process.
    if (std::string(c.extra).find("auto=") != std::string::npos) {
        const auto verdict = [](const std::string& json) {
            for (const char* v : {"kept", "off"})
                if (json.find(std::string("\"guide_auto\": \"") + v + "\"") != std::string::npos)
                    return std::string(v);
            return std::string("not run");
        };
        EXPECT_NE(verdict(stats), "not run") << stats;
        EXPECT_GT(jsonNumber(stats, "\"guide_auto_plain_cost\""), 0.0) << stats;
        EXPECT_EQ(verdict(stats), verdict(oneStats));
        for (const char* key : {"\"guide_auto_guided_cost\"", "\"guide_auto_plain_cost\""})
            EXPECT_EQ(jsonNumber(stats, key), jsonNumber(oneStats, key)) << key;
    }
    for (const char* key : {"\"rays\"", "\"paths\"", "\"guide_records\"", "\"spp\""})
        EXPECT_EQ(jsonNumber(stats, key), jsonNumber(oneStats, key)) << key;

    const std::vector<float> a = readPfm(dir + "/one.pfm"), b = readPfm(dir + "/two.pfm");
    ASSERT_FALSE(a.empty());
    ASSERT_EQ(a.size(), b.size());
    double sum = 0.0;
    size_t differ = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        sum += a[i];
        differ += a[i] != b[i];
    }
    EXPECT_GT(sum / double(a.size()), 0.01) << "the room must be lit";
    RecordProperty("differing_values", int(differ));
    std::printf("%zu of %zu values differ\n", differ, a.size());
    if (std::string(c.guide) == "none") {
        EXPECT_EQ(differ, 0u) << "film tiles are exchanged exactly";
    } else {
        // The guide's sums may be added in another order: a few samples can then take other
        // directions. (Measured: no difference at all for these scenes.)
        EXPECT_LE(differ, a.size() / 100) << differ << " of " << a.size() << " values differ";
    }
    if (hemi) {
        const std::string g1 = slurp(dir + "/one.guide"), g2 = slurp(dir + "/two.guide");
        EXPECT_GT(g1.size(), 1000u);
        // The same field up to the order of its sums, which for these targets is exact
        // (measured; docs/DISTRIBUTED.md).
        EXPECT_TRUE(g1 == g2) << "rank 0's saved field differs from one process's";
    }
}

INSTANTIATE_TEST_SUITE_P(Backends, TwoRanks,
                         ::testing::Values(Case{"none", false, "", "none"},
                                           Case{"hemi", false, "", "hemi"},
                                           Case{"hemi", false, "--guide-param mix=learn",
                                                "hemiLearnedSelection"},
                                           Case{"hemi", false, kSpots, "hemiSpots"},
                                           Case{"hemi", false, "--guide-param auto=4",
                                                "hemiAuto"},
                                           // The trial's plain pass in two parts (28..30,
                                           // 30..37 spp) unless guiding wins after the first.
                                           Case{"hemi", false, "--guide-param auto=20 --spp 40",
                                                "hemiAutoTwoParts"},
                                           Case{"vdb", false, "", "vdb"},
                                           Case{"vdb", true, "", "vdbFog"}),
                         [](const ::testing::TestParamInfo<Case>& i) {
                             return std::string(i.param.name);
                         });

// Resume on two ranks (docs/DISTRIBUTED.md, "Resume"): a job stopped after 3 spp (as by
// SIGTERM; rank 0 writes the image and OUTFILE.resume) and resumed by a second job, whose
// ranks each read the state, gives the uninterrupted job's image bit for bit.
class TwoRanksResume : public ::testing::TestWithParam<Case> {};

TEST_P(TwoRanksResume, EqualsUninterrupted) {
    REQUIRE_MPIRUN();
    const Case c = GetParam();
    const std::string dir = tempDir();
    const std::string scene = writeRoom(dir + "/room.pbrt", c.fog);
    const std::string args = scene + " --spp 8 --seed 3 --quiet --nthreads 1 --guide " +
                             c.guide + " " + c.extra;
    CliRun whole = rlpbrt::test::runCommand(mpirun(2) + args + " -o " + dir +
                                            "/whole.pfm --stats " + dir + "/whole.json");
    ASSERT_EQ(whole.status, 0) << whole.output;
    CliRun first = rlpbrt::test::runCommand(mpirun(2) + args +
                                            " --checkpoint 0 --cancel-at-spp 3 -o " + dir +
                                            "/out.pfm");
    EXPECT_NE(first.status, 0) << first.output;  // stopped: 130
    struct stat st;
    ASSERT_EQ(stat((dir + "/out.pfm.resume").c_str(), &st), 0) << first.output;
    CliRun second = rlpbrt::test::runCommand(mpirun(2) + args + " --resume " + dir +
                                             "/out.pfm.resume -o " + dir + "/out.pfm --stats " +
                                             dir + "/out.json");
    ASSERT_EQ(second.status, 0) << second.output;
    // The auto trial (stopped before it): the resumed job runs it from the state's pixel
    // means (every rank's) and reaches the uninterrupted job's verdict from the same numbers.
    if (std::string(c.extra).find("auto=") != std::string::npos) {
        const std::string w = slurp(dir + "/whole.json"), r = slurp(dir + "/out.json");
        for (const char* key : {"\"guide_auto_guided_cost\"", "\"guide_auto_plain_cost\""}) {
            EXPECT_GT(jsonNumber(r, key), 0.0) << key << r;
            EXPECT_EQ(jsonNumber(r, key), jsonNumber(w, key)) << key;
        }
    }
    const std::vector<float> a = readPfm(dir + "/whole.pfm"), b = readPfm(dir + "/out.pfm");
    ASSERT_FALSE(a.empty());
    EXPECT_TRUE(a == b) << "the resumed job's image differs from the uninterrupted job's";
}

// A state written by one process, resumed on two ranks: a warning (the guide's sums may be
// added in another order), and, without a guide, the same image (film tiles are exact).
TEST(Distributed, ResumeOnAnotherRankCountWarns) {
    REQUIRE_MPIRUN();
    const std::string dir = tempDir();
    const std::string scene = writeRoom(dir + "/room.pbrt", false);
    const std::string args = scene + " --spp 6 --seed 3 --quiet --nthreads 1 --guide none";
    CliRun whole = rlpbrt::test::runCli(args + " -o " + dir + "/whole.pfm");
    ASSERT_EQ(whole.status, 0) << whole.output;
    CliRun first = rlpbrt::test::runCli(args + " --checkpoint 0 --cancel-at-spp 2 -o " + dir +
                                        "/out.pfm");
    ASSERT_EQ(first.status, 130) << first.output;
    CliRun second = rlpbrt::test::runCommand(mpirun(2) + args + " --resume " + dir +
                                             "/out.pfm.resume -o " + dir + "/out.pfm");
    ASSERT_EQ(second.status, 0) << second.output;
    EXPECT_EQ(count(second.output, "written by 1 rank(s), this run has 2"), 1u)
        << second.output;
    const std::vector<float> a = readPfm(dir + "/whole.pfm"), b = readPfm(dir + "/out.pfm");
    ASSERT_FALSE(a.empty());
    EXPECT_TRUE(a == b);
}

INSTANTIATE_TEST_SUITE_P(Backends, TwoRanksResume,
                         ::testing::Values(Case{"none", false, "", "none"},
                                           Case{"hemi", false, "", "hemi"},
                                           Case{"hemi", false, kSpots, "hemiSpots"},
                                           Case{"hemi", false, "--guide-param auto=4",
                                                "hemiAuto"},
                                           Case{"vdb", true, "", "vdbFog"}),
                         [](const ::testing::TestParamInfo<Case>& i) {
                             return std::string(i.param.name);
                         });

TEST(Distributed, SceneErrorOnceAndNoOutput) {
    REQUIRE_MPIRUN();
    const std::string dir = tempDir();
    {
        std::ofstream f(dir + "/bad.pbrt");
        f << "Camera \"perspective\"\nWorldBegin\nShape \"sphere\" \"float radius\" [ oops ]\n"
             "WorldEnd\n";
    }
    CliRun r = rlpbrt::test::runCommand(mpirun(2) + dir + "/bad.pbrt -o " + dir + "/bad.exr");
    EXPECT_NE(r.status, 0) << r.output;
    EXPECT_EQ(count(r.output, "bad.pbrt:3:"), 1u) << r.output;
    struct stat st;
    EXPECT_NE(stat((dir + "/bad.exr").c_str(), &st), 0) << "no image after an error";
}

// What several ranks cannot share yet (the directional trees) is refused before rendering,
// once, on every rank.
TEST(Distributed, UnsharedLearningIsRefused) {
    REQUIRE_MPIRUN();
    const std::string dir = tempDir();
    const std::string scene = writeRoom(dir + "/room.pbrt", false);
    CliRun r = rlpbrt::test::runCommand(mpirun(2) + scene +
                                        " --spp 4 --guide hemi --guide-param directions=tree -o " +
                                        dir + "/out.exr");
    EXPECT_NE(r.status, 0) << r.output;
    EXPECT_EQ(count(r.output, "several ranks"), 1u) << r.output;
    struct stat st;
    EXPECT_NE(stat((dir + "/out.exr").c_str(), &st), 0);
}

// A rank killed mid-render (SIGKILL, as a machine that goes down): the job fails and rank 0
// writes no image. (mpirun ends the job; rlpbrt writes the image only after the last pass.)
TEST(Distributed, KilledRankFailsTheJobWithoutImage) {
    REQUIRE_MPIRUN();
    const std::string dir = tempDir();
    const std::string scene = writeRoom(dir + "/room.pbrt", false);
    {
        // The ranks are mpirun's children (found through /proc: no procps needed).
        std::ofstream f(dir + "/kill.sh");
        f << "export " << kRankEnv << "\n"
          << RLPBRT_MPIEXEC << " --oversubscribe -np 2 " << RLPBRT_BINARY << " " << scene
          << " --time 30 --nthreads 1 --quiet -o " << dir << "/out.exr &\n"
          << "mp=$!\n"
             "kids() { for s in /proc/[0-9]*/status; do\n"
             "  while read -r k v; do [ \"$k\" = PPid: ] && { [ \"$v\" = \"$mp\" ] && "
             "echo ${s//[^0-9]/}; break; }; done < $s 2>/dev/null; done; }\n"
             "for i in $(seq 100); do [ $(kids | wc -l) -ge 2 ] && break; sleep 0.2; done\n"
             "sleep 1\n"
             "kill -9 $(kids | tail -n 1)\n"
             "wait $mp\n";
    }
    CliRun r = rlpbrt::test::runCommand("timeout 120 bash " + dir + "/kill.sh");
    EXPECT_NE(r.status, 0) << r.output;
    EXPECT_NE(r.status, 124) << "the job must end when a rank dies, not at its time budget";
    struct stat st;
    EXPECT_NE(stat((dir + "/out.exr").c_str(), &st), 0) << "no image from a failed job";
}

TEST(Distributed, TimeBudgetEndsOnAllRanks) {
    REQUIRE_MPIRUN();
    const std::string dir = tempDir();
    const std::string scene = writeRoom(dir + "/room.pbrt", false);
    CliRun r = rlpbrt::test::runCommand(mpirun(2) + scene +
                                        " --time 1 --nthreads 1 --quiet -o " + dir +
                                        "/t.exr --stats " + dir + "/t.json");
    ASSERT_EQ(r.status, 0) << r.output;
    const std::string stats = slurp(dir + "/t.json");
    EXPECT_NE(stats.find("\"ranks\": 2"), std::string::npos) << stats;
    const size_t p = stats.find("\"seconds\": ");
    ASSERT_NE(p, std::string::npos);
    const double seconds = std::atof(stats.c_str() + p + 11);
    EXPECT_LT(seconds, 3.0) << stats;  // whole passes within the budget, at most one over
}

}  // namespace
