// The guide's training from one path: the integrator reports what happens at each vertex
// (surface arrival and scattering, medium scattering, free flights, escape) and the recorder
// turns it into the training records of the configured scheme, handed to the field's slot:
// - the path's returns (target=path, the default): each guided surface vertex learns the
//   radiance its sampled direction brought back, recorded when the path ends;
// - Eq. 1's bootstrap (target=sum|sample, and at medium vertices always): the previous guided
//   vertex's target is Le + the learned light scattered at the next vertex, carried through
//   delta vertices (a pending record);
// - the selection samples of mix=learn, recorded when the path ends.
// The only place of the training bookkeeping; the integrator decides nothing about it.
#pragma once

#include "guiding/guiding.h"
#include "render/bsdf.h"
#include "render/direction_sample.h"
#include "render/interaction.h"
#include "render/spectrum.h"

namespace rlpbrt {

struct GuideSettings;

class PathRecorder {
public:
    // Records into `slot` of guide.field if it learns (GuideSettings::learn), else nothing.
    PathRecorder(const GuideSettings& guide, int slot);

    bool learning() const { return learn_; }
    // Whether surface vertices need a region for Eq. 1's bootstrap even where the path
    // samples no guided direction (its last direction).
    bool bootstraps() const { return bootstrap_; }
    // A pending Eq. 1 record waits for the next vertex's light (the path must reach it).
    bool awaitsTarget() const { return pending_.active(); }

