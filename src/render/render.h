// The render loop: passes of samples over film tiles on a thread pool, a time or spp budget,
// progress reporting, and the statistics of a run.
#pragma once

#include <atomic>
#include <functional>
#include <string>

#include "render/distributed.h"
#include "render/image.h"
#include "render/integrator.h"
#include "render/resume.h"
#include "render/scene.h"

namespace rlpbrt {

struct RenderOptions {
    int nThreads = 0;            // 0 = all cores
    double timeBudget = 0.0;     // seconds; > 0 renders whole passes until it is spent
    bool progress = false;       // progress bar on stderr
    const std::atomic<bool>* cancel = nullptr;  // set to stop after the current pass
    GuideSettings guide;         // guiding field (null = plain path tracing) and mixture
    // A guided pass takes at most this many camera paths per process (its share of the
    // image's pixels times the pass's samples per pixel, at least one sample per pixel): its
    // training records are buffered until the pass ends, about 110 bytes per path
    // (render.cpp, the passes).
    long long maxPassPaths = 1ll << 22;
    // Called after each pass with the image so far (for curves and checkpoints).
    std::function<void(int spp, double seconds, const Film& film)> onPass;
    // The ranks of a distributed render (null: this process renders alone). Each rank
    // renders the tiles ownsTile() gives it, of every pass; the film sums go to rank 0 (to
    // every rank where the integrator reads the image so far), the guide's pass statistics
    // to every rank (GuidingField::endPassShared), and rank 0's clock and cancel flag decide
    // for all. Only rank 0's result image and onPass calls are meaningful.
    Ranks* ranks = nullptr;
    // Resuming (render/resume.h): continue after the snapshot's last pass, from its film sums,
    // counters, time (a time budget counts it) and loop state, as the render that took it
    // would have gone on. The caller has restored the snapshot's guide state into guide.field
    // (GuidingField::loadState) and checked that scene and options match. Every rank passes
    // the same snapshot.
    const RenderSnapshot* resume = nullptr;
    // Snapshots: after each pass and its onPass, rank 0 asks snapshotDue(spp, seconds, stop)
    // (stop: the render stops after this pass, cancelled); where it says yes, the statistics
    // are summed over the ranks and onSnapshot gets the snapshot and the film on rank 0.
    // resumable false: the snapshot cannot be resumed from (the guide cannot save its state),
    // and its `guide` holds the reason.
    std::function<bool(int spp, double seconds, bool stop)> snapshotDue;
    std::function<void(const RenderSnapshot& snapshot, bool resumable, const Film& film)>
        onSnapshot;
};

struct RenderResult {
    Image image;
    int spp = 0;            // samples per pixel actually rendered
    double seconds = 0.0;   // render time (without parsing and building)
    PathStats stats;
    bool cancelled = false;
    // Samples per pixel rendered while the guide learned (learn=N; all guided ones without).
    int learningSpp = 0;
    // Wall seconds of the guide's updates between passes (GuidingField::endPass).
    double guideEndPassSeconds = 0.0;
    // The auto trial of a guided render (GuideSettings::autoSpp): whether it ran, its verdict,
    // the spp at which guiding stopped (= spp if it never did), and the two passes' costs
    // (relative variance per sample, times CPU seconds per sample with a time budget).
    struct AutoTrial {
        bool ran = false;
        bool keptGuiding = true;
        int guidedSpp = 0;
        double guidedCost = 0.0, plainCost = 0.0;
        int plainSpp = 0;  // the plain pass's spp (its first part's, if guiding won after it)
    } autoTrial;
    int threads = 1;              // threads per process (RenderOptions::nThreads resolved)
    int ranks = 1;                // processes that rendered (RenderOptions::ranks)
    int passes = 0;
    uint64_t bytesExchanged = 0;  // this rank's payload in the ranks' collectives
    double secondsExchanging = 0.0;  // ... and its wall time in them (during the render)
    double secondsWaiting = 0.0;     // ... of which waiting for the slowest rank
};

RenderResult render(const Scene& scene, const RenderOptions& options);

}  // namespace rlpbrt
