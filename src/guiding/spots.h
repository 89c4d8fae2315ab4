// Spot lobes: small bright sources that a region's strata are far too coarse for, learned
// per region as narrow von Mises-Fisher lobes (docs/GUIDING.md, "spots"). A spot is where a
// direction sampled at the region found, at the very next vertex, far more light than its
// stratum's learned estimate: typically a highlight of the sun on a near-specular surface,
// whose reflected light reaches the region only through a cone much smaller than a stratum.
// Each lobe is aimed either at a point (the spot's mean position: the direction then depends
// on the vertex, parallax-aware, right for curved highlights) or along a fixed direction (a
// flat mirror's reflected sun), whichever the records fit better; its width is fitted to the
// records' spread. Standard library, GLM and the guide files' byte format (field_io.h);
// knows nothing of the strata or the scene.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rlpbrt::guiding {

struct SpotSettings {
    int perRegion = 4;        // lobes per region
    double maxShare = 0.5;    // the largest probability of the lobes within the guide
    double outlier = 5.0;     // a record is a spot candidate above outlier x its stratum's Q
    // A lobe samples only while narrower than this concentration. The field sets it to its
    // strata count: a von Mises-Fisher lobe of concentration kappa spreads over about
    // 2 pi / kappa steradians, a hemisphere's stratum covers 2 pi / strata, so a wider lobe
    // only repeats what the strata learn (and costs a density evaluation at every vertex).
    float minKappa = 0.f;
};

// The von Mises-Fisher distribution on the sphere around unit `mean` with concentration
// kappa > 0: density kappa / (2 pi (1 - e^(-2 kappa))) e^(kappa (cos - 1)).
float vmfPdf(float kappa, float cosTheta);
glm::vec3 vmfSample(const glm::vec3& mean, float kappa, glm::vec2 u);

class SpotLobes {
public:
    void reset(size_t regions, const SpotSettings& settings);
    size_t regions() const { return share_.size(); }
    const SpotSettings& settings() const { return settings_; }

    // What a region's active lobes are worth: the sum over them of (the lobe's light / the
    // region's) x kappa / minKappa, i.e. their light weighted by how many times narrower
    // than a stratum each is (about the factor by which the strata alone would raise the
    // second moment of that light); 0 without active lobes. Set when the lobes are refitted.
    float worth(int region) const {
        return region >= 0 && size_t(region) < worth_.size() ? worth_[size_t(region)] : 0.f;
    }
    // setSilenced(true) stops every region's lobes for good (the field's verdict,
    // HemiParams::spotJudge): no lobe samples or has a density from now on, refits included;
    // what they learned stays (and is saved) as it is. setSilenced(false) lets the next
    // refit decide again (a field loaded from a file).
    void setSilenced(bool silenced);
    bool silenced() const { return silenced_; }
    // The probability of sampling the lobes at a region (0: none there). Frozen per pass.
    float share(int region) const {
        return region >= 0 && size_t(region) < share_.size() ? share_[size_t(region)] : 0.f;
    }
    // Starts loading a region's lobes (a hint).
    void prefetch(int region) const {
        if (region >= 0 && size_t(region) < activeCount_.size() && activeCount_[size_t(region)])
            __builtin_prefetch(activeOf(size_t(region)));
    }
    // A direction from the lobes of `region` seen from x (share(region) > 0), u and uLobe in
    // [0, 1); its density is pdf(region, x, w).
    glm::vec3 sample(int region, const glm::vec3& x, glm::vec2 u, float uLobe) const;
    // The lobes' solid-angle density at unit w seen from x (the lobes' mixture, weights
    // normalised; 0 where share(region) is 0).
    float pdf(int region, const glm::vec3& x, const glm::vec3& w) const;

    // Learning. A candidate: at a vertex x of `region`, unit direction w reached `hit`, whose
    // light (emission and next-event estimation there, luminance) was `light`, against the
    // estimate `reference` of w's stratum. Kept if light > outlier x reference. Thread-safe
    // across slots.
    void beginPass(int numSlots);
    void record(int slot, int region, const glm::vec3& x, const glm::vec3& w,
                const glm::vec3& hit, float light, float reference);
    // Merges the candidates in slot order and refits the lobes; regionTotal(r) gives the sum
    // of every target region r has learned (its strata's Q x visits), against which the
    // lobes' share is set.
    template <class Total>
    void endPass(Total&& regionTotal) {
        mergeCandidates();
        refitAll(regionTotal);
    }
    // Refits every region's lobes from what they have learned (endPass's second half; after
    // read()).
    template <class Total>
    void refitAll(Total&& regionTotal) {
        for (size_t r = 0; r < share_.size(); ++r)
            if (lobeCount_[r] > 0) refit(r, regionTotal(r));
    }

