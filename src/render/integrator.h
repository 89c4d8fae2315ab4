// The one path-tracing integrator (pbrt-v3 `path` semantics: maxdepth, Russian roulette after
// bounce 3, next-event estimation with power-heuristic MIS). The direction-sampling step is a
// seam (sampleDirection / mixturePdf) where a guiding backend plugs in.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <memory>

#include "guiding/guiding.h"
#include "render/direction_sample.h"
#include "render/guide_clock.h"
#include "render/light_sampler.h"
#include "render/patches.h"
#include "render/ray.h"
#include "render/scene.h"

namespace rlpbrt {

// Per-thread counters, summed after rendering.
struct PathStats {
    uint64_t paths = 0;
    uint64_t rays = 0;               // closest-hit and shadow rays
    uint64_t vertices = 0;           // surface scattering vertices (path length sum)
    uint64_t zeroRadiancePaths = 0;  // camera paths that carried no light
    uint64_t nonFinite = 0;          // samples dropped because they were NaN/Inf
    // Guiding's cost (render/guide_clock.h): vertices whose region had a guide, and on the
    // timed paths (one in kGuideClockEvery) those vertices and the time spent in the guide.
    uint64_t guidedVertices = 0;
    uint64_t timedGuidedVertices = 0;
    GuideClockSums guideClock;
    // Every counter, in one fixed order (sums over threads and ranks, the resume file).
    static constexpr size_t kCounters = 9;
    std::array<uint64_t*, kCounters> counters() { return countersOf(*this); }
    std::array<const uint64_t*, kCounters> counters() const { return countersOf(*this); }
    void add(const PathStats& o) {
        const auto mine = counters();
        const auto theirs = o.counters();
        for (size_t i = 0; i < kCounters; ++i) *mine[i] += *theirs[i];
    }

private:
    template <class Self>
    static std::array<decltype(&std::declval<Self&>().paths), kCounters> countersOf(Self& s) {
        return {&s.paths,          &s.rays,           &s.vertices,
                &s.zeroRadiancePaths, &s.nonFinite,   &s.guidedVertices,
                &s.timedGuidedVertices, &s.guideClock.nanos, &s.guideClock.calls};
    }
};

// How the integrator uses a guiding field (none when field is null).
struct GuideSettings {
    guiding::GuidingField* field = nullptr;
    // The surface patches the field asked for (GuidingField::patchSize), whose keys the
    // integrator passes to lookupPatch; null if it wants none or the scene has no triangles.
    std::shared_ptr<const SurfacePatches> patches;
    // Probability of sampling a direction from the guide at a vertex that has guiding data
    // (one-sample MIS mixture with BSDF sampling): 0 = BSDF only, 1 = the paper's pure policy.
    float mix = 0.5f;
    // mix=learn: the probability is learned per region (GuidingField::selection, from the
    // selection samples the integrator records); `mix` stays the value for regions without a
    // learned one.
    bool learnMix = false;
    bool learn = true;  // record training targets during rendering
    // lights=learned (the field learns choices): next-event estimation picks lights with the
    // region's learned choice mixed in (PathIntegrator::lightPmf).
    bool learnLights = false;
    // learn=N (render loop): the guide learns during the first N samples per pixel only; the
    // passes after them sample from the guide as it is then, without recording targets or
    // updating it between passes (no learning work; the image stays consistent, as with any
    // fixed guide). -1 (learn=all, the default): learn in every pass, as the paper does.
    // learn=0 with --guide-load renders with a guide trained before. Not the default: it
    // saves a few percent of the time and loses more per sample (docs/GUIDING.md, `learn`).
    int learnSpp = -1;
    // With Eq. 1's targets (target=sum|sample, pathTarget false): how the sum of Eq. 1 is
    // evaluated at a non-Lambertian vertex y: over all strata
    // (n BSDF evaluations, the paper's form) or with the one direction sampled at y
    // (Q(y, w') f cos / pdf: an unbiased one-sample estimate of the same sum, no extra
    // evaluations). Lambertian vertices always use the exact sum (learned irradiance).
    bool sampledTarget = true;
    // target=path: train each guided vertex on the radiance the rest of its path actually
    // brought back through the sampled direction, as the estimator weighs it (a Monte Carlo
    // return, as practical path guiding trains; emission hit by the direction carries its MIS
    // weight against next-event estimation), instead of Eq. 1's bootstrap from Q at the next
    // vertex. The guide then learns what direction sampling has to find, not light that
    // next-event estimation already delivers (docs/GUIDING.md, `target`).
    bool pathTarget = true;
    // Where a guided render's passes take their samples (samples=sequence|independent):
    // from the one low-discrepancy sequence per pixel that plain rendering uses (false, the
    // default), or from an independently randomized set per pass (true). The sequence
    // keeps the stratification across passes (docs/GUIDING.md, `samples`). Its price is a
    // correlation between the policy (learned from earlier passes) and the samples that
    // follow them in the same pixel: a bias that vanishes as the policy converges
    // (docs/STABILITY.md). Independent sets are exactly unbiased.
    bool independentPasses = false;
    // auto=N (render loop): after about N samples per pixel (or a quarter of a time budget),
    // render a plain pass as large as the guided pass before it (in two parts: render.cpp),
    // compare the two passes' costs (relative variance per sample, render/efficiency.h, times
    // CPU seconds per sample with a time budget: a render of fixed spp stays a function of its
    // seed) and render the rest without guiding (no lookups, no learning) if the guided cost
    // exceeds the plain one; where guiding stays, the plain pass's samples weigh as a guided
    // sample's variance against theirs. 0 = always guide, the default: with auto=64 two 30-s
    // studies gained on metal-spheres and buddha-fractal and lost 3-15% on most other scenes
    // (docs/GUIDING.md, `auto`).
    int autoSpp = 0;
    // rr=adjoint: from the second surface vertex on, guided surface vertices play Russian
    // roulette on the path's expected remaining contribution, throughput x the learned Q of
    // the sampled direction, against the pixel's estimate from earlier passes (Vorba and
    // Krivanek 2016, without splitting): below rouletteWindow of it the path survives with
    // the ratio (at least kMinSurvival). The throughput alone is low exactly where the guide
    // chose a bright direction. Untrained regions and pixels without an estimate (the render
    // loop gives none before 8 samples per pixel) keep pbrt-v3's roulette (after bounce 3).
    // rr=pbrt: pbrt-v3's everywhere.
    // Per sample it costs some variance and saves more time; starting at the first vertex
    // lost per time (docs/GUIDING.md, `rr`; docs/BENCHMARKS_HISTORY.md, session 9).
    // Like the policy, the estimate comes from earlier samples of the same pixels
    // (GuideSettings::independentPasses).
    bool adjointRoulette = true;
    // rr-window: the weight window's lower edge as a share of the pixel estimate.
    float rouletteWindow = 0.1f;
    // split=N (1 = off): a guided surface vertex whose expected contribution (throughput x
    // the diffuse lobes' f(wo, n) x the learned irradiance) exceeds splitWindow x the pixel's
    // estimate continues as up to N paths, each with 1 / r of the throughput (r the ratio,
    // rounded stochastically): the splitting half of Vorba and Krivanek 2016. Each branch
    // trains on its own light (PathRecorder::split). Like the adjoint roulette it waits for
    // the pixel estimates. The default 16 with window 1 (session 36; 8 with window 3 before):
    // at 30 s against plain path tracing breakfast 0.10 (0.15 with 8 / 3), cornell-box 0.74
    // (0.79), caustic-glass 0.75 (0.86), conference-room 0.85 (0.96), killeroo 1.04 (0.96)
    // (docs/GUIDING.md, `split`).
    int splitMax = 16;
    float splitWindow = 1.f;
};

class Rng;
class PathRecorder;

class PathIntegrator {
public:
    PathIntegrator(const Scene& scene, const GuideSettings& guide = {});
    // Radiance arriving along a camera ray; consumes dimensions of `sampler`. `slot` is the
    // work item (film tile) index, used to record guiding targets deterministically.
    // pixelEstimate: the luminance of the ray's pixel estimated so far (0 = unknown), for
    // GuideSettings::adjointRoulette.
    Spectrum Li(const Ray& ray, Sampler& sampler, PathStats& stats, int slot = 0,
                float pixelEstimate = 0.f) const;
    // Whether Li uses a pixel estimate (the render loop then provides one).
    bool wantsPixelEstimate() const { return guide_.field && guide_.adjointRoulette; }

private:
    // The guide at a vertex mixed with its BSDF or phase function: the field's guide there
    // (invalid: BSDF or phase function only) and the BSDF's diffuse share (1 in a medium).
    // guideMix() finds the probability of a guided sample at its first use (NEE's MIS weight
    // or the direction sample) and keeps it, with the region's confidence, for the other uses
    // (and the roulette): the confidence is read late, so that the lookup's prefetch of its
    // cache line has landed, and once. Sampling and pdf evaluation thus agree to the bit.
    struct GuideMixture {
        guiding::VertexGuide guide;
        float share = 0.f;
        float mix = -1.f;         // the guide probability: selection x scale, once found
        float confidence = 0.f;   // the region's
        float scale = 0.f;        // confidence x share
        // Whether the path records this vertex's selection sample (mix=learn, while the
        // region learns): its guide pdf is then wanted even where the guide probability is 0.
        bool recordsSelection = false;
        GuideClockSums* clock = nullptr;  // the path's guide clock (render/guide_clock.h), if timed
    };
    float guideMix(GuideMixture& g) const {
        if (g.mix < 0.f) {
            g.mix = 0.f;
            if (g.guide.valid()) {
                g.confidence = g.guide.confidence();
                g.scale = g.confidence * g.share;
                if (g.guide.guides()) g.mix = guideSelection(g.guide) * g.scale;
            }
        }
        return g.mix;
    }
    // The pdf of a vertex's direction sampling for wi: the guide mixed with the BSDF or phase
    // function, whose pdf of wi is otherPdf (otherPdf alone without a guided share).
    float mixturePdf(GuideMixture& g, const Vec3& wi, float otherPdf) const {
        if (!g.guide.valid()) return otherPdf;
        const float mix = guideMix(g);
        if (!(mix > 0.f)) return otherPdf;
        GuideTimer timer(g.clock);
        return mix * g.guide.pdf(wi) + (1.f - mix) * otherPdf;
    }
    // PathStats' count of guided vertices (and of those on timed paths).
    static void countGuided(const guiding::VertexGuide& g, const GuideClockSums* clock,
                            PathStats& stats) {
        if (!g.valid()) return;
        ++stats.guidedVertices;
        if (clock) ++stats.timedGuidedVertices;
    }
    // Whether a direction drawn at g needs the guide's pdf (a valid guide only): where it may
    // be sampled, or where a selection sample rates the candidates (mix=learn, while the
    // region learns).
    bool needsGuidePdf(GuideMixture& g) const {
        return g.guide.valid() && (guideMix(g) > 0.f || (g.recordsSelection && g.guide.learns()));
    }
    float guideConfidence(GuideMixture& g) const {
        guideMix(g);
        return g.confidence;
    }
    // The direction at a surface vertex from the sample (uc, u): uc picks a lobe's own choice
    // or the guide's part, u the direction (u.x first the guide or the BSDF).
    DirectionSample sampleDirection(const SurfaceInteraction& si, const BSDF& bsdf,
                                    GuideMixture& guide, float uc, Vec2 u) const;
    // The selection probability of a vertex's guide: learned (mix=learn, where the field has
    // one) or the mix setting.
    float guideSelection(const guiding::VertexGuide& guide) const {
        if (guide_.learnMix) {
            const float s = guide.selection();
            if (s >= 0.f) return s;
        }
        return guide_.mix;
    }
    // Media (scene_.hasMedia() only): the medium a path is in and its tracking generator.
    struct PathMedium {
        int medium = -1;
        Rng* rng = nullptr;
    };
    // choice: the vertex's learned light choice (GuidingField::choice; none: the scene's
    // light sampler alone); with rec, what the shadow ray found is recorded for `region`.
    // One 2D sample: u.x chooses the light and, rescaled to its share, places the point on
    // it with u.y, so each light's points keep the sampler's 2D stratification (a separate
    // 1D choice gave each light an unstratified share: with the Sobol' sampler 4-10% more
    // error per sample on caustic-glass, conference-room and veach-mis; session 31). A light
    // of probability p keeps 24 + log2(p) bits of u.x.
    Spectrum sampleLight(const SurfaceInteraction& si, const BSDF& bsdf, GuideMixture& guide,
                         Sampler& sampler, PathStats& stats, const PathMedium* media = nullptr,
                         const guiding::GuidingField::Choice& choice = {},
                         PathRecorder* rec = nullptr,
                         const guiding::VertexGuide* region = nullptr) const;
    // The probability that next-event estimation at p picks `light`: the scene's light
    // sampler's, mixed with the learned choice where there is one (choiceShare of it).
    float lightPmf(const Vec3& p, const guiding::GuidingField::Choice& choice, int light) const {
        return lightChoice(choice).pmf(p, light);
    }
    MixedLightChoice lightChoice(const guiding::GuidingField::Choice& c) const {
        return MixedLightChoice{*lights_, c.cdf, scene_.lightGroups, choiceShare(c)};
    }
    // The learned light choice's share of the selection: up to kChoiceShare as the region's
    // records grow (its weight); the rest stays with the scene's light sampler, so a light
    // the region has not seen lit keeps its chance (and the estimate stays unbiased).
    static constexpr float kChoiceShare = 0.8f;
    static float choiceShare(const guiding::GuidingField::Choice& c) {
        return kChoiceShare * c.weight;
    }
    // Next-event estimation at a medium vertex (phase function pbrt-v3 HG with g), MIS
    // against the vertex's direction sampling (phase, or the guide mixed with it at a region).
    Spectrum sampleLightMedium(const Vec3& p, const Vec3& wo, float g, GuideMixture& guide,
                               const PathMedium& pm, Sampler& sampler, PathStats& stats) const;
    // The direction-sampling seam at a medium vertex: the phase function, or at a region the
    // guide with probability guideMix, mixed with it (f = the phase value; one 1D dimension
    // more where the field guides media: `guided`); mixturePdf gives that strategy's pdf.
    DirectionSample sampleMediumDirection(const Vec3& wo, float g, GuideMixture& guide,
                                          bool guided, Sampler& sampler) const;
    // Transmittance of the segment o + t d, t in (0, tMax), starting in `medium`: through
    // medium boundaries (interface-only surfaces), zero at any other surface.
    Spectrum transmittance(Vec3 o, const Vec3& d, float tMax, int medium, Rng& rng,
                           PathStats& stats) const;
    // The state a path carries from vertex to vertex.
    struct PathState {
        Spectrum L{0.f}, beta{1.f};
        Ray ray;
        bool specularBounce = false;
        float dirPdf = 0.f, etaScale = 1.f;
        LightSampleContext prev;
        // The learned light choice (GuidingField::choice) that the previous vertex's
        // next-event estimation used, for the MIS weight of emission found from there; none:
        // the scene's light sampler alone.
        guiding::GuidingField::Choice prevChoice;
        PathMedium pm;
        GuideClockSums* clock = nullptr;  // the guide clock of a timed path (render/guide_clock.h)
    };
    // The medium step of Li (scenes with media, a path in a medium): the free flight to the
    // closest hit si (found: there is one), and at a scattering event the medium vertex (NEE,
    // direction sampling, roulette). Surface: the flight reached the surface (or escaped);
    // Scattered: s.ray is the next ray; End: the path ends.
    enum class Step { Surface, Scattered, End };
    // Continues s from surface vertex si along the sampled direction ds (its throughput
    // weight is the caller's): the next ray, and what MIS, the roulette and media remember
    // of the vertex (the medium only if `media`). The path and its split branches share it.
    void takeDirection(PathState& s, const SurfaceInteraction& si, const BSDF& bsdf,
                       const DirectionSample& ds, bool media) const;
    Step mediumStep(PathState& s, bool found, const SurfaceInteraction& si, int bounces,
                    Sampler& sampler, PathStats& stats, PathRecorder& rec) const;
    // The subsurface step of Li (pbrt-v3's BSSRDF sampling), after the BSDF of a material with
    // a BSSRDF sampled a transmission at si: a probe segment (bssrdf.h) is intersected with the
    // surfaces of si's material, one hit is the exit point; the throughput takes Sp / pdf,
    // next-event estimation runs there with the exit lobe, and s.ray leaves the exit in a
    // direction sampled from that lobe. Scattered: s.ray is the next ray; End: the path ends.
    Step subsurfaceStep(PathState& s, const SurfaceInteraction& si, const BSDF& bsdf,
                        Sampler& sampler, PathStats& stats, PathRecorder& rec) const;

    const Scene& scene_;
    std::unique_ptr<LightSampler> lights_;
    GuideSettings guide_;
    int maxDepth_;
    float rrThreshold_;
    float originScale_ = 1.f;  // smallScale of offsetRayOrigin: min(1, scene size)
};

// Builds the guiding field of --guide/--guide-param for a scene (null field for "none") and
// the integrator's guide settings ("mix" is read here; the rest goes to the backend).
// False with a message in *error for bad configurations.
bool setupGuiding(const Scene& scene, const guiding::GuideConfig& config,
                  std::unique_ptr<guiding::GuidingField>* field, GuideSettings* settings,
                  std::string* error);

// Moves p off a surface with unit normal n (oriented towards the side the ray leaves on),
// by 256 float ULPs of each coordinate (Wachter and Binder 2019); coordinates within
// smallScale / 32 of zero, where ULPs vanish, move by smallScale / 65536 instead. The
// integrator passes min(1, scene size) so that offsets stay relative in tiny scenes
// (a 1e-4-sized scene would otherwise be offset by 15% of its size).
Vec3 offsetRayOrigin(const Vec3& p, const Vec3& n, float smallScale = 1.f);

}  // namespace rlpbrt
