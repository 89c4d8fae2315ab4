#include "render/integrator.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "render/media.h"
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
                                 scene.boundsMin(), scene.boundsMax(), nullptr)),
      guide_(guide), maxDepth_(scene.integrator.maxDepth),
      rrThreshold_(scene.integrator.rrThreshold) {
    guide_.mix = clamp(guide_.mix, 0.f, 1.f);
    const Vec3 extent = scene.boundsMax() - scene.boundsMin();
    const float size = std::max({extent.x, extent.y, extent.z});
    if (std::isfinite(size) && size > 0.f) originScale_ = std::min(1.f, size);
    if (guide_.mix == 0.f && !guide_.learn) guide_.field = nullptr;
}

namespace {
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
            *error = "mix must be a number in [0, 1] or \"learn\", got \"" + it->second + "\"";
            return false;
        }
        settings->mix = mix;
    }
    auto target = config.params.find("target");
    if (target != config.params.end()) {
        if (target->second != "sum" && target->second != "sample" && target->second != "path") {
            *error = "target must be \"sum\", \"sample\" or \"path\", got \"" +
                     target->second + "\"";
            return false;
        }
        settings->sampledTarget = target->second != "sum";
        settings->pathTarget = target->second == "path";
    }
    auto samples = config.params.find("samples");
    if (samples != config.params.end()) {
        if (samples->second != "sequence" && samples->second != "independent") {
            *error = "samples must be \"sequence\" or \"independent\", got \"" +
                     samples->second + "\"";
            return false;
        }
        settings->independentPasses = samples->second == "independent";
    }
    auto rr = config.params.find("rr");
    if (rr != config.params.end()) {
        if (rr->second != "adjoint" && rr->second != "pbrt") {
            *error = "rr must be \"adjoint\" or \"pbrt\", got \"" + rr->second + "\"";
            return false;
        }
        settings->adjointRoulette = rr->second == "adjoint";
    }
    auto window = config.params.find("rr-window");
    if (window != config.params.end()) {
        float w = 0.f;
        if (!parseFloat(window->second, &w) || !(w > 0.f && w <= 1.f)) {
            *error = "rr-window must be a number in (0, 1], got \"" + window->second + "\"";
            return false;
        }
        settings->rouletteWindow = w;
    }
    auto learn = config.params.find("learn");
    if (learn != config.params.end() && learn->second != "all" &&
        !parseSampleCount(learn->second, &settings->learnSpp)) {
        *error = "learn must be \"all\" or a sample count in [0, 16777216], got \"" +
                 learn->second + "\"";
        return false;
    }
    auto autoSpp = config.params.find("auto");
    if (autoSpp != config.params.end() && !parseSampleCount(autoSpp->second, &settings->autoSpp)) {
        *error = "auto must be a sample count in [0, 16777216] (0 = always guide), got \"" +
                 autoSpp->second + "\"";
        return false;
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

// A guided vertex of the path whose direction sample feeds the selection learning (mix=learn):
// the radiance the path gathers after it, over the throughput at it, is the sample's
// contribution F = f cos Li / pdf, so its integrand is F * pdf (known when the path ends).
struct SelectionVertex {
    int region;
    guiding::SelectionSample s;
    float lumL;     // luminance of L when the direction was sampled
    float lumBeta;  // luminance of the throughput at the vertex
};
constexpr int kMaxSelectionVertices = 16;
// A path's selection vertices, left uninitialised until used: value-initialising all of
// them cost every path 48 instructions, and only mix=learn uses them.
union SelectionVertices {
    SelectionVertices() {}
    SelectionVertex v[kMaxSelectionVertices];
};

// Adjoint-driven roulette (GuideSettings::adjointRoulette): the first bounce it may end a
// path at, the least survival probability (bounds a survivor's weight), and the confidence a
// region needs before its Q is trusted.
constexpr int kRouletteFirstBounce = 1;
constexpr float kMinSurvival = 0.25f;
constexpr float kRouletteConfidence = 0.5f;

// A guided vertex trained with the path's return (target=path): the radiance the path
// gathered after it, over the throughput after its direction sample, is the radiance that
// direction brought to it, as the estimator counts it: emission found by the direction
// carries its MIS weight against the vertex's next-event estimation.
struct ReturnVertex {
    int region;
    int bin;  // the guide's bin of w in region, or -1
    Vec3 w;
    Spectrum L;     // L when the direction was sampled (after the vertex's NEE)
    Spectrum beta;  // throughput after the direction's weight
};
constexpr int kMaxReturnVertices = 32;

// The pending training record of the last guided vertex: its region and direction, and the
// target collected so far through delta vertices (weight = product of their f cos / pdf).
struct PendingRecord {
    int region = -1;
    Vec3 w{0.f};
    int bin = -1;  // the guide's bin of w in region, or -1
    float target = 0.f;
    float weight = 1.f;
    bool active() const { return region >= 0; }
};
}  // namespace

