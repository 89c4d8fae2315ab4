// rlpbrt: renders pbrt-v3 scenes with a path tracer whose directions can be learned.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <unistd.h>
#include <cstdlib>

#include "cli/distributed.h"
#include "guiding/options.h"
#include "parser/diagnostics.h"
#include "rlpbrt_commit.h"  // generated at build time: RLPBRT_COMMIT
#include "render/checkpoint.h"
#include "render/image_io.h"
#include "render/metrics.h"
#include "render/render.h"
#include "render/resume.h"
#include "render/scene.h"
#include "render/scene_builder.h"

using namespace rlpbrt;

namespace {

double seconds() {
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
}

std::atomic<bool> gCancel{false};
extern "C" void onSignal(int) { gCancel.store(true); }

void printSummary(const SceneDesc& desc, const Scene& scene, const Diagnostics& diag,
                  double parseSec, double buildSec) {
    const SceneStats& s = scene.stats;
    std::printf("shapes: %zu (%zu triangles in meshes, %zu quadrics, %zu curve segments)\n",
                s.shapes, s.triangles, s.quadrics, s.curves);
    std::printf("instances: %zu of %zu objects (%zu instanced triangles)\n", s.instances,
                desc.objects.size(), s.instancedTriangles);
    std::printf("lights: %zu (%zu area lights, %zu other)\n", s.lights, s.areaLights,
                s.lights - s.areaLights);
    std::printf("materials: %zu\n", s.materials);
    std::printf("textures: %zu\n", s.textures);
    std::printf("media: %zu rendered of %zu defined%s\n", scene.media.size(), desc.media.size(),
                scene.cameraMedium >= 0 ? ", camera inside a medium" : "");
    std::printf("camera: %s, film %dx%d, sampler %s %d spp, integrator %s maxdepth %d\n",
                desc.camera.present ? desc.camera.type.c_str() : "perspective",
                scene.filmParams.xResolution, scene.filmParams.yResolution,
                scene.samplerName.c_str(), scene.sampler->samplesPerPixel(),
                scene.integrator.name.c_str(), scene.integrator.maxDepth);
    std::printf("parse: %.3f s, build: %.3f s\n", parseSec, buildSec);
    const auto& ignored = diag.ignoredFeatures();
    std::printf("ignored features: %zu\n", ignored.size());
    for (const auto& [what, count] : ignored) std::printf("  %s (x%d)\n", what.c_str(), count);
}

// What a resumed render must share with the one that wrote the state (render/resume.h): the
// scene file's contents, the film, the sampler, the spp or time budget, the seed, the guide
// and its parameters. Not the threads (images do not depend on them), nor the output.
ResumeFingerprint resumeFingerprint(const std::string& scenePath, const Scene& scene,
                                    uint64_t seed, double timeBudget,
                                    const guiding::GuideConfig& guide) {
    std::string sceneHash = "unreadable";
    {
        std::ifstream f(scenePath, std::ios::binary);
        std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
        char buf[32];
        std::snprintf(buf, sizeof(buf), "%016llx", (unsigned long long)fnv1a(text));
        if (f || f.eof()) sceneHash = buf;
    }
    const FilmParams& fp = scene.filmParams;
    const Bounds2i pb = fp.pixelBounds();
    char film[160];
    std::snprintf(film, sizeof(film), "%dx%d, pixels [%d,%d)x[%d,%d)", fp.xResolution,
                  fp.yResolution, pb.pMin.x, pb.pMax.x, pb.pMin.y, pb.pMax.y);
    std::string params;
    for (const auto& [k, v] : guide.params) params += (params.empty() ? "" : " ") + k + "=" + v;
    char budget[64];
    std::snprintf(budget, sizeof(budget), "%.17g", timeBudget);
    return {
        {"the scene file's contents (FNV-1a)", sceneHash},
        {"the film", film},
        {"the sampler", scene.samplerName},
        {"spp", std::to_string(scene.sampler->samplesPerPixel())},
        {"--time", timeBudget > 0.0 ? budget : ""},
        {"--seed", std::to_string(seed)},
        {"--guide", guide.backend},
        {"--guide-param", params},
    };
}

std::string defaultOutput(const Scene& scene) {
    return scene.filmParams.filename.empty() ? std::string("pbrt.exr") : scene.filmParams.filename;
}

}  // namespace

