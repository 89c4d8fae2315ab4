// Resuming a render (render/resume.h, docs/DISTRIBUTED.md "Resume"): a render stopped after
// some passes (the cancel flag, as a signal stops it) and resumed from its snapshot, through
// the file, gives the uninterrupted render's image bit for bit, its statistics and its guide,
// for none, hemi and vdb (surfaces and medium tables), learned selections, learn=N and the
// adjoint roulette's pixel estimates; a resumed time budget counts the time spent; bad files
// and other renders' states are refused. The command line's --checkpoint/--resume end to end.
#include <sys/stat.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli_run.h"
#include "parser/diagnostics.h"
#include "render/render.h"
#include "render/resume.h"
#include "render/scene.h"
#include "render/scene_builder.h"
#include "scene_text.h"

namespace rlpbrt {
namespace {

// A 24x24 box room lit by a ceiling quad (2x2 sample tiles) and, with `secondEmitter`, a dim
// point light; `fog` fills it with a scattering medium (volpath; vdb's medium tables learn
// too).
std::string room(bool fog, bool secondEmitter, int spp = 16) {
    std::string s;
    if (fog)
        s += "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" "
             "\"rgb sigma_a\" [0.1 0.1 0.1] \"rgb sigma_s\" [0.6 0.6 0.6]\n"
             "MediumInterface \"\" \"fog\"\n";
    s += "LookAt 0 0.5 0.9  0 0.5 0  0 1 0\nCamera \"perspective\" \"float fov\" 70\n"
         "Film \"image\" \"integer xresolution\" 24 \"integer yresolution\" 24\n"
         "Sampler \"sobol\" \"integer pixelsamples\" " + std::to_string(spp) + "\n";
    s += std::string("Integrator \"") + (fog ? "volpath" : "path") +
         "\" \"integer maxdepth\" 6\nWorldBegin\n"
         "AttributeBegin\n  AreaLightSource \"diffuse\" \"rgb L\" [8 8 8]\n"
         "  Shape \"trianglemesh\" \"point P\" [-0.2 0.99 -0.2  0.2 0.99 -0.2  0.2 0.99 0.2  "
         "-0.2 0.99 0.2] \"integer indices\" [0 1 2 0 2 3]\nAttributeEnd\n"
         "Material \"matte\"\n";
    // A second emitter: hemi's learned light choice (and its state) takes part.
    if (secondEmitter)
        s += "LightSource \"point\" \"point from\" [0.6 0.3 0.4] \"rgb I\" [0.2 0.2 0.2]\n";
    if (fog) s += "MediumInterface \"fog\" \"\"\n";
    s += "Shape \"trianglemesh\" \"point P\" [-1 0 -1  1 0 -1  1 0 1  -1 0 1  -1 1 -1  "
         "1 1 -1  1 1 1  -1 1 1] \"integer indices\" [0 1 2 0 2 3  4 6 5 4 7 6  "
         "0 4 5 0 5 1  0 3 7 0 7 4  1 5 6 1 6 2  3 2 6 3 6 7]\nWorldEnd\n";
    return s;
}

std::unique_ptr<Scene> build(const std::string& text) {
    BuildOptions bo;
    bo.seed = 5;
    auto scene = test::sceneFromText(text, "room.pbrt", bo);
    EXPECT_NE(scene, nullptr);
    return scene;
}

std::string tempDir() {
    char tmpl[] = "/tmp/rlpbrt-resume-XXXXXX";
    return mkdtemp(tmpl) ? tmpl : "/tmp";
}

struct Case {
    const char* guide;
    const char* params;  // space-separated key=value
    bool fog;
    int stopAt;          // spp after which the first run stops
    const char* name;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

// The auto trial's cases keep one emitter: with the learned light choice between two, the
// trial's guided and plain costs come too close for its verdict to repeat from run to run.
bool autoTrial(const Case& c) { return std::string(c.params).rfind("auto=", 0) == 0; }

// One render of the case: a fresh scene and field; stopped after `stopAt` spp (0: never)
// with a snapshot then, or resumed from `resume`.
struct CaseRun {
    RenderResult result;
    guiding::GuidingStats guideStats;
    RenderSnapshot snapshot;
    bool snapshotTaken = false, resumable = false;
    bool learnsLights = false;  // the learned light choice is on (GuideSettings::learnLights)
};

CaseRun renderCase(const Case& c, int nThreads, int stopAt, const RenderSnapshot* resume) {
    CaseRun run;
    // auto=20 at 64 spp: the trial's guided pass is 19..28 spp, its plain pass 28..30 and
    // (unless guiding wins already) 30..37.
    const bool twoParts = std::string(c.params) == "auto=20";
    auto scene = build(room(c.fog, !autoTrial(c), twoParts ? 64 : 16));
    if (!scene) return run;
    guiding::GuideConfig gc;
    gc.backend = c.guide;
    std::istringstream params(c.params);
    for (std::string kv; params >> kv;) gc.params[kv.substr(0, kv.find('='))] =
                                          kv.substr(kv.find('=') + 1);
    std::unique_ptr<guiding::GuidingField> field;
    RenderOptions ro;
    std::string err;
    EXPECT_TRUE(setupGuiding(*scene, gc, &field, &ro.guide, &err)) << err;
    run.learnsLights = ro.guide.learnLights;
    ro.nThreads = nThreads;
    if (resume) {
        if (field) {
            EXPECT_TRUE(field->loadState(resume->guide, &err)) << err;
        }
        ro.resume = resume;
    }
    std::atomic<bool> cancel{false};
    if (stopAt > 0) {
        ro.cancel = &cancel;
        ro.onPass = [&](int spp, double, const Film&) {
            if (spp >= stopAt) cancel.store(true);
        };
        ro.snapshotDue = [](int, double, bool stop) { return stop; };
        ro.onSnapshot = [&](const RenderSnapshot& s, bool resumable, const Film&) {
            run.snapshot = s;
            run.snapshotTaken = true;
            run.resumable = resumable;
        };
    }
    run.result = render(*scene, ro);
    if (field) run.guideStats = field->stats();
    return run;
}

class Resume : public ::testing::TestWithParam<Case> {};

TEST_P(Resume, EqualsUninterrupted) {
    const Case c = GetParam();
    const CaseRun whole = renderCase(c, 2, 0, nullptr);
    const CaseRun first = renderCase(c, 2, c.stopAt, nullptr);
    ASSERT_TRUE(first.snapshotTaken);
    ASSERT_TRUE(first.resumable) << first.snapshot.guide;
    ASSERT_TRUE(first.result.cancelled);
    ASSERT_LT(first.result.spp, whole.result.spp);
    EXPECT_EQ(first.snapshot.spp, first.result.spp);
    // The state the case is about is there to be restored.
    const std::string params = c.params;
    if (params.rfind("mix=learn", 0) == 0) {
        EXPECT_GT(first.guideStats.selectionRegions, 0u);
    }
    if (params == "rr=adjoint") {
        EXPECT_FALSE(first.snapshot.estimates.empty());
    }
    if (params == "learn=4") {
        EXPECT_TRUE(first.snapshot.frozen);
    }
    if (params == "auto=4") {
        EXPECT_EQ(first.snapshot.trial, c.stopAt == 2 ? 1 : 2);
    }
    if (params == "auto=20") {
        EXPECT_EQ(first.snapshot.trial, 3);  // the plain pass's first part measured
        EXPECT_EQ(first.snapshot.trialPlainCount, 2);
        EXPECT_FALSE(first.snapshot.trialPlain.empty());
    }
    if (c.fog && std::string(c.guide) == "vdb") {
        EXPECT_GT(first.guideStats.mediumCells, 0u);
    }
    // hemi learns the choice between the room's two emitters (its state is restored too).
    EXPECT_EQ(first.learnsLights, std::string(c.guide) == "hemi" && !autoTrial(c));
    // Through the file, and on another thread count.
    const std::string path = tempDir() + "/state.resume";
    const ResumeFingerprint fp = {{"spp", "16"}, {"--guide", c.guide}};
    std::string err;
    ASSERT_TRUE(writeResumeFile(path, fp, first.snapshot, &err)) << err;
    ResumeFingerprint readFp;
    RenderSnapshot snap;
    ASSERT_TRUE(readResumeFile(path, &readFp, &snap, &err)) << err;
    EXPECT_EQ(readFp, fp);
    const CaseRun second = renderCase(c, 1, 0, &snap);
    EXPECT_FALSE(second.result.cancelled);
    EXPECT_EQ(second.result.spp, whole.result.spp);
    ASSERT_EQ(second.result.image.pixels.size(), whole.result.image.pixels.size());
    // The auto trial at a fixed sample count compares variances per sample, not CPU time:
    // the resumed render finishes the trial with the uninterrupted render's verdict, from the
    // same numbers.
    if (autoTrial(c)) {
        EXPECT_TRUE(second.result.autoTrial.ran);
        EXPECT_EQ(second.result.autoTrial.keptGuiding, whole.result.autoTrial.keptGuiding);
        EXPECT_EQ(second.result.autoTrial.guidedCost, whole.result.autoTrial.guidedCost);
        EXPECT_EQ(second.result.autoTrial.plainCost, whole.result.autoTrial.plainCost);
        EXPECT_EQ(second.result.autoTrial.guidedSpp, whole.result.autoTrial.guidedSpp);
    }
    EXPECT_EQ(second.result.passes, whole.result.passes);
    EXPECT_TRUE(second.result.image.pixels == whole.result.image.pixels)
        << "the resumed image differs from the uninterrupted one";
    EXPECT_EQ(second.result.stats.paths, whole.result.stats.paths);
    EXPECT_EQ(second.result.stats.rays, whole.result.stats.rays);
    EXPECT_EQ(second.result.stats.vertices, whole.result.stats.vertices);
    EXPECT_EQ(second.result.learningSpp, whole.result.learningSpp);
    EXPECT_EQ(second.guideStats.passes, whole.guideStats.passes);
    EXPECT_EQ(second.guideStats.records, whole.guideStats.records);
    EXPECT_EQ(second.guideStats.mediumCells, whole.guideStats.mediumCells);
    EXPECT_EQ(second.guideStats.selectionRegions, whole.guideStats.selectionRegions);
    std::remove(path.c_str());
}

INSTANTIATE_TEST_SUITE_P(
    Guides, Resume,
    ::testing::Values(Case{"none", "", false, 5, "none"},
                      Case{"hemi", "", false, 6, "hemi"},
                      Case{"vdb", "", false, 6, "vdb"},
                      Case{"vdb", "", true, 4, "vdb_medium"},
                      Case{"hemi", "mix=learn points=32", false, 8, "hemi_mix_learn"},
                      Case{"hemi", "learn=4", false, 6, "hemi_learn_4"},
                      Case{"hemi", "rr=adjoint", false, 10, "hemi_adjoint_roulette"},
                      Case{"hemi", "spots=4 spot-outlier=1 warmup=0", false, 5, "hemi_spots"},
                      Case{"vdb", "samples=independent", false, 3, "vdb_independent"},
                      // Stopped before the auto trial's guided pass, and between its two.
                      Case{"hemi", "auto=4", false, 2, "hemi_auto_pending"},
                      Case{"hemi", "auto=4", false, 6, "hemi_auto_between"},
                      // ... and between the two parts of its plain pass.
                      Case{"hemi", "auto=20", false, 30, "hemi_auto_plain_parts"}),
    [](const ::testing::TestParamInfo<Case>& info) { return std::string(info.param.name); });

// With a time budget, the time the snapshot had spent counts: a state that spent more than
// the budget renders no further pass.
TEST(ResumeTime, SpentTimeCountsTowardTheBudget) {
    const Case c{"hemi", "", false, 2, "t"};
    CaseRun first = renderCase(c, 1, c.stopAt, nullptr);
    ASSERT_TRUE(first.snapshotTaken);
    RenderSnapshot snap = first.snapshot;
    snap.seconds = 1000.0;
    auto scene = build(room(false, true));
    guiding::GuideConfig gc;
    gc.backend = "hemi";
    std::unique_ptr<guiding::GuidingField> field;
    RenderOptions ro;
    std::string err;
    ASSERT_TRUE(setupGuiding(*scene, gc, &field, &ro.guide, &err)) << err;
    ASSERT_TRUE(field->loadState(snap.guide, &err)) << err;
    ro.resume = &snap;
    ro.nThreads = 1;
    ro.timeBudget = 500.0;
    RenderResult r = render(*scene, ro);
    EXPECT_EQ(r.spp, snap.spp);
    EXPECT_GE(r.seconds, 1000.0);
    // The image is the snapshot's film.
    EXPECT_EQ(r.image.pixels, first.result.image.pixels);
}

// A guide state restores only into a field of the same structure, and a hemi state not into
// vdb.
TEST(ResumeGuide, StateOfAnotherFieldIsRefused) {
    const CaseRun first = renderCase(Case{"hemi", "", false, 2, "h"}, 1, 2, nullptr);
    ASSERT_TRUE(first.resumable);
    auto scene = build(room(false, true));
    for (const char* other : {"hemi points=512", "vdb"}) {
        guiding::GuideConfig gc;
        std::istringstream in(other);
        in >> gc.backend;
        for (std::string kv; in >> kv;)
            gc.params[kv.substr(0, kv.find('='))] = kv.substr(kv.find('=') + 1);
        std::unique_ptr<guiding::GuidingField> field;
        GuideSettings gs;
        std::string err;
        ASSERT_TRUE(setupGuiding(*scene, gc, &field, &gs, &err)) << err;
        EXPECT_FALSE(field->loadState(first.snapshot.guide, &err)) << other;
        EXPECT_FALSE(err.empty());
        EXPECT_FALSE(field->loadState(first.snapshot.guide.substr(0, 100), &err)) << other;
    }
}

std::string slurp(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::stringstream ss;
    ss << f.rdbuf();
    return ss.str();
}

void spit(const std::string& path, const std::string& data) {
    std::ofstream f(path, std::ios::binary);
    f << data;
}

// Truncated, corrupted or foreign files: an error that says so, never a crash.
TEST(ResumeFile, BadFilesAreErrors) {
    const CaseRun first = renderCase(Case{"vdb", "", true, 2, "v"}, 1, 2, nullptr);
    ASSERT_TRUE(first.resumable);
    const std::string dir = tempDir(), path = dir + "/s.resume", bad = dir + "/bad.resume";
    std::string err;
    ASSERT_TRUE(writeResumeFile(path, {{"k", "v"}}, first.snapshot, &err)) << err;
    const std::string data = slurp(path);
    ResumeFingerprint fp;
    RenderSnapshot s;
    for (size_t len : {size_t(0), size_t(7), size_t(12), size_t(40), data.size() / 2,
                       data.size() - 1}) {
        spit(bad, data.substr(0, len));
        err.clear();
        EXPECT_FALSE(readResumeFile(bad, &fp, &s, &err)) << len;
        EXPECT_FALSE(err.empty()) << len;
    }
    std::string flipped = data;
    flipped[data.size() / 3] ^= 0x10;
    spit(bad, flipped);
    EXPECT_FALSE(readResumeFile(bad, &fp, &s, &err));
    EXPECT_NE(err.find("checksum"), std::string::npos) << err;
    spit(bad, "P6\n1 1\n255\nabc");
    EXPECT_FALSE(readResumeFile(bad, &fp, &s, &err));
    EXPECT_NE(err.find("not an rlpbrt resume file"), std::string::npos) << err;
    EXPECT_FALSE(readResumeFile(dir + "/missing.resume", &fp, &s, &err));
    ASSERT_TRUE(readResumeFile(path, &fp, &s, &err)) << err;
    EXPECT_EQ(s.film, first.snapshot.film);
    EXPECT_EQ(s.guide, first.snapshot.guide);
}

TEST(ResumeFile, FingerprintMismatchSaysWhich) {
    const ResumeFingerprint saved = {{"spp", "32"}, {"--guide", "hemi"}, {"--seed", "0"}};
    EXPECT_EQ(fingerprintMismatch(saved, saved), "");
    const std::string d =
        fingerprintMismatch(saved, {{"spp", "64"}, {"--guide", "hemi"}, {"--seed", "0"}});
    EXPECT_EQ(d, "spp is 64 here, 32 in the file");
    EXPECT_NE(fingerprintMismatch(saved, {{"spp", "32"}, {"--guide", "hemi"}}).find("--seed"),
              std::string::npos);
}

// ---- The command line: --checkpoint writes OUTFILE.resume, --resume continues.

bool exists(const std::string& p) {
    struct stat st;
    return stat(p.c_str(), &st) == 0;
}

TEST(ResumeCli, CheckpointThenResumeEqualsUninterrupted) {
    const std::string dir = tempDir(), scene = dir + "/room.pbrt";
    spit(scene, room(false, true));
    const std::string args = scene + " --spp 16 --seed 4 --quiet --nthreads 2 --guide hemi ";
    using rlpbrt::test::runCli;
    auto whole = runCli(args + "-o " + dir + "/whole.pfm");
    ASSERT_EQ(whole.status, 0) << whole.output;
    // Stopped after 5 spp as by SIGTERM: the image so far and its restart state.
    auto first = runCli(args + "--checkpoint 0 --cancel-at-spp 5 -o " + dir + "/out.pfm");
    ASSERT_EQ(first.status, 130) << first.output;
    ASSERT_TRUE(exists(dir + "/out.pfm.resume"));
    EXPECT_NE(slurp(dir + "/out.pfm"), slurp(dir + "/whole.pfm"));
    auto second = runCli(args + "--resume " + dir + "/out.pfm.resume --stats " + dir +
                         "/s.json -o " + dir + "/out.pfm");
    ASSERT_EQ(second.status, 0) << second.output;
    EXPECT_EQ(slurp(dir + "/out.pfm"), slurp(dir + "/whole.pfm"));
    EXPECT_NE(slurp(dir + "/s.json").find("\"spp\": 16"), std::string::npos);
}

TEST(ResumeCli, OtherOptionsOrBadFilesAreRefused) {
    const std::string dir = tempDir(), scene = dir + "/room.pbrt";
    spit(scene, room(false, true));
    const std::string args = scene + " --seed 4 --quiet --nthreads 1 --guide hemi ";
    using rlpbrt::test::runCli;
    auto first = runCli(args + "--spp 8 --checkpoint 0 --cancel-at-spp 2 -o " + dir + "/a.pfm");
    ASSERT_EQ(first.status, 130) << first.output;
    const std::string state = dir + "/a.pfm.resume";
    ASSERT_TRUE(exists(state));
    // Another spp, seed or guide: refused, saying which, and nothing written.
    for (const std::string& other : {std::string("--spp 16"), std::string("--spp 8 --seed 5"),
                                     std::string("--spp 8 --guide vdb")}) {
        auto r = runCli(scene + " --quiet --nthreads 1 " +
                        (other.find("--seed") == std::string::npos ? "--seed 4 " : "") +
                        (other.find("--guide") == std::string::npos ? "--guide hemi " : "") +
                        other + " --resume " + state + " -o " + dir + "/b.pfm");
        EXPECT_EQ(r.status, 1) << other << ": " << r.output;
        EXPECT_NE(r.output.find(state + ": error: the state of another render"),
                  std::string::npos)
            << r.output;
        EXPECT_FALSE(exists(dir + "/b.pfm")) << other;
    }
    auto spp = runCli(args + "--spp 16 --resume " + state + " -o " + dir + "/b.pfm");
    EXPECT_NE(spp.output.find("spp is 16 here, 8 in the file"), std::string::npos) << spp.output;
    // The scene file changed.
    spit(dir + "/room2.pbrt", room(false, true) + "\n# edited\n");
    auto edited = runCli(dir + "/room2.pbrt --seed 4 --quiet --nthreads 1 --guide hemi --spp 8 "
                         "--resume " + state + " -o " + dir + "/b.pfm");
    EXPECT_EQ(edited.status, 1) << edited.output;
    EXPECT_NE(edited.output.find("scene file"), std::string::npos) << edited.output;
    // Truncated: an error naming the file.
    const std::string data = slurp(state);
    spit(dir + "/t.resume", data.substr(0, data.size() / 2));
    auto truncated = runCli(args + "--spp 8 --resume " + dir + "/t.resume -o " + dir + "/b.pfm");
    EXPECT_EQ(truncated.status, 1) << truncated.output;
    EXPECT_NE(truncated.output.find(dir + "/t.resume: error: truncated or corrupt"),
              std::string::npos)
        << truncated.output;
    EXPECT_FALSE(exists(dir + "/b.pfm"));
    auto missing = runCli(args + "--spp 8 --resume " + dir + "/none.resume -o " + dir + "/b.pfm");
    EXPECT_EQ(missing.status, 1) << missing.output;
    EXPECT_NE(missing.output.find(dir + "/none.resume: error:"), std::string::npos)
        << missing.output;
    EXPECT_FALSE(exists(dir + "/b.pfm"));
}

}  // namespace
}  // namespace rlpbrt