PathIntegrator::DirectionSample PathIntegrator::sampleDirection(const SurfaceInteraction& si,
                                                                const BSDF& bsdf,
                                                                VertexGuide& guide,
                                                                Sampler& sampler) const {
    DirectionSample ds;
    const int region = guide.region;
    float uc = sampler.get1D();
    Vec2 u = sampler.get2D();
    if (region < 0) {
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
    const float mix = guideMix(guide);
    ds.scale = guide.scale;
    float pGuide = 0.f, pBsdf = 0.f;
    if (uc < mix) {
        float uStratum = std::min(uc / mix, OneMinusEpsilon);
        ds.wi = guide_.field->sample(region, u, uStratum, &pGuide, &ds.bin);
        if (!(pGuide > 0.f)) return DirectionSample();
        ds.f = bsdf.f(si.wo, ds.wi);
        pBsdf = bsdf.pdf(si.wo, ds.wi);
    } else {
        float ub = std::min((uc - mix) / (1.f - mix), OneMinusEpsilon);
        BSDFSample bs = bsdf.sampleF(si.wo, ub, u);
        if (!bs.valid()) return DirectionSample();
        ds.wi = bs.wi;
        ds.f = bs.f;
        pBsdf = bs.pdf;
        pGuide = guide_.field->pdf(region, ds.wi, &ds.bin);
    }
    ds.pdf = mix * pGuide + (1.f - mix) * pBsdf;
    ds.pGuide = pGuide;
    ds.pOther = pBsdf;
    ds.transmission = glm::dot(ds.wi, si.ng) * glm::dot(si.wo, si.ng) < 0.f;
    if (!(ds.pdf > 0.f) || !std::isfinite(ds.pdf)) return DirectionSample();
    return ds;
}

Spectrum PathIntegrator::sampleLight(const SurfaceInteraction& si, const BSDF& bsdf,
                                     VertexGuide& guide, Sampler& sampler, PathStats& stats,
                                     const PathMedium* media) const {
    float uLight = sampler.get1D();
    Vec2 u = sampler.get2D();
    float pmf;
    int li = lights_->sample(si.p, uLight, &pmf);
    if (li < 0 || pmf == 0.f) return Spectrum(0.f);
    const Light& light = *scene_.lights[size_t(li)];
    LightSampleContext ctx{si.p, si.ng};
    LightSample ls;
    if (!light.sampleLi(ctx, u, &ls) || !ls.valid()) return Spectrum(0.f);
    Spectrum f = bsdf.f(si.wo, ls.wi) * std::abs(glm::dot(ls.wi, si.ns));
    if (isBlack(f)) return Spectrum(0.f);
    Vec3 o = spawnOrigin(si, ls.wi, originScale_);
    float tMax = std::isinf(ls.dist) ? Infinity : ls.dist * (1.f - 1e-4f);
    if (media) {
        f *= transmittance(o, ls.wi, tMax, si.mediumAfter(ls.wi, media->medium), *media->rng,
                           stats);
        if (isBlack(f)) return Spectrum(0.f);
    } else {
        ++stats.rays;
        if (scene_.occluded(o, ls.wi, tMax)) return Spectrum(0.f);
    }
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

PathIntegrator::DirectionSample PathIntegrator::sampleMediumDirection(const Vec3& wo, float g,
                                                                      VertexGuide& guide,
                                                                      Sampler& sampler) const {
    DirectionSample ds;
    const int region = guide.region;
    const float uc = guide_.field ? sampler.get1D() : 1.f;
    const Vec2 u = sampler.get2D();
    const float mix = guideMix(guide);
    ds.scale = guide.scale;
    float pGuide = 0.f, pPhase = 0.f;
    if (uc < mix) {
        ds.wi = guide_.field->sample(region, u, std::min(uc / mix, OneMinusEpsilon), &pGuide,
                                     &ds.bin);
        if (!(pGuide > 0.f)) return DirectionSample();
        pPhase = henyeyGreenstein(glm::dot(wo, ds.wi), g);
    } else {
        ds.wi = sampleHenyeyGreenstein(wo, g, u, &pPhase);
        if (!(pPhase > 0.f)) return DirectionSample();
        if (mix > 0.f) pGuide = guide_.field->pdf(region, ds.wi, &ds.bin);
    }
    ds.f = Spectrum(pPhase);
    ds.pdf = mix * pGuide + (1.f - mix) * pPhase;
    ds.pGuide = pGuide;
    ds.pOther = pPhase;
    if (!(ds.pdf > 0.f) || !std::isfinite(ds.pdf)) return DirectionSample();
    return ds;
}

Spectrum PathIntegrator::sampleLightMedium(const Vec3& p, const Vec3& wo, float g,
                                           VertexGuide& guide, const PathMedium& pm,
                                           Sampler& sampler, PathStats& stats) const {
    float uLight = sampler.get1D();
    Vec2 u = sampler.get2D();
    float pmf;
    int li = lights_->sample(p, uLight, &pmf);
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

float PathIntegrator::scatteredTarget(const SurfaceInteraction& si, const BSDF& bsdf, int region,
                                      const Vec3& woY) const {
    Vec3 n = glm::dot(si.ns, woY) >= 0.f ? si.ns : -si.ns;
    // Lambertian y: the sum is rho/pi times the learned irradiance (no BSDF evaluations).
    Spectrum albedo(0.f);
    bool lambertian = true;
    for (int i = 0; i < bsdf.numComponents() && lambertian; ++i) {
        if (const auto* l = bsdf.component(i).get<LambertianReflection>()) albedo += l->r;
        else lambertian = false;
    }
    if (lambertian) return luminance(albedo) * InvPi * guide_.field->irradianceEstimate(region, n);
    if (guide_.sampledTarget) return -1.f;  // estimated with the direction sampled at y
    struct Ctx {
        const BSDF& bsdf;
        Vec3 wo, n;
    } ctx{bsdf, woY, n};
    const Ctx* c = &ctx;  // one captured pointer: no allocation in std::function
    return guide_.field->scatteredEstimate(region, [c](const glm::vec3& wj) {
        float cosj = glm::dot(wj, c->n);
        return cosj > 0.f ? luminance(c->bsdf.f(c->wo, wj)) * cosj : 0.f;
    });
}

bool PathIntegrator::pbrtRoulette(Spectrum* beta, float etaScale, int bounces,
                                  Sampler& sampler) const {
    const float m = maxComponent(*beta * etaScale);
    if (!(m < rrThreshold_) || bounces <= 3) return true;
    const float q = std::max(0.05f, 1.f - m);
    if (sampler.get1D() < q) return false;
    *beta /= 1.f - q;
    return true;
}

Spectrum PathIntegrator::Li(const Ray& cameraRay, Sampler& sampler, PathStats& stats,
                            int slot, float pixelEstimate) const {
    Spectrum L(0.f), beta(1.f);
    Ray ray = cameraRay;
    bool specularBounce = false;
    float dirPdf = 0.f, etaScale = 1.f;
    LightSampleContext prev;
    int passThroughs = 0;
    BSDF bsdf;
    guiding::GuidingField* field = guide_.field;
    const bool learn = field && guide_.learn;
    PendingRecord pending;
    SelectionVertices selVerts;
    int numSelVerts = 0;
    const bool learnSelection = learn && guide_.learnMix;
    // Training targets of surface vertices: the path's returns, or Eq. 1 bootstrapped at the
    // next vertex (pending). Medium vertices always bootstrap: in a lossless medium the noisy
    // returns made a pure policy's phase / pdf weights heavy-tailed over the many vertices of
    // a thick medium (vdb, mix 1: mean 0.53 +- 0.04 of an exact 1 at 64 spp).
    const bool bootstrap = learn && !guide_.pathTarget;
    const bool returns = learn && guide_.pathTarget;
    ReturnVertex retVerts[kMaxReturnVertices];
    int numRet = 0;
    auto pushReturn = [&](int region, const Vec3& w, int bin) {
        if (returns && region >= 0 && numRet < kMaxReturnVertices)
            retVerts[numRet++] = ReturnVertex{region, bin, w, L, beta};
    };
    auto pushSelection = [&](int region, const DirectionSample& ds) {
        if (!learnSelection || region < 0 || numSelVerts >= kMaxSelectionVertices) return;
        selVerts.v[numSelVerts++] = SelectionVertex{
            region, guiding::SelectionSample{0.f, ds.pdf, ds.pGuide, ds.pOther, ds.scale},
            luminance(L), luminance(beta)};
    };
    // Media (volpath): the medium the ray travels in; tracking decisions use a per-path
    // generator seeded from two sampler dimensions. Scenes without media skip all of it.
    const bool media = scene_.hasMedia();
    Rng rng;
    PathMedium pm;
    if (media) {
        uint32_t a, b;
        float ua = sampler.get1D(), ub = sampler.get1D();
        std::memcpy(&a, &ua, 4);
        std::memcpy(&b, &ub, 4);
        rng.setSeed((uint64_t(a) << 32) | b, uint64_t(slot));
        pm.medium = scene_.cameraMedium;
        pm.rng = &rng;
    }
    auto flush = [&](float addTarget) {
        if (!pending.active()) return;
        pending.target += pending.weight * addTarget;
        field->record(slot, pending.region, pending.w, pending.target, pending.bin);
        pending = PendingRecord();
    };
    for (int bounces = 0;; ++bounces) {
        SurfaceInteraction si;
        ++stats.rays;
        bool found = scene_.intersect(ray, &si);
        // The path's last direction (no vertex after it) brings back only the emission it
        // hits, weighted against this vertex's next-event estimation: the learned Q, the light
        // of whole returns, overstates what it can find there, and its truncated return would
        // understate Q for the vertices before the last. It samples the BSDF and records no
        // return (Eq. 1 targets, bootstrapped from Q, are learned there as everywhere), so a
        // surface vertex looks up a region only before it or to bootstrap.
        const bool lastDirection = bounces + 1 >= maxDepth_;
        const bool wantsRegion = field && (!lastDirection || bootstrap);
        // The lookup below reads a table entry for si.p: start loading it (a cache miss
        // otherwise; the material evaluation runs in between).
        uint32_t patch = SurfacePatches::kNone;
        if (found && wantsRegion) {
            if (guide_.patches) patch = guide_.patches->key(si);
            field->prefetchPatch(patch, si.p);
        }
        if (media && pm.medium >= 0) {
            // Free flight to the surface (or to infinity) through the current medium.
            const Medium& medium = *scene_.media[size_t(pm.medium)];
            MediumSample ms = medium.sample(ray.o, ray.d, found ? si.t : ray.tMax, rng);
            beta *= ms.weight;
            if (isBlack(beta) || !isFinite(beta)) break;
            // The pending target is radiance arriving at its vertex: weighted by the flight.
            if (pending.active()) pending.weight *= luminance(ms.weight);
            if (ms.scattered) {
                // A medium vertex: NEE with MIS against the direction sampling, then a
                // direction from the phase function, mixed with the guide where the field
                // has a volume cell (the field is asked to model this place otherwise).
                if (bounces >= maxDepth_) break;
                Vec3 p = ray.o + ms.t * ray.d, wo = -ray.d;
                int region = -1;
                if (field) {
                    region = field->lookupMedium(p);
                    if (region < 0 && learn) field->requestMedium(slot, p);
                }
                const int sampleRegion = guide_.mix > 0.f ? region : -1;
                ++stats.vertices;
                VertexGuide vertexGuide{sampleRegion, 1.f};
                L += beta * sampleLightMedium(p, wo, medium.g(), vertexGuide, pm, sampler, stats);
                DirectionSample ds = sampleMediumDirection(wo, medium.g(), vertexGuide, sampler);
                if (learn) {
                    // Eq. 1 for the previous vertex, with the one-sample estimate of the
                    // light scattered here: Q(p, w') phase(w') / pdf(w').
                    if (pending.active() && region >= 0 && ds.pdf > 0.f) {
                        const float est = field->radiance(region, ds.wi, ds.bin) * ds.f.x / ds.pdf;
                        flush(std::isfinite(est) ? est : 0.f);
                    }
                    pending = PendingRecord();
                    if (region >= 0 && ds.pdf > 0.f) {
                        pending.region = region;
                        pending.w = ds.wi;
                        pending.bin = ds.bin;
                    }
                }
                if (!(ds.pdf > 0.f)) break;
                pushSelection(sampleRegion, ds);
                const Vec3 wi = ds.wi;
                beta *= ds.f.x / ds.pdf;  // 1 for plain phase sampling
                dirPdf = ds.pdf;
                specularBounce = false;
                prev = LightSampleContext{p, Vec3(0.f)};
                ray = Ray(p, wi);
                if (!pbrtRoulette(&beta, etaScale, bounces, sampler)) break;
                continue;
            }
        }
        // Emission reached by the previous scattering (or seen by the camera), weighted by
        // MIS against next-event estimation.
        if (!found) {
            float envLum = 0.f;
            for (int idx : scene_.infiniteLights) {
                const Light& light = *scene_.lights[size_t(idx)];
                Spectrum Le = light.Le(ray.d);
                if (isBlack(Le)) continue;
                envLum += luminance(Le);
                if (bounces == 0 || specularBounce) {
                    L += beta * Le;
                } else {
                    float lightPdf = lights_->pmf(prev.p, idx) *
                                     light.pdfLi(prev, ray.d, Vec3(0.f), Vec3(0.f));
                    L += beta * Le * powerHeuristic(1, dirPdf, 1, lightPdf);
                }
            }
            if (learn) flush(envLum);
            break;
        }
        float emitted = 0.f;
        if (si.light >= 0) {
            const Light& light = *scene_.lights[size_t(si.light)];
            Spectrum Le = light.L(si.p, si.ng, si.uv, si.wo);
            if (!isBlack(Le)) {
                emitted = luminance(Le);
                if (bounces == 0 || specularBounce) {
                    L += beta * Le;
                } else {
                    float lightPdf = lights_->pmf(prev.p, si.light) *
                                     light.pdfLi(prev, ray.d, si.p, si.ng);
                    L += beta * Le * powerHeuristic(1, dirPdf, 1, lightPdf);
                }
            }
        }
        // Medium boundaries without a surface: continue the ray unchanged.
        if (si.material < 0) {
            // (With media, as volpath, light found through boundaries after the last vertex
            // still counts; path's shadow rays stop at them.)
            if ((bounces >= maxDepth_ && !media) || ++passThroughs > 256) break;
            if (pending.active()) pending.target += pending.weight * emitted;
            if (media) pm.medium = si.mediumAfter(ray.d, pm.medium);
            ray.o = spawnOrigin(si, ray.d, originScale_);
            --bounces;
            continue;
        }
        if (bounces >= maxDepth_ && !pending.active()) break;
        bsdf.clear();
        scene_.materials[size_t(si.material)]->computeBSDF(si, sampler.get1D(), &bsdf);
        // Lobe counts, in one pass: all lobes, the non-specular and the diffuse ones.
        const BSDF::LobeCounts lobeCounts = bsdf.lobeCounts();
        const int lobes = lobeCounts.all;
        const int smoothLobes = lobeCounts.smooth;
        const bool canGuide = field && guidable(lobeCounts);
        int region = -1;
        if (canGuide && wantsRegion) {
            Vec3 nFacing = glm::dot(si.ns, si.wo) >= 0.f ? si.ns : -si.ns;
            region = field->lookupPatch(patch, si.p, nFacing);
        }
        const bool lastVertex = bounces >= maxDepth_;
        // The guide's probability here: mix x the region's confidence x the diffuse share.
        const float share =
            region >= 0 && guide_.mix > 0.f && !lastDirection ? diffuseShare(lobeCounts) : 0.f;
        const int sampleRegion = share > 0.f ? region : -1;
        VertexGuide vertexGuide{sampleRegion, share};
        // Next-event estimation at non-specular vertices (first: its shadow ray gives the
        // guide's prefetch of the region's tables time to land).
        if (!lastVertex) {
            ++stats.vertices;
            if (smoothLobes > 0)
                L += beta * sampleLight(si, bsdf, vertexGuide, sampler, stats,
                                        media ? &pm : nullptr);
        }
        // Eq. 1 target for the previous guided vertex: Le(y) + the learned light scattered at
        // y, carried unchanged through delta vertices.
        bool deferTarget = false;
        if (learn && pending.active()) {
            float scattered = region >= 0 ? scatteredTarget(si, bsdf, region, si.wo) : 0.f;
            if (region >= 0 && scattered < 0.f && !lastVertex)
                deferTarget = true;  // completed below with the direction sampled at y
            else if (region >= 0)
                flush(emitted + std::max(scattered, 0.f));
            else if (canGuide || lobes == 0)
                pending = PendingRecord();  // no data at y: nothing to learn from
            else
                pending.target += pending.weight * emitted;  // delta y: continue the chain
        }
        if (lastVertex) break;
        // Sample the next direction (the guiding seam).
        DirectionSample ds = sampleDirection(si, bsdf, vertexGuide, sampler);
        if (deferTarget) {
            // One-sample estimate of the Eq. 1 sum: Q(y, w') f(w') cos / pdf(w').
            float est = 0.f;
            if (ds.pdf > 0.f && !ds.transmission)
                est = field->radiance(region, ds.wi, ds.bin) * luminance(ds.f) *
                      std::abs(glm::dot(ds.wi, si.ns)) / ds.pdf;
            flush(emitted + (std::isfinite(est) ? est : 0.f));
        }
        if (!(ds.pdf > 0.f) || isBlack(ds.f)) break;
        pushSelection(sampleRegion, ds);
        Spectrum weight = ds.f * std::abs(glm::dot(ds.wi, si.ns)) / ds.pdf;
        beta *= weight;
        dirPdf = ds.pdf;
        specularBounce = ds.specular;
        pushReturn(ds.transmission || lastDirection ? -1 : region, ds.wi, ds.bin);
        if (learn) {
            if (bootstrap && region >= 0 && !ds.transmission) {
                pending = PendingRecord();
                pending.region = region;
                pending.w = ds.wi;
                pending.bin = ds.bin;
            } else if (pending.active() && region < 0 && !canGuide) {
                pending.weight *= luminance(weight);  // through a delta vertex
            } else {
                pending = PendingRecord();
            }
        }
        if (ds.specular && ds.transmission) {
            float eta = bsdf.eta();
            etaScale *= glm::dot(si.wo, si.ng) > 0.f ? eta * eta : 1.f / (eta * eta);
        }
        prev = LightSampleContext{si.p, si.ng};
        if (media) pm.medium = si.mediumAfter(ds.wi, pm.medium);
        ray.o = spawnOrigin(si, ds.wi, originScale_);
        ray.d = ds.wi;
        ray.tMax = Infinity;
        if (!isFinite(beta)) break;
        // From the second vertex on: roulette on the expected contribution where the guide
        // knows it.
        if (guide_.adjointRoulette && bounces >= kRouletteFirstBounce && pixelEstimate > 0.f &&
            sampleRegion >= 0 && !ds.transmission &&
            guideConfidence(vertexGuide) >= kRouletteConfidence) {
            const float expected =
                luminance(beta) * field->policyRadiance(sampleRegion, ds.wi, ds.bin);
            const float low = guide_.rouletteWindow * pixelEstimate;
            if (expected < low) {
                const float survive = std::max(expected / low, kMinSurvival);
                if (sampler.get1D() >= survive) break;
                beta /= survive;
            }
            continue;
        }
        if (!pbrtRoulette(&beta, etaScale, bounces, sampler)) break;
    }
    for (int i = 0; i < numRet; ++i) {
        const ReturnVertex& v = retVerts[i];
        const Spectrum d = L - v.L;
        Spectrum li(0.f);
        for (int c = 0; c < 3; ++c) li[c] = v.beta[c] > 0.f ? d[c] / v.beta[c] : 0.f;
        field->record(slot, v.region, v.w, std::max(luminance(li), 0.f), v.bin);
    }
    if (numSelVerts > 0) {
        const float lumL = luminance(L);
        for (int i = 0; i < numSelVerts; ++i) {
            SelectionVertex& v = selVerts.v[i];
            v.s.integrand = (lumL - v.lumL) / v.lumBeta * v.s.pdf;
            field->recordSelection(slot, v.region, v.s);
        }
    }
    return L;
}

}  // namespace rlpbrt