int main(int argc, char** argv) {
    // Under mpirun/srun: one rank of a distributed render (docs/DISTRIBUTED.md). Every rank
    // reads the scene and prepares alike; rank 0 alone prints and writes, the others are
    // quiet (their messages would repeat rank 0's).
    DistributedSession session(&argc, &argv);
    Ranks* const ranks = session.ranks();
    const bool root = !ranks || ranks->rank() == 0;
    if (session.launched() && !root) {
        if (!std::freopen("/dev/null", "w", stdout) || !std::freopen("/dev/null", "w", stderr))
            session.abort(1);
    }
    // An error before rendering: every rank stops (the ranks that did not fail learn it in
    // the agreement before the render).
    auto fail = [&] {
        if (ranks) ranks->allOk(false);
        return 1;
    };
    CLI::App app{"rlpbrt: a pbrt-v3 scene renderer with reinforcement-learned path guiding"};
    std::string scenePath, outFile, statsFile, guide = "hemi", curveFile, refFile;
    std::string guideSave, guideLoad, resumeFile;
    int cancelAtSpp = 0;
    bool parseOnly = false, quiet = false, strict = false;
    int spp = 0, nThreads = 0;
    double timeBudget = 0.0, checkpointEvery = -1.0;
    uint64_t seed = 0;
    // Option groups of --help (CLI11 lists each group under its name).
    const std::string gRender = "Render", gGuiding = "Guiding", gOutput = "Output",
                      gDiagnostics = "Diagnostics";
    app.set_version_flag("--version", std::string("rlpbrt ") + RLPBRT_VERSION + " (commit " +
                                          RLPBRT_COMMIT + ")");
    app.add_option("scene", scenePath, "pbrt-v3 scene file")->required();
    app.add_option("--spp", spp, "samples per pixel (overrides the Sampler's pixelsamples)")
        ->check(CLI::Range(1, 1 << 24))
        ->group(gRender);
    app.add_option("--time", timeBudget, "render whole passes until SECONDS are spent")
        ->check(CLI::Range(0.0, 1e9))
        ->group(gRender);
    app.add_option("--nthreads", nThreads, "threads (default: all cores)")
        ->check(CLI::Range(0, 4096))
        ->group(gRender);
    app.add_option("--seed", seed, "random seed")->group(gRender);
    std::vector<std::string> guideParams;
    app.add_option("--guide", guide, "guiding backend: none, hemi (the default) or vdb")
        ->check(CLI::IsMember({"none", "hemi", "vdb"}))
        ->group(gGuiding);
    app.add_option("--guide-param", guideParams,
                   "guiding parameter key=value (repeatable; --guide-options lists every key "
                   "with its default, docs/GUIDING.md explains them)")
        ->group(gGuiding);
    app.add_flag_callback(
           "--guide-options",
           [] {
               std::fputs(guiding::guideOptionsHelp().c_str(), stdout);
               throw CLI::Success();
           },
           "list the --guide-param keys with their defaults and exit")
        ->group(gGuiding);
    app.add_option("--guide-save", guideSave, "save the learned guiding field after rendering")
        ->group(gGuiding);
    app.add_option("--guide-load", guideLoad,
                   "start from a guiding field saved for this scene with the same backend")
        ->group(gGuiding);
    app.add_option("--outfile,-o", outFile, "output image (.exr, .png, .pfm, .hdr); default: the "
                                            "Film's filename")
        ->group(gOutput);
    app.add_flag("--quiet,-q", quiet, "no progress or summary output")->group(gOutput);
    app.add_option("--checkpoint", checkpointEvery,
                   "write the image so far (atomically, real spp in its metadata) and the "
                   "restart state OUTFILE.resume (for --resume) after each pass once SECONDS "
                   "have passed since the last checkpoint, and when stopped by a signal")
        ->check(CLI::Range(0.0, 1e9))
        ->group(gOutput);
    app.add_option("--resume", resumeFile,
                   "continue the render whose restart state FILE holds (--checkpoint writes it "
                   "to OUTFILE.resume; same scene and options)")
        ->group(gOutput);
    // (Tests: stop as a signal would, after the pass that reaches N spp. Hidden.)
    app.add_option("--cancel-at-spp", cancelAtSpp, "")->group("");
    app.add_flag("--parse-only", parseOnly, "parse and build the scene, print a summary, exit")
        ->group(gDiagnostics);
    app.add_option("--stats", statsFile, "write run statistics as JSON")->group(gDiagnostics);
    auto* refOpt = app.add_option("--ref", refFile, "reference image for --curve (same size as "
                                                    "the film's output)")
                       ->group(gDiagnostics);
    app.add_option("--curve", curveFile, "write seconds,spp,relmse against --ref after each "
                                         "pass to this CSV file")
        ->needs(refOpt)
        ->group(gDiagnostics);
    app.add_flag("--strict", strict, "treat every unsupported feature and every substitute "
                                     "(pbrt-v3's tolerance of bad input) as an error")
        ->group(gDiagnostics);
    CLI11_PARSE(app, argc, argv);
    // From here on SIGINT/SIGTERM finish the current pass and write the image so far.
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);

    Diagnostics diag;
    diag.setStrict(strict);
    double t0 = seconds();
    SceneDesc desc;
    bool ok = loadSceneDesc(scenePath, diag, &desc);
    double parseSec = seconds() - t0;
    if (!ok) {
        std::fprintf(stderr, "rlpbrt: %d error(s); nothing rendered\n", diag.errorCount());
        return fail();
    }
    BuildOptions bo;
    bo.sppOverride = spp;
    bo.seed = seed;
    bo.nThreads = nThreads;
    double t1 = seconds();
    std::unique_ptr<Scene> scene;
    try {
        scene = buildScene(desc, bo, diag);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: error: %s\n", scenePath.c_str(), e.what());
        return fail();
    }
    double buildSec = seconds() - t1;
    if (!scene || diag.errorCount() > 0) {
        std::fprintf(stderr, "rlpbrt: %d error(s); nothing rendered\n", diag.errorCount());
        return fail();
    }
    if (parseOnly) {
        printSummary(desc, *scene, diag, parseSec, buildSec);
        return 0;
    }

    // The guiding field (none: plain path tracing).
    guiding::GuideConfig gc;
    gc.backend = guide;
    for (const std::string& kv : guideParams) {
        auto eq = kv.find('=');
        if (eq == std::string::npos || eq == 0) {
            std::fprintf(stderr, "error: --guide-param expects key=value, got \"%s\"\n", kv.c_str());
            return fail();
        }
        gc.params[kv.substr(0, eq)] = kv.substr(eq + 1);
    }
    if (guide == "none" && !guideParams.empty())
        std::fprintf(stderr, "warning: --guide-param is ignored with --guide=none\n");
    std::unique_ptr<guiding::GuidingField> field;
    GuideSettings guideSettings;
    {
        std::string gerr;
        double tg = seconds();
        if (!setupGuiding(*scene, gc, &field, &guideSettings, &gerr)) {
            std::fprintf(stderr, "error: --guide=%s: %s\n", guide.c_str(), gerr.c_str());
            return fail();
        }
        if (!field && (!guideLoad.empty() || !guideSave.empty())) {
            std::fprintf(stderr, "error: --guide-load/--guide-save need a guiding backend\n");
            return fail();
        }
        if (!guideLoad.empty() && !resumeFile.empty()) {
            std::fprintf(stderr, "warning: --guide-load is ignored with --resume (the restart "
                                 "state holds the guide)\n");
            guideLoad.clear();
        }
        if (!guideLoad.empty() && !field->load(guideLoad, &gerr)) {
            std::fprintf(stderr, "error: --guide-load: %s\n", gerr.c_str());
            return fail();
        }
        if (field && !quiet)
            std::fprintf(stderr, "guide: %s (%.2f s to build)\n", field->describe().c_str(),
                         seconds() - tg);
    }
    if (field && guideSettings.learnSpp == 0 && guideLoad.empty() && resumeFile.empty())
        std::fprintf(stderr, "warning: learn=0 without --guide-load: the guide never learns, "
                             "so every vertex samples its BSDF (at the guide's cost)\n");
    const float mix = guideSettings.mix;

    if (outFile.empty()) outFile = defaultOutput(*scene);
    if (root) {
        std::string err;  // no render for an output that cannot be written
        if (!checkOutputPath(outFile, &err)) {
            std::fprintf(stderr, "%s: error: %s\n", outFile.c_str(), err.c_str());
            return fail();
        }
    }
    RenderOptions ro;
    // Error curve: relMSE against the reference after each pass, computed while its cost
    // stays under 1% of the render time so far (passes are skipped otherwise), with that
    // cost subtracted from the seconds column. Rows are written when the render ends.
    Image reference;
    std::vector<std::string> curveRows;
    double curveCost = 0.0;
    int lastCurveSpp = 0;
    if (!curveFile.empty() && root) {
        std::string rerr;
        if (!readImage(refFile, &reference, &rerr)) {
            std::fprintf(stderr, "%s: error: %s\n", refFile.c_str(), rerr.c_str());
            return fail();
        }
        const Bounds2i pb = scene->filmParams.pixelBounds();
        if (reference.width != pb.width() || reference.height != pb.height() ||
            reference.channels < 3) {
            std::fprintf(stderr, "%s: error: reference is %dx%d with %d channels; the film "
                                 "gives %dx%d RGB\n", refFile.c_str(), reference.width,
                         reference.height, reference.channels, pb.width(), pb.height());
            return fail();
        }
        ro.onPass = [&](int passSpp, double elapsed, const Film& film) {
            if (curveCost > 0.01 * elapsed) return;
            const double tc = seconds();
            const double e = relMseTrimmed(film.toImage(), reference);
            char row[96];
            std::snprintf(row, sizeof(row), "%.6f,%d,%.9g", elapsed - curveCost, passSpp, e);
            curveRows.push_back(row);
            lastCurveSpp = passSpp;
            curveCost += seconds() - tc;
        };
    }
    ro.nThreads = nThreads;
    ro.timeBudget = timeBudget;
    ro.progress = !quiet && isatty(STDERR_FILENO);
    ro.cancel = &gCancel;
    ro.guide = guideSettings;
    auto metadata = [&](int spp, double renderSeconds) -> ImageMetadata {
        return {
            {"rlpbrt:version", RLPBRT_VERSION},
            {"rlpbrt:commit", RLPBRT_COMMIT},
            {"rlpbrt:spp", std::to_string(spp)},
            {"rlpbrt:seconds", std::to_string(renderSeconds)},
            {"rlpbrt:seed", std::to_string(seed)},
            {"rlpbrt:guide", guide},
            {"rlpbrt:scene", scenePath},
        };
    };
    Checkpointer checkpoint(outFile, checkpointEvery, metadata);
    // Resuming (docs/DISTRIBUTED.md, "Resume"): every rank reads the state itself (a shared
    // file system, as for the scene); one that does not match the scene and options stops all.
    // (The scene file is read again for its hash only where a state is written or read.)
    const ResumeFingerprint fingerprint =
        checkpointEvery >= 0.0 || !resumeFile.empty()
            ? resumeFingerprint(scenePath, *scene, seed, timeBudget, gc)
            : ResumeFingerprint();
    RenderSnapshot resumed;
    if (!resumeFile.empty()) {
        ResumeFingerprint saved;
        std::string rerr;
        if (!readResumeFile(resumeFile, &saved, &resumed, &rerr)) {
            std::fprintf(stderr, "%s: error: %s\n", resumeFile.c_str(), rerr.c_str());
            return fail();
        }
        const std::string diff = fingerprintMismatch(saved, fingerprint);
        if (!diff.empty()) {
            std::fprintf(stderr, "%s: error: the state of another render: %s\n",
                         resumeFile.c_str(), diff.c_str());
            return fail();
        }
        if (resumed.film.size() != size_t(scene->filmParams.pixelBounds().area()) * 4) {
            std::fprintf(stderr, "%s: error: corrupt resume file (film size)\n",
                         resumeFile.c_str());
            return fail();
        }
        if (field && !field->loadState(resumed.guide, &rerr)) {
            std::fprintf(stderr, "%s: error: the guide's state: %s\n", resumeFile.c_str(),
                         rerr.c_str());
            return fail();
        }
        if (!field && !resumed.guide.empty()) {
            std::fprintf(stderr, "%s: error: corrupt resume file (a guide state without a "
                                 "guide)\n", resumeFile.c_str());
            return fail();
        }
        const int nRanks = ranks ? ranks->size() : 1;
        if (resumed.ranks != nRanks)
            std::fprintf(stderr, "warning: %s was written by %d rank(s), this run has %d: the "
                                 "result is a valid render, but not bit for bit the "
                                 "uninterrupted one\n",
                         resumeFile.c_str(), resumed.ranks, nRanks);
        if (!quiet)
            std::fprintf(stderr, "resuming after pass %d (%d spp, %.2f s)%s%s\n",
                         resumed.passes, resumed.spp, resumed.seconds,
                         field ? "; guide: " : "", field ? field->describe().c_str() : "");
        checkpoint.setLast(resumed.seconds);
        ro.resume = &resumed;
    }
    // With --checkpoint, rank 0 writes the image and the restart state OUTFILE.resume after
    // each pass once SECONDS have passed since the last, and both when the render is
    // stopped (SIGINT/SIGTERM): a killed render loses at most one interval.
    const std::string resumeOut = outFile + ".resume";
    bool resumeWarned = false;
    if (checkpointEvery >= 0.0 && root) {
        ro.snapshotDue = [&](int, double t, bool stop) { return stop || checkpoint.due(t); };
        ro.onSnapshot = [&](const RenderSnapshot& snap, bool resumable, const Film& film) {
            checkpoint.write(snap.spp, snap.seconds, film);
            std::string werr;
            if (!resumable) {
                werr = "no restart state: " + snap.guide;
            } else if (writeResumeFile(resumeOut, fingerprint, snap, &werr)) {
                return;
            }
            if (!resumeWarned)
                std::fprintf(stderr, "%s: warning: %s\n", resumeOut.c_str(), werr.c_str());
            resumeWarned = true;
        };
    }
    if (cancelAtSpp > 0)
        ro.onPass = chainOnPass(std::move(ro.onPass), [&](int passSpp, double, const Film&) {
            if (passSpp >= cancelAtSpp) gCancel.store(true);
        });
    if (ranks) {
        if (field && !field->sharesPasses()) {
            std::fprintf(stderr, "error: this guide (%s) cannot be learned by several ranks "
                                 "yet (directions=tree; docs/DISTRIBUTED.md)\n",
                         guide.c_str());
            return fail();
        }
        if (!ranks->allOk(true)) {
            std::fprintf(stderr, "rlpbrt: another rank failed before rendering; nothing "
                                 "rendered\n");
            return 1;
        }
        ro.ranks = ranks;
    }
    RenderResult r = render(*scene, ro);
    if (!root) return r.cancelled ? 130 : 0;  // rank 0 writes the outputs

    ImageMetadata meta = metadata(r.spp, r.seconds);
    std::string err;
    if (!writeImage(outFile, r.image, meta, &err)) {
        std::fprintf(stderr, "%s: error: %s\n", outFile.c_str(), err.c_str());
        return 1;
    }
    if (!curveFile.empty()) {
        // The last pass always has a row (the cost rule may have skipped it).
        if (r.spp > 0 && (curveRows.empty() || lastCurveSpp != r.spp)) {
            char row[96];
            std::snprintf(row, sizeof(row), "%.6f,%d,%.9g", r.seconds - curveCost, r.spp,
                          relMseTrimmed(r.image, reference));
            curveRows.push_back(row);
        }
        std::string content = "seconds,spp,relmse\n";
        for (const std::string& row : curveRows) content += row + "\n";
        if (!writeFileAtomically(curveFile, content, &err)) {
            std::fprintf(stderr, "%s: error: %s\n", curveFile.c_str(), err.c_str());
            return 1;
        }
    }
    if (!guideSave.empty()) {
        if (!field->save(guideSave, &err)) {
            std::fprintf(stderr, "error: --guide-save: %s\n", err.c_str());
            return 1;
        }
    }
    if (r.stats.nonFinite > 0)
        std::fprintf(stderr, "warning: %llu non-finite samples were dropped\n",
                     (unsigned long long)r.stats.nonFinite);
    if (!statsFile.empty()) {
        const PathStats& s = r.stats;
        nlohmann::json j;
        j["seconds"] = r.seconds;
        j["parse_seconds"] = parseSec;
        j["build_seconds"] = buildSec;
        j["spp"] = r.spp;
        j["rays"] = s.rays;
        j["paths"] = s.paths;
        j["zero_contribution_fraction"] = s.paths ? double(s.zeroRadiancePaths) / s.paths : 0.0;
        j["mean_path_length"] = s.paths ? double(s.vertices) / s.paths : 0.0;
        j["guide"] = guide;
        // The field's tables and the surface patches it asked for (render/patches.h).
        j["guide_bytes"] = field ? field->bytes() + (guideSettings.patches
                                                         ? guideSettings.patches->bytes()
                                                         : 0)
                                 : 0;
        if (field) {
            guiding::GuidingStats gs = field->stats();
            j["guide_records"] = gs.records;
            j["guide_rejected_targets"] = gs.rejectedTargets;
            j["guide_mix"] = mix;
            if (guide == "vdb") j["guide_active_voxels"] = gs.activeVoxels;
            j["guide_learned_regions"] = gs.learnedRegions;
            j["guide_capped_regions"] = gs.cappedRegions;
            j["guide_pruned_regions"] = gs.prunedRegions;
            j["guide_summary"] = field->describe();  // the guide's state after the render
            // Guiding's cost (render/guide_clock.h): the guide's time per vertex with a guide,
            // from the timed paths; the updates between passes; their share of the render's
            // thread time.
            const double nsPerVertex =
                s.timedGuidedVertices ? s.guideClock.guideNanos() / double(s.timedGuidedVertices)
                                      : 0.0;
            // Vertices of all ranks over the thread time of all ranks.
            const double threads = double(r.threads) * double(r.ranks);
            j["guide_guided_vertices"] = s.guidedVertices;
            j["guide_ns_per_guided_vertex"] = nsPerVertex;
            j["guide_end_pass_seconds"] = r.guideEndPassSeconds;
            j["guide_time_share"] =
                r.seconds > 0.0 ? (nsPerVertex * 1e-9 * double(s.guidedVertices) / threads +
                                   r.guideEndPassSeconds) / r.seconds
                                : 0.0;
            if (gs.mediumCells) j["guide_medium_cells"] = gs.mediumCells;
            if (gs.selectionRegions) {
                j["guide_selection_regions"] = gs.selectionRegions;
                j["guide_selection_mean"] = gs.selectionMean;
            }
            const RenderResult::AutoTrial& at = r.autoTrial;
            j["guide_auto"] = !at.ran ? "not run" : at.keptGuiding ? "kept" : "off";
            j["guide_guided_spp"] = at.guidedSpp;
            j["guide_learning_spp"] = r.learningSpp;
            if (at.ran) {
                j["guide_auto_guided_cost"] = at.guidedCost;
                j["guide_auto_plain_cost"] = at.plainCost;
                j["guide_auto_plain_spp"] = at.plainSpp;
            }
        }
        j["nonfinite_samples"] = s.nonFinite;
        j["cancelled"] = r.cancelled;
        j["checkpoints"] = checkpoint.written();
        // A distributed render: its ranks, and the bytes rank 0 put into their collectives
        // (film tiles, guide statistics, decisions) in all and per pass.
        j["ranks"] = r.ranks;
        j["passes"] = r.passes;
        j["bytes_exchanged"] = r.bytesExchanged;
        j["bytes_exchanged_per_pass"] = r.passes ? double(r.bytesExchanged) / r.passes : 0.0;
        // Rank 0's wall seconds in the collectives during the render (waiting for slower
        // ranks included).
        j["exchange_seconds"] = r.secondsExchanging;
        // ... of which at the barrier before each collective: waiting for the slowest rank.
        j["exchange_wait_seconds"] = r.secondsWaiting;
        std::ofstream f(statsFile);
        f << j.dump(2) << "\n";
        if (!f) {
            std::fprintf(stderr, "%s: error: cannot write statistics\n", statsFile.c_str());
            return 1;
        }
    }
    if (!quiet)
        std::fprintf(stderr, "rendered %s: %dx%d, %d spp in %.2f s (parse %.2f s, build %.2f s), "
                             "%.2f Mrays/s -> %s\n",
                     scenePath.c_str(), r.image.width, r.image.height, r.spp, r.seconds, parseSec,
                     buildSec, r.stats.rays / std::max(r.seconds, 1e-9) * 1e-6, outFile.c_str());
    return r.cancelled ? 130 : 0;
}