    // A free flight through a medium weighted the throughput by `weight`.
    void flight(const Spectrum& weight) {
        if (pending_.active()) pending_.weight *= luminance(weight);
    }
    // A medium vertex at p where the field has no region: ask it to model the place.
    void requestMedium(const Vec3& p) {
        if (learn_) slot_.requestMedium(p);
    }
    // A medium vertex with the field's `guide` there (invalid: none) sampled ds: completes
    // the pending record with the one-sample estimate Q(p, w') phase / pdf and starts its own.
    void mediumScattered(const guiding::VertexGuide& guide, const DirectionSample& ds);
    // The path left the scene, where the environment's luminance is envLum.
    void escaped(float envLum) {
        if (learn_) flush(envLum);
    }
    // The path passed a surface without material that emits `emitted` (luminance).
    void passedThrough(float emitted) {
        if (pending_.active()) pending_.target += pending_.weight * emitted;
    }
    // The path reached surface vertex si (BSDF bsdf, the field's guide there, invalid where
    // it has none),
    // which emits `emitted` toward it. Completes the pending Eq. 1 record with the light
    // scattered at si; true if that waits for the direction sampled at si (surfaceSampled).
    bool surfaceReached(const SurfaceInteraction& si, const BSDF& bsdf,
                        const guiding::VertexGuide& guide, bool canGuide, int lobes,
                        float emitted, bool lastVertex) {
        return learn_ && pending_.active() &&
               completePending(si, bsdf, guide, canGuide, lobes, emitted, lastVertex);
    }
    // The direction ds was sampled at si; `deferred` is surfaceReached's answer.
    void surfaceSampled(bool deferred, const SurfaceInteraction& si,
                        const guiding::VertexGuide& guide, const DirectionSample& ds,
                        float emitted) {
        if (deferred) completeDeferred(si, guide, ds, emitted);
    }
    // Whether the path records selection samples (mix=learn, until it splits), at vertices
    // whose region still learns (GuidingField::learns).
    bool recordsSelection() const { return learnSelection_ && !split_; }
    // Before the throughput takes ds's weight: a selection sample of a guided vertex at
    // sampleGuide (mix=learn), with the path's L and throughput so far.
    void selectionVertex(const guiding::VertexGuide& sampleGuide, const DirectionSample& ds,
                         const Spectrum& L, const Spectrum& beta) {
        if (!recordsSelection() || !sampleGuide.valid() || numSel_ >= kMaxSelectionVertices ||
            !sampleGuide.learns())
            return;
        sel_.v[numSel_++] = SelectionVertex{
            sampleGuide, guiding::SelectionSample{0.f, ds.pdf, ds.pGuide, ds.pOther, ds.scale},
            luminance(L), luminance(beta)};
    }
    // After the throughput took the direction's weight (beta): the vertex's return (it learns
    // the light gathered from here on), and the pending record's next step (a new one at a
    // guided vertex with Eq. 1's targets, carried through a delta vertex, else dropped).
    // learnsReturn: whether the vertex's guide learns the return (where its region still
    // learns: GuidingField::learns).
    void surfaceScattered(const guiding::VertexGuide& guide, bool learnsReturn, bool canGuide,
                          const DirectionSample& ds, const Spectrum& weight, const Spectrum& L,
                          const Spectrum& beta) {
        addReturn(guide, learnsReturn, ds.bin, ds.wi, L, beta);
        if (!learn_ || split_) return;
        if (bootstrap_ && guide.valid() && !ds.transmission && guide.learns()) {
            pending_ = PendingRecord();
            pending_.guide = guide;
            pending_.w = ds.wi;
            pending_.bin = ds.bin;
        } else if (pending_.active() && !guide.valid() && !canGuide) {
            pending_.weight *= luminance(weight);  // through a delta vertex
        } else {
            pending_ = PendingRecord();
        }
    }
    // The path jumped through a BSSRDF from its entry to an exit point: the pending Eq. 1
    // record is dropped (no one direction connects its vertex to what follows the exit; the
    // exit's light is a subsurface transport, not a radiance along the recorded direction).
    // Returns stay valid: the light gathered after a vertex is still what its direction
    // brought back.
    void subsurfaceScattered() { pending_ = PendingRecord(); }
    // The path arrived at surface point p (after the next-event estimation there, or at the
    // depth limit, with L the radiance so far): for a field that learns spots, what the last
    // return vertex's direction found here (GuidingField::recordSpot).
    void arrived(const Vec3& p, const Spectrum& L) {
        if (spotPending_) spotReached(p, L);
    }
    // The path splits (GuideSettings::splitMax) into branches traced one after another, each
    // a segment. The returns go on: a vertex learns the light gathered after it within its
    // own segment (segmentEnded), the vertices before the split the light of all branches
    // (each branch carries its share 1 / r of the throughput). Eq. 1's pending records and
    // the selection samples stop. Returns the branches' base: the number of return vertices
    // before the split, which wait for every branch.
    int split() {
        split_ = true;
        spotPending_ = false;
        pending_ = PendingRecord();
        return numRet_;
    }
    // A branch of a split path starts: its direction w (bin) was sampled at the vertex of
    // `guide`, the path's light so far is L and the branch's throughput beta (with its share
    // 1 / r); like surfaceScattered's return vertex.
    void branchStarted(const guiding::VertexGuide& guide, bool learnsReturn, int bin,
                       const Vec3& w, const Spectrum& L, const Spectrum& beta) {
        addReturn(guide, learnsReturn, bin, w, L, beta);
    }
    // A segment of a split path ended with radiance L (the light of every segment so far):
    // the return vertices from `base` on (the ended segment's) learn now.
    void segmentEnded(const Spectrum& L, int base) {
        spotPending_ = false;
        recordReturns(L, base);
    }
    // Next-event estimation at the vertex of `guide` sent its shadow ray to a light of
    // `group` (LightGroups) and found `value` (GuidingField::recordChoice; 0 where hidden).
    void lightChosen(const guiding::VertexGuide& guide, int group, float value) {
        if (learn_) slot_.recordChoice(guide, group, value);
    }
    // The path ended with radiance L: records the returns and the selection samples.
    void finish(const Spectrum& L);

private:
    // The pending training record of the last guided vertex: its region and direction, and
    // the target collected so far through delta vertices (weight = product of their
    // f cos / pdf).
    struct PendingRecord {
        guiding::VertexGuide guide;
        Vec3 w{0.f};
        int bin = -1;  // the guide's bin of w, or -1
        float target = 0.f;
        float weight = 1.f;
        bool active() const { return guide.valid(); }
    };
    // A guided vertex trained with the path's return (target=path): the radiance the path
    // gathered after it, over the throughput after its direction sample, is the radiance that
    // direction brought to it, as the estimator counts it: emission found by the direction
    // carries its MIS weight against the vertex's next-event estimation.
    struct ReturnVertex {
        guiding::VertexGuide guide;
        int bin;  // the guide's bin of w, or -1
        Vec3 w;
        Spectrum L;     // L when the direction was sampled (after the vertex's NEE)
        Spectrum beta;  // throughput after the direction's weight
    };
    static constexpr int kMaxReturnVertices = 32;
    // A guided vertex whose direction sample feeds the selection learning (mix=learn): the
    // radiance the path gathers after it, over the throughput at it, is the sample's
    // contribution F = f cos Li / pdf, so its integrand is F * pdf (known when the path ends).
    struct SelectionVertex {
        guiding::VertexGuide guide;
        guiding::SelectionSample s;
        float lumL;     // luminance of L when the direction was sampled
        float lumBeta;  // luminance of the throughput at the vertex
    };
    static constexpr int kMaxSelectionVertices = 16;
    // A path's return and selection vertices, left uninitialised until used (their guides
    // have default values): initialising the arrays cost every path 48 (selections) to 170
    // (returns) instructions.
    union ReturnVertices {
        ReturnVertices() {}
        ReturnVertex v[kMaxReturnVertices];
    };
    union SelectionVertices {
        SelectionVertices() {}
        SelectionVertex v[kMaxSelectionVertices];
    };