    // Several processes learning one set of lobes (GuidingField::endPassShared): each takes
    // its pass's candidates as bytes (the slots emptied), the processes concatenate their
    // bytes in process order, and each puts the whole back before endPass. A slot's
    // candidates stay in their order, and endPass merges the slots in slot order: where each
    // slot is recorded by one process (a tile is one rank's), the lobes are those of one
    // process that recorded every slot.
    std::string takeCandidates();
    // False (nothing added) if the bytes are not takeCandidates' of this configuration.
    bool putCandidates(const std::string& bytes);

    // The lobes' learned state (their accumulators and last fits) as bytes, and its restoring
    // (then refitAll). read() fails, with *why, on bytes of another number of regions or
    // lobes per region, or corrupt ones, and then leaves the lobes empty.
    std::string write() const;
    bool read(const std::string& bytes, std::string* why);

    size_t bytes() const;
    // Regions with at least one active lobe, and active lobes in all.
    size_t activeRegions() const;
    size_t activeLobes() const;

private:
    // What a lobe learns, accumulated over passes (weighted by the candidates' light), and
    // its parameters as of the last endPass (for matching candidates).
    struct Lobe {
        glm::vec3 point{0.f};  // mean hit point
        glm::vec3 dir{0.f};    // mean direction (unit)
        float kappa = 0.f;     // 0: not active yet
        double sumLight = 0.0;
        glm::dvec3 sumPoint{0.0}, sumDir{0.0};
        double sumErrPoint = 0.0, sumErrDir = 0.0;
        uint32_t hits = 0;
    };
    // What sampling and pdf read, frozen per pass: a region's active lobes, packed (two to a
    // cache line).
    struct Active {
        glm::vec3 axis{0.f};  // the point aimed at, or the direction
        float kappa = 0.f;
        float norm = 0.f;     // weight x kappa / (2 pi (1 - e^-2kappa))
        float cumWeight = 0.f;  // the selection CDF up to this lobe
        uint32_t aimsAtPoint = 0;
        float cosCut = -2.f;  // below this cosine to the lobe its density is skipped (pdf)
    };
    struct Candidate {
        uint32_t region;
        glm::vec3 x, w, hit;
        float light;
    };
    // The lobe's direction seen from x (unit; the last fitted direction `fallback` if x is
    // at its point).
    static glm::vec3 lobeDirection(const Active& a, const glm::vec3& x);
    void mergeCandidates();
    void refit(size_t region, double regionTotal);

    SpotSettings settings_;
    // A region's perRegion lobes and actives, allocated with its first candidate: memory
    // only where spots were found (block_: the region's block of lobes_ and active_).
    static constexpr uint32_t kNoBlock = UINT32_MAX;
    Lobe* lobesOf(size_t region) {
        return &lobes_[size_t(block_[region]) * size_t(settings_.perRegion)];
    }
    const Lobe* lobesOf(size_t region) const {
        return &lobes_[size_t(block_[region]) * size_t(settings_.perRegion)];
    }
    Active* activeOf(size_t region) {
        return &active_[size_t(block_[region]) * size_t(settings_.perRegion)];
    }
    const Active* activeOf(size_t region) const {
        return &active_[size_t(block_[region]) * size_t(settings_.perRegion)];
    }
    void allocate(size_t region);
    std::vector<uint32_t> block_;       // per region, or kNoBlock
    std::vector<Lobe> lobes_;           // blocks x perRegion
    std::vector<uint8_t> lobeCount_;    // used lobes per region
    std::vector<Active> active_;        // blocks x perRegion, the first activeCount_ used
    std::vector<uint8_t> activeCount_;
    std::vector<float> share_;          // frozen per pass
    std::vector<float> worth_;          // per region (worth())
    bool silenced_ = false;
    std::vector<std::vector<Candidate>> slots_;
};

}  // namespace rlpbrt::guiding
