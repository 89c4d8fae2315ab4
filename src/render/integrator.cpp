#include "render/integrator.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "guiding/options.h"
#include "render/media.h"
#include "render/path_recorder.h"
#include "render/roulette.h"
#include "render/sampling.h"

namespace rlpbrt {

Vec3 offsetRayOrigin(const Vec3& p, const Vec3& n, float smallScale) {
    const float kOrigin = smallScale / 32.f, kFloatScale = smallScale / 65536.f;
    constexpr float kIntScale = 256.f;
    Vec3 out;
    for (int i = 0; i < 3; ++i) {
        int32_t offset = int32_t(kIntScale * n[i]);
        int32_t bits;
        std::memcpy(&bits, &p[i], sizeof(float));
        bits += (p[i] < 0.f) ? -offset : offset;
        float moved;
        std::memcpy(&moved, &bits, sizeof(float));
        out[i] = std::abs(p[i]) < kOrigin ? p[i] + kFloatScale * n[i] : moved;
    }
    return out;
}

PathIntegrator::PathIntegrator(const Scene& scene, const GuideSettings& guide)
    : scene_(scene),
      lights_(createLightSampler(scene.integrator.lightSampleStrategy, scene.lights,
                                 scene.boundsMin(), scene.boundsMax(), nullptr,
                                 scene.hasMedia())),
      guide_(guide), maxDepth_(scene.integrator.maxDepth),
      rrThreshold_(scene.integrator.rrThreshold) {
    guide_.mix = clamp(guide_.mix, 0.f, 1.f);
    const Vec3 extent = scene.boundsMax() - scene.boundsMin();
    const float size = std::max({extent.x, extent.y, extent.z});
    if (std::isfinite(size) && size > 0.f) originScale_ = std::min(1.f, size);
    if (guide_.mix == 0.f && !guide_.learn) guide_.field = nullptr;
}

namespace {
// The message of a bad value for one of the integrator's guide options; returns false.
bool badOption(const std::string& key, const std::string& value, std::string* error) {
    const guiding::GuideOption* o = guiding::findGuideOption(key);
    *error = key + " must be " + (o ? o->expected : "?") + ", got \"" + value + "\"";
    return false;
}
// A whole-string number (strtof syntax); false if the text is anything else.
bool parseFloat(const std::string& text, float* out) {
    char* end = nullptr;
    *out = std::strtof(text.c_str(), &end);
    return end != text.c_str() && *end == '\0';
}
// A whole-string sample count in [0, 2^24] (strtol syntax); false if the text is anything else.
bool parseSampleCount(const std::string& text, int* out) {
    char* end = nullptr;
    const long n = std::strtol(text.c_str(), &end, 10);
    if (end == text.c_str() || *end != '\0' || n < 0 || n > (1L << 24)) return false;
    *out = int(n);
    return true;
}
}  // namespace

bool setupGuiding(const Scene& scene, const guiding::GuideConfig& config,
                  std::unique_ptr<guiding::GuidingField>* field, GuideSettings* settings,
                  std::string* error) {
    *settings = GuideSettings();
    field->reset();
    auto it = config.params.find("mix");
    if (it != config.params.end() && it->second == "learn") {
        settings->learnMix = true;
    } else if (it != config.params.end()) {
        float mix = 0.f;
        if (!parseFloat(it->second, &mix) || !(mix >= 0.f && mix <= 1.f)) {
            return badOption("mix", it->second, error);
        }
        settings->mix = mix;
    }
    auto target = config.params.find("target");
    if (target != config.params.end()) {
        if (target->second != "sum" && target->second != "sample" && target->second != "path") {
            return badOption("target", target->second, error);
        }
        settings->sampledTarget = target->second != "sum";
        settings->pathTarget = target->second == "path";
    }
    auto samples = config.params.find("samples");
    if (samples != config.params.end()) {
        if (samples->second != "sequence" && samples->second != "independent") {
            return badOption("samples", samples->second, error);
        }
        settings->independentPasses = samples->second == "independent";
    }
    auto rr = config.params.find("rr");
    if (rr != config.params.end()) {
        if (rr->second != "adjoint" && rr->second != "pbrt") {
            return badOption("rr", rr->second, error);
        }
        settings->adjointRoulette = rr->second == "adjoint";
    }
    auto window = config.params.find("rr-window");
    if (window != config.params.end()) {
        float w = 0.f;
        if (!parseFloat(window->second, &w) || !(w > 0.f && w <= 1.f)) {
            return badOption("rr-window", window->second, error);
        }
        settings->rouletteWindow = w;
    }
    auto split = config.params.find("split");
    if (split != config.params.end()) {
        float v = 0.f;
        if (!parseFloat(split->second, &v) || !(v >= 1.f && v <= 64.f) || v != std::floor(v))
            return badOption("split", split->second, error);
        settings->splitMax = int(v);
    }
    auto splitWindow = config.params.find("split-window");
    if (splitWindow != config.params.end()) {
        float v = 0.f;
        if (!parseFloat(splitWindow->second, &v) || !(v > 0.f && v <= 1e6f))
            return badOption("split-window", splitWindow->second, error);
        settings->splitWindow = v;
    }
    auto lightsParam = config.params.find("lights");
    const bool learnLights = lightsParam == config.params.end() || lightsParam->second == "learned";
    if (lightsParam != config.params.end() && lightsParam->second != "learned" &&
        lightsParam->second != "scene")
        return badOption("lights", lightsParam->second, error);
    auto learn = config.params.find("learn");
    if (learn != config.params.end() && learn->second != "all" &&
        !parseSampleCount(learn->second, &settings->learnSpp)) {
        return badOption("learn", learn->second, error);
    }
    auto autoSpp = config.params.find("auto");
    if (autoSpp != config.params.end() && !parseSampleCount(autoSpp->second, &settings->autoSpp)) {
        return badOption("auto", autoSpp->second, error);
    }
    if (config.backend == "none") return true;
    guiding::SceneInfo info;
    info.boundsMin = scene.boundsMin();
    info.boundsMax = scene.boundsMax();
    info.totalArea = scene.totalSurfaceArea();
    Vec3 mediaMin, mediaMax;
    if (scene.mediaBounds(&mediaMin, &mediaMax)) info.mediaMin = mediaMin, info.mediaMax = mediaMax;
    const Scene* sc = &scene;
    info.samplePoint = [sc](const glm::vec3& u, glm::vec3* p, glm::vec3* n) {
        return sc->sampleSurface(u, p, n);
    };
    *field = guiding::createGuidingField(config, info, error);
    if (!*field) return false;
    settings->field = field->get();
    // Learned light choices for scenes of a few emitters (each region keeps a mean per
    // emitter: render/light_sampler.h, LightGroups).
    const int emitters = scene.lightGroups.count();
    settings->learnLights = learnLights && emitters >= 2 &&
                            emitters <= guiding::GuidingField::kMaxChoices &&
                            (*field)->enableChoices(emitters);
    const float patchSize = (*field)->patchSize();
    if (patchSize > 0.f) {
        // At most 2^24 patches (64 MiB of memo at most, in pages touched only where paths
        // go); a scene with more triangles than that gets none (the cell lookup serves it).
        auto patches = std::make_shared<const SurfacePatches>(scene.worldPrimitives(), patchSize,
                                                              uint64_t(1) << 24);
        if (patches->count() > 0) {
            settings->patches = patches;
            (*field)->setPatches(patches->count(),
                                 [patches](uint32_t i, glm::vec3* p, glm::vec3* n) {
                                     return patches->centre(i, p, n);
                                 });
        }
    }
    return true;
}

namespace {
// Offsets a ray origin to the side of the surface that direction w leaves on.
Vec3 spawnOrigin(const SurfaceInteraction& si, const Vec3& w, float smallScale) {
    return offsetRayOrigin(si.p, glm::dot(w, si.ng) > 0.f ? si.ng : -si.ng, smallScale);
}

// The share of a guidable BSDF's lobes that are diffuse: the guide's table (Q cos, no BSDF
// product) suits diffuse lobes; a glossy lobe is narrower than a stratum and is better
// sampled by the BSDF. The integrator scales its guide probability by this share.
float diffuseShare(const BSDF::LobeCounts& lobes) {
    return lobes.all > 0 ? float(lobes.diffuse) / float(lobes.all) : 0.f;
}

// A BSDF the guide may drive: no delta lobes (delta BSDFs bypass the guide; a lobe counts
// as smooth when its flags are all among All & ~Specular, so "specular lobes" are the lobes
// not counted as smooth).
bool guidable(const BSDF::LobeCounts& lobes) { return lobes.all > 0 && lobes.smooth == lobes.all; }

// a + t wrapped into [0, 1) (a in [0, 1), t in [0, 1)): a uniform a stays uniform.
float shiftUnit(float a, float t) {
    const float v = a + t;
    return std::min(v < 1.f ? v : v - 1.f, OneMinusEpsilon);
}
float fractional(float x) { return x - std::floor(x); }
// Steps of the branches' shifts (splitting): 1 / golden ratio, 1 / plastic number.
constexpr float kGolden = 0.618033988749895f;
constexpr float kPlastic = 0.754877666246693f;

// Adjoint-driven roulette (GuideSettings::adjointRoulette): the first bounce it may end a
// path at, the least survival probability (bounds a survivor's weight), and the confidence a
// region needs before its Q is trusted.
constexpr int kRouletteFirstBounce = 1;
constexpr float kMinSurvival = 0.25f;
constexpr float kRouletteConfidence = 0.5f;

}  // namespace

DirectionSample PathIntegrator::sampleDirection(const SurfaceInteraction& si, const BSDF& bsdf,
                                                GuideMixture& guide, float uc, Vec2 u) const {
    DirectionSample ds;
    // Where the guide's probability is 0 (a region whose learned selection is 0, or not yet
    // confident), the BSDF's sample alone, without the guide's pdf unless a selection sample
    // needs it.
    if (!needsGuidePdf(guide)) {
        BSDFSample bs = bsdf.sampleF(si.wo, uc, u);
        if (!bs.valid()) return ds;
        ds.f = bs.f;
        ds.wi = bs.wi;
        ds.pdf = bs.pdf;
        ds.specular = bs.isSpecular();
        ds.transmission = bs.isTransmission();
        return ds;
    }
    // One-sample MIS: guide with probability mix, else the BSDF; the pdf is the mixture's.
    // The choice is made by u.x, rescaled to [0,1) for the chosen strategy, so that either
    // strategy's directions come from a well-stratified subset of the sampler's 2D points
    // (uc, a separate dimension, picks the BSDF's lobe or the guide's mixture part). Choosing
    // by uc took each strategy an unstratified random share of the 2D points: 5-7% more
    // error per sample with the Sobol' sampler (killeroo-simple, cornell-box; session 31).
    const float mix = guideMix(guide);
    ds.scale = guide.scale;
    float pGuide = 0.f, pBsdf = 0.f;
    if (u.x < mix) {
        u.x = std::min(u.x / mix, OneMinusEpsilon);
        {
            GuideTimer timer(guide.clock);
            ds.wi = guide.guide.sample(u, uc, &pGuide, &ds.bin);
        }
        if (!(pGuide > 0.f)) return DirectionSample();
        ds.f = bsdf.f(si.wo, ds.wi);
        pBsdf = bsdf.pdf(si.wo, ds.wi);
    } else {
        u.x = std::min((u.x - mix) / (1.f - mix), OneMinusEpsilon);
        BSDFSample bs = bsdf.sampleF(si.wo, uc, u);
        if (!bs.valid()) return DirectionSample();
        ds.wi = bs.wi;
        ds.f = bs.f;
        pBsdf = bs.pdf;
        GuideTimer timer(guide.clock);
        pGuide = guide.guide.pdf(ds.wi, &ds.bin);
    }
    ds.pdf = mix * pGuide + (1.f - mix) * pBsdf;
    ds.pGuide = pGuide;
    ds.pOther = pBsdf;
    ds.transmission = glm::dot(ds.wi, si.ng) * glm::dot(si.wo, si.ng) < 0.f;
    if (!(ds.pdf > 0.f) || !std::isfinite(ds.pdf)) return DirectionSample();
    return ds;
}

void PathIntegrator::takeDirection(PathState& s, const SurfaceInteraction& si, const BSDF& bsdf,
                                   const DirectionSample& ds, bool media) const {
    s.dirPdf = ds.pdf;
    s.specularBounce = ds.specular;
    if (ds.specular && ds.transmission) {
        float eta = bsdf.eta();
        s.etaScale *= glm::dot(si.wo, si.ng) > 0.f ? eta * eta : 1.f / (eta * eta);
    }
    s.prev = LightSampleContext{si.p, si.ng};
    if (media) s.pm.medium = si.mediumAfter(ds.wi, s.pm.medium);
    s.ray.o = spawnOrigin(si, ds.wi, originScale_);
    s.ray.d = ds.wi;
    s.ray.tMax = Infinity;
}

Spectrum PathIntegrator::sampleLight(const SurfaceInteraction& si, const BSDF& bsdf,
                                     GuideMixture& guide, Sampler& sampler, PathStats& stats,
                                     const PathMedium* media,
                                     const guiding::GuidingField::Choice& choice,
                                     PathRecorder* rec,
                                     const guiding::VertexGuide* region) const {
    Vec2 u = sampler.get2D();
    float pmf;
    const int li = lightChoice(choice).sample(si.p, u.x, &pmf, &u.x);
    if (li < 0 || pmf == 0.f) return Spectrum(0.f);
    // What the shadow ray found for the learned choice: Le f cos / pdf where the light is
    // visible, 0 where not (before the selection's probability and the MIS weight), over the
    // light's share of its emitter: an estimate of the whole emitter's.
    const bool learns = rec && region && region->valid();
    auto found = [&](float value) {
        if (!learns) return;
        const float within = scene_.lightGroups.within(li);
        rec->lightChosen(*region, scene_.lightGroups.group(li),
                         within > 0.f ? value / within : 0.f);
    };
    const Light& light = *scene_.lights[size_t(li)];
    LightSampleContext ctx{si.p, si.ng};
    LightSample ls;
    if (!light.sampleLi(ctx, u, &ls) || !ls.valid()) {
        found(0.f);
        return Spectrum(0.f);
    }
    Spectrum f = bsdf.f(si.wo, ls.wi) * std::abs(glm::dot(ls.wi, si.ns));
    if (isBlack(f)) {
        found(0.f);
        return Spectrum(0.f);
    }
    Vec3 o = spawnOrigin(si, ls.wi, originScale_);
    float tMax = std::isinf(ls.dist) ? Infinity : ls.dist * (1.f - 1e-4f);
    if (media) {
        f *= transmittance(o, ls.wi, tMax, si.mediumAfter(ls.wi, media->medium), *media->rng,
                           stats);
        if (isBlack(f)) {
            found(0.f);
            return Spectrum(0.f);
        }
    } else {
        ++stats.rays;
        if (scene_.occluded(o, ls.wi, tMax)) {
            found(0.f);
            return Spectrum(0.f);
        }
    }
    found(luminance(f * ls.L) / ls.pdf);
    if (ls.isDelta) return f * ls.L / (pmf * ls.pdf);
    float lightPdf = pmf * ls.pdf;
    float w = powerHeuristic(1, lightPdf, 1, mixturePdf(guide, ls.wi, bsdf.pdf(si.wo, ls.wi)));
    return f * ls.L * (w / lightPdf);
}

Spectrum PathIntegrator::transmittance(Vec3 o, const Vec3& d, float tMax, int medium, Rng& rng,
                                       PathStats& stats) const {
    Spectrum tr(1.f);
    for (int crossings = 0; crossings < 256; ++crossings) {
        SurfaceInteraction si;
        ++stats.rays;
        bool hit = scene_.intersect(Ray(o, d, tMax), &si);
        if (hit && si.material >= 0) return Spectrum(0.f);
        if (medium >= 0) tr *= scene_.media[size_t(medium)]->tr(o, d, hit ? si.t : tMax, rng);
        if (!hit || isBlack(tr)) return tr;
        medium = si.mediumAfter(d, medium);
        o = spawnOrigin(si, d, originScale_);
        tMax -= si.t;
        if (!(tMax > 0.f)) return tr;
    }
    return tr;
}

DirectionSample PathIntegrator::sampleMediumDirection(const Vec3& wo, float g,
                                                                      GuideMixture& guide,
                                                                      bool guided,
                                                                      Sampler& sampler) const {
    DirectionSample ds;
    const float uc = guided ? sampler.get1D() : 0.f;
    Vec2 u = sampler.get2D();
    const float mix = guideMix(guide);
    ds.scale = guide.scale;
    float pGuide = 0.f, pPhase = 0.f;
    // The guide or the phase function by u.x, as sampleDirection does.
    if (u.x < mix) {
        u.x = std::min(u.x / mix, OneMinusEpsilon);
        {
            GuideTimer timer(guide.clock);
            ds.wi = guide.guide.sample(u, uc, &pGuide, &ds.bin);
        }
        if (!(pGuide > 0.f)) return DirectionSample();
        pPhase = henyeyGreenstein(glm::dot(wo, ds.wi), g);
    } else {
        u.x = std::min((u.x - mix) / (1.f - mix), OneMinusEpsilon);
        ds.wi = sampleHenyeyGreenstein(wo, g, u, &pPhase);
        if (!(pPhase > 0.f)) return DirectionSample();
        if (needsGuidePdf(guide)) {
            GuideTimer timer(guide.clock);
            pGuide = guide.guide.pdf(ds.wi, &ds.bin);
        }
    }
    ds.f = Spectrum(pPhase);
    ds.pdf = mix * pGuide + (1.f - mix) * pPhase;
    ds.pGuide = pGuide;
    ds.pOther = pPhase;
    if (!(ds.pdf > 0.f) || !std::isfinite(ds.pdf)) return DirectionSample();
    return ds;
}

Spectrum PathIntegrator::sampleLightMedium(const Vec3& p, const Vec3& wo, float g,
                                           GuideMixture& guide, const PathMedium& pm,
                                           Sampler& sampler, PathStats& stats) const {
    Vec2 u = sampler.get2D();
    float pmf;
    int li = lights_->sample(p, u.x, &pmf, &u.x);
    if (li < 0 || pmf == 0.f) return Spectrum(0.f);
    const Light& light = *scene_.lights[size_t(li)];
    LightSample ls;
    if (!light.sampleLi(LightSampleContext{p, Vec3(0.f)}, u, &ls) || !ls.valid())
        return Spectrum(0.f);
    float phase = henyeyGreenstein(glm::dot(wo, ls.wi), g);
    float tMax = std::isinf(ls.dist) ? Infinity : ls.dist * (1.f - 1e-4f);
    Spectrum tr = transmittance(p, ls.wi, tMax, pm.medium, *pm.rng, stats);
    if (isBlack(tr)) return Spectrum(0.f);
    if (ls.isDelta) return phase * tr * ls.L / (pmf * ls.pdf);
    float lightPdf = pmf * ls.pdf;
    float w = powerHeuristic(1, lightPdf, 1, mixturePdf(guide, ls.wi, phase));
    return phase * tr * ls.L * (w / lightPdf);
}

PathIntegrator::Step PathIntegrator::mediumStep(PathState& s, bool found,
                                                const SurfaceInteraction& si, int bounces,
                                                Sampler& sampler, PathStats& stats,
                                                PathRecorder& rec) const {
    // Free flight to the surface (or to infinity) through the current medium.
    const Medium& medium = *scene_.media[size_t(s.pm.medium)];
    MediumSample ms = medium.sample(s.ray.o, s.ray.d, found ? si.t : s.ray.tMax,
                                    sampler.get2D(), *s.pm.rng);
    s.beta *= ms.weight;
    if (isBlack(s.beta) || !isFinite(s.beta)) return Step::End;
    // The pending target is radiance arriving at its vertex: weighted by the flight.
    {
        GuideTimer timer(s.clock);
        rec.flight(ms.weight);
    }
    if (!ms.scattered) return Step::Surface;
    // A medium vertex: NEE with MIS against the direction sampling, then a direction from the
    // phase function, mixed with the guide where the field has a volume cell (the field is
    // asked to model this place otherwise).
    if (bounces >= maxDepth_) return Step::End;
    const Vec3 p = s.ray.o + ms.t * s.ray.d, wo = -s.ray.d;
    guiding::VertexGuide guide;
    const bool guided = guide_.field && guide_.field->active() && guide_.field->guidesMedia();
    if (guided) {
        GuideTimer timer(s.clock);
        guide = guide_.field->guide(guiding::VertexQuery::inMedium(p));
        if (!guide.valid()) rec.requestMedium(p);
    }
    countGuided(guide, s.clock, stats);
    const guiding::VertexGuide sampleGuide = guide_.mix > 0.f ? guide : guiding::VertexGuide();
    ++stats.vertices;
    GuideMixture vertexGuide{sampleGuide, 1.f};
    vertexGuide.recordsSelection = rec.recordsSelection();
    vertexGuide.clock = s.clock;
    s.L += s.beta * sampleLightMedium(p, wo, medium.g(), vertexGuide, s.pm, sampler, stats);
    DirectionSample ds = sampleMediumDirection(wo, medium.g(), vertexGuide, guided, sampler);
    {
        GuideTimer timer(s.clock);
        rec.mediumScattered(guide, ds);
    }
    if (!(ds.pdf > 0.f)) return Step::End;
    {
        GuideTimer timer(s.clock);
        rec.selectionVertex(sampleGuide, ds, s.L, s.beta);
    }
    s.beta *= ds.f.x / ds.pdf;  // 1 for plain phase sampling
    s.dirPdf = ds.pdf;
    s.specularBounce = false;
    s.prev = LightSampleContext{p, Vec3(0.f)};
    s.prevChoice = {};
    s.ray = Ray(p, ds.wi);
    if (!pbrtRoulette(&s.beta, s.etaScale, bounces, rrThreshold_, sampler)) return Step::End;
    return Step::Scattered;
}

PathIntegrator::Step PathIntegrator::subsurfaceStep(PathState& s, const SurfaceInteraction& si,
                                                    const BSDF& bsdf, Sampler& sampler,
                                                    PathStats& stats, PathRecorder& rec) const {
    const SeparableBSSRDF& b = *bsdf.subsurface();
    const float u1 = sampler.get1D();
    const Vec2 u2 = sampler.get2D();
    BSSRDFProbe probe;
    if (!sampleProbe(b, bsdf.frame(), si.p, u1, u2, &probe)) return Step::End;
    // Every hit of the probe segment on a surface of the entry's material (pbrt-v3 keeps all;
    // more than kMaxHits on one segment is not expected, the rest are not counted).
    constexpr int kMaxHits = 16;
    SurfaceInteraction hits[kMaxHits];
    int found = 0;
    Vec3 o = probe.start;
    const Vec3 seg = probe.end - probe.start;
    const float len = glm::length(seg);
    if (!(len > 0.f)) return Step::End;
    const Vec3 d = seg / len;
    for (int crossings = 0; crossings < 256 && found < kMaxHits; ++crossings) {
        const float remaining = glm::dot(probe.end - o, d);
        if (!(remaining > 0.f)) break;
        ++stats.rays;
        SurfaceInteraction& h = hits[found];
        if (!scene_.intersect(Ray(o, d, remaining), &h)) break;
        o = spawnOrigin(h, d, originScale_);
        if (h.material == si.material) ++found;
    }
    if (found == 0) return Step::End;
    const int pick = std::min(int(probe.uPick * float(found)), found - 1);
    SurfaceInteraction pi = hits[pick];
    const float pdf = pdfSp(b, bsdf.frame(), si.p, pi.p, pi.ng) / float(found);
    const Spectrum sp = b.sr(glm::distance(si.p, pi.p));
    if (!(pdf > 0.f) || isBlack(sp)) return Step::End;
    s.beta *= sp / pdf;
    if (!isFinite(s.beta)) return Step::End;
    rec.subsurfaceScattered();

    // The exit vertex: the exit lobe Sw in the frame of the hit (no material evaluation, as
    // pbrt-v3), seen from its shading normal. Not guided: the lobe is BSDF-sampled.
    BSDF exit;
    exit.init(pi.ng, pi.ns, glm::length(pi.shadingTangent) > 0.f ? pi.shadingTangent : pi.dpdu);
    exit.add(BSSRDFExitLobe(b.eta(), TransportMode::Radiance));
    pi.wo = pi.ns;
    const bool media = scene_.hasMedia();
    ++stats.vertices;
    GuideMixture none{guiding::VertexGuide(), 0.f};
    s.L += s.beta * sampleLight(pi, exit, none, sampler, stats, media ? &s.pm : nullptr);
    const float uc = sampler.get1D();
    const Vec2 u = sampler.get2D();
    const BSDFSample bs = exit.sampleF(pi.wo, uc, u);
    if (!bs.valid() || isBlack(bs.f)) return Step::End;
    s.beta *= bs.f * (std::abs(glm::dot(bs.wi, pi.ns)) / bs.pdf);
    s.dirPdf = bs.pdf;
    s.specularBounce = false;
    s.prev = LightSampleContext{pi.p, pi.ng};
    s.prevChoice = {};
    if (media) s.pm.medium = pi.mediumAfter(bs.wi, s.pm.medium);
    s.ray.o = spawnOrigin(pi, bs.wi, originScale_);
    s.ray.d = bs.wi;
    s.ray.tMax = Infinity;
    return isFinite(s.beta) ? Step::Scattered : Step::End;
}

Spectrum PathIntegrator::Li(const Ray& cameraRay, Sampler& sampler, PathStats& stats,
                            int slot, float pixelEstimate) const {
    PathState s;
    s.ray = cameraRay;
    int passThroughs = 0;
    BSDF bsdf;
    // A field that can no longer change a path (GuidingField::active) is skipped: plain path
    // tracing, its recorder off too.
    guiding::GuidingField* field = guide_.field && guide_.field->active() ? guide_.field : nullptr;
    PathRecorder rec(guide_, slot);
    // One path in kGuideClockEvery measures the guide's time (render/guide_clock.h).
    s.clock = field && stats.paths % kGuideClockEvery == 0 ? &stats.guideClock : nullptr;
    // Media (volpath): the medium the ray travels in; tracking decisions use a per-path
    // generator seeded from two sampler dimensions. Scenes without media skip all of it.
    const bool media = scene_.hasMedia();
    Rng rng;
    if (media) {
        uint32_t a, b;
        float ua = sampler.get1D(), ub = sampler.get1D();
        std::memcpy(&a, &ua, 4);
        std::memcpy(&b, &ub, 4);
        rng.setSeed((uint64_t(a) << 32) | b, uint64_t(slot));
        s.pm.medium = scene_.cameraMedium;
        s.pm.rng = &rng;
    }
    // Split paths (GuideSettings::splitMax): the branches waiting to be traced, each a path
    // state after its direction sample at bounce `bounces`.
    struct Branch {
        PathState s;
        int bounces;
        int retBase;  // PathRecorder::split's base
        // The split vertex's guide and the branch's direction, for its return.
        guiding::VertexGuide guide;
        int bin;
        Vec3 wi;
        bool learnsReturn;
    };
    constexpr int kMaxBranches = 32;
    // Left uninitialised (every field is set when a branch is pushed): value-initialising the
    // 32 branches (6 KB) took 4% of every render's time, guided or not (killeroo, perf).
    union BranchStack {
        BranchStack() {}
        Branch v[kMaxBranches];
    } stack;
    Branch* const branches = stack.v;
    int numBranches = 0, startBounces = 0;
    int branchesLeft = kMaxBranches;  // per camera path: its work stays bounded
    for (;;) {
        for (int bounces = startBounces;; ++bounces) {
            // The closest hit. The path's last direction (no vertex after it) brings back only
            // the emission it hits, weighted against this vertex's next-event estimation: the
            // learned Q, the light of whole returns, overstates what it can find there, and its
            // truncated return would understate Q for the vertices before the last. It samples
            // the BSDF and records no return (Eq. 1 targets, bootstrapped from Q, are learned
            // there as everywhere), so a surface vertex looks up a region only before it, to
            // bootstrap, or for its next-event estimation's learned light choice (lights=learned:
            // at veach-mis' only vertex, maxdepth 1, it has 0.21x the error per sample of the
            // scene's light sampler; docs/BENCHMARKS_HISTORY.md, session 38).
            SurfaceInteraction si;
            ++stats.rays;
            const bool found = scene_.intersect(s.ray, &si);
            const bool lastDirection = bounces + 1 >= maxDepth_;
            const bool wantsRegion =
                field && (!lastDirection || rec.bootstraps() || guide_.learnLights);

            // Media: a free flight to the hit; a scattering event is a medium vertex.
            if (media && s.pm.medium >= 0) {
                const Step step = mediumStep(s, found, si, bounces, sampler, stats, rec);
                if (step == Step::End) break;
                if (step == Step::Scattered) continue;
            }
            // The lookup below reads a table entry for a surface vertex at si.p: start loading
            // it (a cache miss otherwise; the emission and material evaluations run in
            // between). Not at medium boundaries, which the path passes without a vertex.
            guiding::VertexQuery query;
            if (found && wantsRegion && si.material >= 0) {
                GuideTimer timer(s.clock);
                query.p = si.p;
                if (guide_.patches) query.patch = guide_.patches->key(si);
                field->prefetch(query);
            }

            // Emission reached by the previous scattering (or seen by the camera), weighted by
            // MIS against next-event estimation.
            if (!found) {
                float envLum = 0.f;
                for (int idx : scene_.infiniteLights) {
                    const Light& light = *scene_.lights[size_t(idx)];
                    Spectrum Le = light.Le(s.ray.d);
                    if (isBlack(Le)) continue;
                    envLum += luminance(Le);
                    if (bounces == 0 || s.specularBounce) {
                        s.L += s.beta * Le;
                    } else {
                        float lightPdf = lightPmf(s.prev.p, s.prevChoice, idx) *
                                         light.pdfLi(s.prev, s.ray.d, Vec3(0.f), Vec3(0.f));
                        s.L += s.beta * Le * powerHeuristic(1, s.dirPdf, 1, lightPdf);
                    }
                }
                GuideTimer timer(s.clock);
                rec.escaped(envLum);
                break;
            }
            float emitted = 0.f;
            if (si.light >= 0) {
                const Light& light = *scene_.lights[size_t(si.light)];
                Spectrum Le = light.L(si.p, si.ng, si.uv, si.wo);
                if (!isBlack(Le)) {
                    emitted = luminance(Le);
                    if (bounces == 0 || s.specularBounce) {
                        s.L += s.beta * Le;
                    } else {
                        float lightPdf = lightPmf(s.prev.p, s.prevChoice, si.light) *
                                         light.pdfLi(s.prev, s.ray.d, si.p, si.ng);
                        s.L += s.beta * Le * powerHeuristic(1, s.dirPdf, 1, lightPdf);
                    }
                }
            }

            // Medium boundaries without a surface: continue the ray unchanged. At the depth
            // limit, pbrt-v3 ends the path here (it tests maxdepth before it skips a boundary):
            // path always (its shadow rays stop at boundaries too); volpath where the light
            // beyond would count at full weight (the camera ray, after a specular bounce). After a
            // non-specular vertex the ray goes on for its MIS-weighted share, which volpath's
            // next-event estimation finds through boundaries (docs/MEDIA.md, "Depth limit
            // at medium boundaries").
            if (si.material < 0) {
                const bool fullWeight = bounces == 0 || s.specularBounce;
                if ((bounces >= maxDepth_ && (!media || fullWeight)) || ++passThroughs > 256) break;
                {
                    GuideTimer timer(s.clock);
                    rec.passedThrough(emitted);
                }
                if (media) s.pm.medium = si.mediumAfter(s.ray.d, s.pm.medium);
                s.ray.o = spawnOrigin(si, s.ray.d, originScale_);
                --bounces;
                continue;
            }
            if (bounces >= maxDepth_ && !rec.awaitsTarget()) break;

            // The BSDF, and the guide here: its region, and the guide's probability (mix x the
            // region's confidence x the BSDF's diffuse share).
            bsdf.clear();
            scene_.materials[size_t(si.material)]->computeBSDF(si, sampler.get1D(), &bsdf);
            const BSDF::LobeCounts lobes = bsdf.lobeCounts();
            const bool canGuide = field && guidable(lobes);
            guiding::VertexGuide guide;
            if (canGuide && wantsRegion) {
                GuideTimer timer(s.clock);
                query.n = glm::dot(si.ns, si.wo) >= 0.f ? si.ns : -si.ns;
                guide = field->guide(query);
            }
            countGuided(guide, s.clock, stats);
            const bool lastVertex = bounces >= maxDepth_;
            const float share =
                guide.valid() && guide_.mix > 0.f && !lastDirection ? diffuseShare(lobes) : 0.f;
            const guiding::VertexGuide sampleGuide = share > 0.f ? guide : guiding::VertexGuide();
            GuideMixture vertexGuide{sampleGuide, share};
            vertexGuide.recordsSelection = rec.recordsSelection();
            vertexGuide.clock = s.clock;

            // Next-event estimation at non-specular vertices (first: its shadow ray gives the
            // guide's prefetch of the region's tables time to land).
            s.prevChoice = {};
            if (!lastVertex) {
                ++stats.vertices;
                if (lobes.smooth > 0) {
                    const guiding::GuidingField::Choice choice =
                        guide_.learnLights ? guide.choice() : guiding::GuidingField::Choice();
                    s.L += s.beta * sampleLight(si, bsdf, vertexGuide, sampler, stats,
                                                media ? &s.pm : nullptr, choice,
                                                choice.learning ? &rec : nullptr, &guide);
                    s.prevChoice = choice;
                }
            }
            // Training: the previous guided vertex's Eq. 1 target, from the light found here.
            bool deferTarget;
            {
                GuideTimer timer(s.clock);
                rec.arrived(si.p, s.L);
                deferTarget =
                    rec.surfaceReached(si, bsdf, guide, canGuide, lobes.all, emitted, lastVertex);
            }
            if (lastVertex) break;

            // The sample of the next direction: drawn before splitting's own, so that a path's
            // direction here takes the same dimensions whether it splits or not.
            const float uc = sampler.get1D();
            const Vec2 u = sampler.get2D();

            // Splitting: how many paths continue from here (r, rounded stochastically).
            float splitRatio = 1.f;
            int splitCount = 1, retBase = 0;
            if (guide_.splitMax > 1 && sampleGuide.valid() && pixelEstimate > 0.f && !media &&
                !bsdf.subsurface() && guideConfidence(vertexGuide) >= kRouletteConfidence) {
                // The diffuse lobes' light: what the learned irradiance predicts (a glossy
                // lobe's light comes from its reflection direction, not from E / pi).
                const float expected = luminance(s.beta) *
                                       luminance(bsdf.f(si.wo, query.n, kDiffuseLobes)) *
                                       sampleGuide.irradianceEstimate(query.n);
                const float r = expected / (guide_.splitWindow * pixelEstimate);
                if (r > 1.f && std::isfinite(r)) {
                    // At most as many branches as the stack holds: E[count] = ratio exactly.
                    splitRatio = std::min({r, float(guide_.splitMax), float(1 + branchesLeft)});
                    splitCount = int(splitRatio);
                    if (sampler.get1D() < splitRatio - float(splitCount)) ++splitCount;
                    if (splitCount > 1) retBase = rec.split();
                    branchesLeft -= splitCount - 1;
                }
            }
            // Each branch's direction from the vertex's sample shifted by the k-th of splitCount
            // points spread over the unit square (k / n in x, a golden-ratio step in y, and a
            // step of its own for uc): every branch's sample is uniform, as the path's own, so
            // each branch is an unbiased estimate (their number, rounded from an independent
            // dimension, is independent of them), and together they cover the square evenly
            // (stratified splitting) instead of drawing dimensions of their own.
            for (int k = 1; k < splitCount; ++k) {
                const float t = float(k) / float(splitCount);
                const Vec2 uk(shiftUnit(u.x, t), shiftUnit(u.y, fractional(float(k) * kGolden)));
                const float uck = shiftUnit(uc, fractional(float(k) * kPlastic));
                DirectionSample dk = sampleDirection(si, bsdf, vertexGuide, uck, uk);
                if (!(dk.pdf > 0.f) || isBlack(dk.f)) continue;
                Branch& b = branches[numBranches];
                b.s = s;
                b.s.beta *= dk.f * (std::abs(glm::dot(dk.wi, si.ns)) / (dk.pdf * splitRatio));
                if (!isFinite(b.s.beta)) continue;
                takeDirection(b.s, si, bsdf, dk, false);
                b.bounces = bounces;
                b.retBase = retBase;
                b.guide = guide;
                b.bin = dk.bin;
                b.wi = dk.wi;
                b.learnsReturn = !dk.transmission && !lastDirection;
                ++numBranches;
            }

            // What the guide learns from the path's own direction.
            DirectionSample ds = sampleDirection(si, bsdf, vertexGuide, uc, u);

            {
                GuideTimer timer(s.clock);
                rec.surfaceSampled(deferTarget, si, guide, ds, emitted);
            }
            if (!(ds.pdf > 0.f) || isBlack(ds.f)) break;
            {
                GuideTimer timer(s.clock);
                rec.selectionVertex(sampleGuide, ds, s.L, s.beta);
            }
            const Spectrum weight = ds.f * std::abs(glm::dot(ds.wi, si.ns)) / ds.pdf;
            s.beta *= weight;
            if (splitRatio > 1.f) s.beta /= splitRatio;  // one of about r branches
            {
                GuideTimer timer(s.clock);
                rec.surfaceScattered(guide, !ds.transmission && !lastDirection, canGuide, ds, weight,
                                     s.L, s.beta);
            }
            // The next ray.
            takeDirection(s, si, bsdf, ds, media);
            if (!isFinite(s.beta)) break;
            // A transmission into a material with a BSSRDF: the path continues from an exit point.
            if (ds.transmission && bsdf.subsurface() &&
                subsurfaceStep(s, si, bsdf, sampler, stats, rec) == Step::End)
                break;

            // Russian roulette: from the second vertex on, on the expected contribution where
            // the guide knows it; else pbrt-v3's.
            if (guide_.adjointRoulette && bounces >= kRouletteFirstBounce && pixelEstimate > 0.f &&
                sampleGuide.valid() && !ds.transmission &&
                guideConfidence(vertexGuide) >= kRouletteConfidence) {
                float expected;
                {
                    GuideTimer timer(s.clock);
                    expected = luminance(s.beta) * sampleGuide.policyRadiance(ds.wi, ds.bin);
                }
                if (!adjointRoulette(&s.beta, expected, guide_.rouletteWindow * pixelEstimate,
                                     kMinSurvival, sampler))
                    break;
                continue;
            }
            if (!pbrtRoulette(&s.beta, s.etaScale, bounces, rrThreshold_, sampler)) break;
        }
        if (numBranches == 0) break;
        {
            GuideTimer timer(s.clock);
            rec.segmentEnded(s.L, branches[numBranches - 1].retBase);
        }
        // The next branch, with the light of every branch so far.
        const Spectrum L = s.L;
        --numBranches;
        const Branch& b = branches[numBranches];
        s = b.s;
        s.L = L;
        startBounces = b.bounces + 1;
        {
            GuideTimer timer(s.clock);
            rec.branchStarted(b.guide, b.learnsReturn, b.bin, b.wi, s.L, s.beta);
        }
    }
    {
        GuideTimer timer(s.clock);
        rec.finish(s.L);
    }
    return s.L;
}

}  // namespace rlpbrt