    // A return vertex (surfaceScattered, branchStarted) where the vertex learns its return and
    // its region still learns (GuidingField::learns); a spot record waits for it.
    void addReturn(const guiding::VertexGuide& guide, bool learnsReturn, int bin, const Vec3& w,
                   const Spectrum& L, const Spectrum& beta) {
        spotPending_ = false;
        if (returns_ && learnsReturn && guide.valid() && numRet_ < kMaxReturnVertices &&
            guide.learns()) {
            ret_.v[numRet_++] = ReturnVertex{guide, bin, w, L, beta};
            spotPending_ = spots_;
        }
    }
    // Completes the pending record with `addTarget` (weighted) and records it.
    void flush(float addTarget) {
        if (!pending_.active()) return;
        pending_.target += pending_.weight * addTarget;
        slot_.record(pending_.guide, pending_.w, pending_.target, pending_.bin);
        pending_ = PendingRecord();
    }
    bool completePending(const SurfaceInteraction& si, const BSDF& bsdf,
                         const guiding::VertexGuide& guide, bool canGuide, int lobes,
                         float emitted, bool lastVertex);
    void completeDeferred(const SurfaceInteraction& si, const guiding::VertexGuide& guide,
                          const DirectionSample& ds, float emitted);
    // The bootstrap term of Eq. 1 at a vertex with guiding data (luminance); -1 if it is to
    // be estimated with the direction sampled there.
    float scatteredTarget(const SurfaceInteraction& si, const BSDF& bsdf,
                          const guiding::VertexGuide& guide, const Vec3& woY) const;

    void spotReached(const Vec3& p, const Spectrum& L);
    // Records the returns of the vertices from `base` on with the path's light L and drops
    // them.
    void recordReturns(const Spectrum& L, int base);

    guiding::TrainingSlot slot_;
    bool learn_, learnSelection_, bootstrap_, returns_, sampledTarget_;
    bool spots_ = false;        // the field learns spots (returns only)
    bool spotPending_ = false;  // the last return vertex waits for its next vertex
    bool split_ = false;        // the path has split: no more training
    PendingRecord pending_;
    ReturnVertices ret_;
    int numRet_ = 0;
    SelectionVertices sel_;
    int numSel_ = 0;
};

}  // namespace rlpbrt
