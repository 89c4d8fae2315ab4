// The `hemi` guiding backend (Dahm & Keller 2017): points distributed uniformly over the
// scene surface, two hemispheres per point (around n and -n), each cut into equal-area
// strata holding Q, the learned incident radiance; a kd-tree finds the nearest point with an
// admissible normal. Learning is batched per pass (running mean or fixed alpha) and the
// sampling CDFs are rebuilt between passes.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "guiding/cell_cache.h"
#include "guiding/directional.h"
#include "guiding/guiding.h"
#include "guiding/kdtree.h"
#include "guiding/spots.h"
#include "guiding/strata_table.h"
#include "guiding/tree_table.h"

namespace rlpbrt::guiding {

// Validated parameters of the hemi backend (see createGuidingField for their meaning).
struct HemiParams {
    bool alphaVisits = true;     // alpha = 1/(1 + visits) if true, else fixedAlpha
    double fixedAlpha = 1.0;     // in (0, 1]
    // Defaults and the measurements behind them: docs/GUIDING.md, one row per key.
    // Strata in phi and in cos(theta). 16x16, not the paper's 8x8: a trained 16x16 guide
    // resolves the small bright patches that light indirectly lit scenes.
    int cols = 16, rows = 16;
    // Surface samples (two hemispheres each). Fewer regions learn faster; 1024 since every
    // point is in use with the patch lookup, where 2048 learned slower and 512 lost breakfast.
    uint64_t points = 1024;
    double normalAngleDeg = 30;  // admissible normal deviation
    double init = 1e-3;          // initial Q
    double epsilon = 0.1;        // uniform share of every CDF
    int knn = 8;                 // neighbours checked by lookup
    // Sample strata in proportion to Q_j cos(theta_j) (the cosine to the region normal at the
    // stratum centre) instead of Q_j: the product with the cosine factor of every BSDF's
    // integrand, which sampling by Q alone spends on grazing directions.
    bool cosine = true;
    // Confidence of a region = visits / (visits + warmup * strata): the integrator scales its
    // mixture probability by it, so barely trained regions sample mostly the BSDF.
    double warmup = 8.0;
    // A region stops learning once it holds learnCap records per stratum on average (0:
    // never): its guide stays as learned and its vertices skip the training work, which was
    // most of the guide's cost in long renders of scenes it cannot improve (docs/GUIDING.md).
    double learnCap = 256.0;
    // A learned region samples only the BSDF (no guide, no guide pdf) where the cosine
    // sampling of its learned light already has a relative variance (the second moment of
    // Q cos / cos-pdf over its mean squared, minus 1) of at most prune: there the guide has
    // little to gain and costs its work per vertex. 0: never; regions with spot lobes never,
    // nor with treeDirections. The default 0.3 since session 43 (docs/GUIDING.md, `prune`):
    // error x time per sample 0.93x on buddha-fractal and 0.96x on metal-spheres, equal on
    // caustic-glass at 256 spp but 1.03x at 1024 spp.
    double prune = 0.3;
    // The scene's verdict on direction guiding (0: none): once the learned regions'
    // visit-weighted confidence reaches 0.5, the second moment of the strata's light under
    // the guide's mixture is predicted against cosine sampling's (visit-weighted over the
    // regions, as directionGuidingPays() computes); where the mixture keeps more than judge of
    // it, every region stops guiding and learning directions for good (the verdict is a
    // function of the tables, which then stop changing, so a saved or shared field reaches
    // it again). A field without a learned light choice then changes no path: the
    // integrator skips it (GuidingField::active). The default 0.8 since session 44
    // (docs/GUIDING.md, `judge`): it stops directions on buddha-fractal, metal-spheres, cloud,
    // caustic-glass and conference-room (predicted 0.86-1.0; per sample their direction
    // guiding gains nothing) and on none of the scenes whose guide gains (0.08-0.70).
    double judge = 0.8;
    // The scene's verdict on spot lobes (0: none): once the regions' visit-weighted
    // confidence reaches 0.8 (then after every pass until it fires), the
    // visit-weighted mean over the regions of their lobes' worth (SpotLobes::worth: the
    // lobes' light share x how many times narrower than a stratum they are); below
    // spotJudge every region's lobes stop sampling and learning for good, sparing their
    // density at every vertex (docs/GUIDING.md, `spot-judge`). The default 3 since session
    // 45: at confidence 0.8 the lobes of veach-bidir, breakfast and glossy-lamps are worth
    // 8.5-34 (they gain 1.1-1.6x per sample there) and those of killeroo, cornell-box and
    // door 0.01-0.45 (at most 3% per sample); at 30 s against plain killeroo 1.15 -> 1.03,
    // cornell-box 0.76 -> 0.70, door 0.21 -> 0.22.
    double spotJudge = 3.0;
    // lookup=cell: the knn points nearest to the centre of the query's cell, from a memo
    // filled once per cell (guiding/cell_cache.h; cells as large as the points' mean
    // spacing), are checked for an admissible normal in that order. lookup=exact: the kd-tree
    // query at every vertex, from the vertex itself; the memo costs a third of that and
    // guides as well per sample.
    bool cellLookup = true;
    // lookup=patch (the default): where the integrator names the vertex's surface patch
    // (setPatches: pieces about as large as the cells), the knn points nearest to the patch's
    // centre, memoised per patch, are checked against the patch's normal once; the first
    // admissible one answers the vertex if it is admissible for the vertex's normal too (else,
    // and off patches, the cell memo). A patch's memo is one word, found from the hit without
    // hashing or probing.
    bool patchLookup = true;
    // The integrator's target (the "target" parameter, which it validates): "path" (the
    // default) reads no estimates per vertex; "sample" and "sum" read them for Eq. 1's
    // bootstrap, so that the lookup prefetches them as well.
    bool bootstrapTargets = false;
    // Prior strength, in visits, of the hierarchical smoothing of the strata estimates
    // (StrataTable::setSmoothing over StrataLayout::quadtree): a stratum with few visits
    // borrows the mean of the 2x2, 4x4, ... strata around it instead of keeping init. 0 = off
    // (each stratum its own Q, the paper's). It removes most of the bias of the default
    // samples=sequence (docs/STABILITY.md): an unvisited stratum no longer looks dark, so the
    // samples a pixel's sequence places where its earlier samples did not go do not meet a
    // policy that learned to avoid those directions.
    double smooth = 2.0;
    // directions=tree (issue 30, experimental): each hemisphere's directions are an adaptive
    // quadtree (guiding/tree_table.h) refined where its learned light concentrates, instead
    // of the fixed strata; treeSplit and treeDepth are DirTree::refined's share and depth.
    // strata, smooth and --guide-save do not apply to it.
    bool treeDirections = false;
    double treeSplit = 0.03;
    int treeDepth = 12;
    // Spot lobes per region (0: off; -1: the default, 4 with the strata and 0 with
    // directions=tree; docs/GUIDING.md).
    int spots = -1;
    double spotShare = 0.5;
    double spotOutlier = 5.0;
};

// Estimated bytes of a hemi field with these parameters (tables, CDFs, points, kd-tree).
double hemiEstimatedBytes(const HemiParams& params);

class HemiField final : public GuidingField {
public:
    // Draws params.points surface samples with scene.samplePoint (Halton sequence in bases
    // 2, 3, 5; failed or degenerate samples are skipped) and builds the kd-tree.
    HemiField(const HemiParams& params, const SceneInfo& scene);
    ~HemiField() override;
    // Large tables: not copyable.
    HemiField(const HemiField&) = delete;
    HemiField& operator=(const HemiField&) = delete;

    // A surface vertex's region: the point kept for its patch where that is admissible for
    // n (lookup=patch), else lookupPoint(p, n); -1 in a medium.
    int locate(const VertexQuery& q) const override;
    // The vertex's cell memo entry or, on a patch, the patch's memo word.
    void prefetch(const VertexQuery& q) const override {
        if (q.patch < numPatches_) {
            prefetchLine(&patchPoint_[q.patch]);
        } else if (cache_ && std::isfinite(q.p.x) && std::isfinite(q.p.y) &&
                   std::isfinite(q.p.z)) {
            cache_->prefetch(q.p);
        }
    }
    // The region of the nearest point with an admissible normal for n (through the cell
    // memo, or the kd-tree with lookup=exact), -1 if none.
    int lookupPoint(const glm::vec3& p, const glm::vec3& n) const;
    float patchSize() const override;
    void setPatches(uint32_t count,
                    std::function<bool(uint32_t, glm::vec3*, glm::vec3*)> centre) override;
    glm::vec3 sample(int region, glm::vec2 u, float uPick, float* pdf,
                     int* bin = nullptr) const override;
    float pdf(int region, const glm::vec3& w, int* bin = nullptr) const override;
    glm::vec3 sampleAt(int region, const glm::vec3& x, glm::vec2 u, float uPick,
                       float* pdf, int* bin = nullptr) const override;
    float pdfAt(int region, const glm::vec3& x, const glm::vec3& w,
                int* bin = nullptr) const override;
    void recordSpot(int slot, int region, const glm::vec3& x, const glm::vec3& w,
                    const glm::vec3& hit, float light, int bin = -1) override;
    bool learnsSpots() const override {
        return spots_ != nullptr && !spots_->silenced() && !directionsOff_;
    }
    bool enableChoices(int n) override;
    Choice choice(int region) const override {
        if (!choices_ || !validRegion(region)) return Choice();
        const float w = choiceWeight_[size_t(region)];
        return Choice{w > 0.f ? choices_->cdf(size_t(region)) : nullptr, std::max(w, 0.f),
                      w < kChoiceFullWeight};
    }
    void recordChoice(int slot, int region, int k, float value) override;
    const SpotLobes* spots() const { return spots_.get(); }
    float scatteredEstimate(int region,
                            const std::function<float(const glm::vec3&)>& fcos) const override;
    float irradianceEstimate(int region, const glm::vec3& n) const override;
    float radiance(int region, const glm::vec3& w, int bin = -1) const override;
    // From the stratum's probability in the CDF and the region's policyScale: Q_j = (p_j -
    // epsilon / n) * policyScale / cos_j (cos_j = 1 without the cosine product), equal to
    // radiance() up to the CDF's float rounding, about 1e-7 of the region's cosine-weighted
    // total divided by cos_j. (radiance() with epsilon = 1, where the CDF holds no Q.)
    float policyRadiance(int region, const glm::vec3& w, int bin = -1) const override;
    float confidence(int region) const override;
    // False once the judge (HemiParams::judge) stopped direction guiding in a field without
    // a learned light choice: no region then guides, learns or chooses.
    bool active() const override { return !(directionsOff_ && !choices_); }
    // Whether the judge stopped direction guiding (every region samples the BSDF alone and
    // learns no directions).
    bool directionsOff() const { return directionsOff_; }
    // What the scene verdicts (judgeScene) read from the tables as they are, in one pass over
    // the regions with visits.
    struct SceneMeasures {
        // The judge's prediction: the visit-weighted second moment of the strata's learned
        // light under the guide's mixture (mix 0.5 x confidence where a region guides; a
        // region with spot lobes of share s at most 1 - s of its cosine sampling's) over
        // cosine sampling's, over the regions with learned light; 1 without them.
        double ratio = 1.0;
        // The visit-weighted confidence of the regions with learned light (0 without them).
        double confidence = 0.0;
        // The spot verdict's measure (HemiParams::spotJudge): the visit-weighted mean of
        // every visited region's SpotLobes::worth (0 without spots or visits).
        double spotWorth = 0.0;
    };
    SceneMeasures sceneMeasures() const;
    bool learns(int region) const override {
        return !directionsOff_ && validRegion(region) && frames_[size_t(region)].learns;
    }
    bool guides(int region) const override {
        return !directionsOff_ && validRegion(region) &&
               (frames_[size_t(region)].guides || (spots_ && spots_->share(region) > 0.f));
    }
    float selection(int region) const override;
    void recordSelection(int slot, int region, const SelectionSample& s) override;
    void beginPass(int numSlots) override;
    void record(int slot, int region, const glm::vec3& w, float target,
                int bin = -1) override;
    void endPass() override;
    void endPassShared(const SumAcrossProcesses& sum) override;
    // Not with directions=tree: its adaptive trees are not shared yet.
    bool sharesPasses() const override { return !trees_; }
    size_t bytes() const override;
    std::string describe() const override;
    GuidingStats stats() const override;
    // Little-endian binary file, docs/GUIDE_FILES.md.
    bool save(const std::string& path, std::string* error) const override;
    bool load(const std::string& path, std::string* error) override;
    // The saved field's bytes and the selection learner's state (directions=tree: refused).
    bool saveState(std::string* state, std::string* error) const override;
    bool loadState(const std::string& state, std::string* error) override;

    // Inspection (tests, tools).
    // Bytes of the per-pass record buffers and endPass scratch (not counted in bytes()).
    size_t scratchBytes() const;
    // Regions that have received records and hold tables of their own (the others share the
    // untrained prior's).
    size_t learnedRegions() const {
        return trees_ ? size_t(trees_->stats().learnedRegions) : table_.learnedRegions();
    }
    // Number of regions (hemispheres): twice the number of accepted surface points.
    int numRegions() const { return numRegions_; }
    const StrataLayout& layout() const { return layout_; }
    const HemiParams& params() const { return params_; }
    // The lookup's cell memo (null with lookup=exact, or knn > CellCache::kMaxCandidates).
    const CellCache* cellCache() const { return cache_.get(); }
    // Patches set by setPatches (0 without), and the point a patch's memo holds (-1: none
    // admissible or not filled yet).
    uint32_t numPatches() const { return numPatches_; }
    int patchPoint(uint32_t patch) const {
        if (patch >= numPatches_) return -1;
        const uint32_t v = __atomic_load_n(&patchPoint_[patch], __ATOMIC_RELAXED);
        return v == 0 || v == kNoPoint ? -1 : int(v - 1);
    }
    // Surface position and unit hemisphere normal of a region.
    glm::vec3 regionPosition(int region) const { return positions_[size_t(region) / 2]; }
    glm::vec3 regionNormal(int region) const {
        glm::vec3 n = normals_[size_t(region) / 2];
        return (region & 1) ? -n : n;
    }
    // Stratum of world direction w in a region's hemisphere, -1 outside. Always inlined:
    // pdf() asks it at every guided vertex.
    [[gnu::always_inline]] int stratumOf(int region, const glm::vec3& w) const {
        glm::vec3 unit;
        if (!validRegion(region) || !unitDirection(w, &unit)) return -1;
        return layout_.stratumOf(frames_[size_t(region)].frame.toLocal(unit));
    }
    // The same, given the bin that pdf()/sample() reported for it (-1 or out of range: found
    // from w).
    int stratumOf(int region, const glm::vec3& w, int bin) const {
        return validRegion(region) && bin >= 0 && bin < strata_ ? bin : stratumOf(region, w);
    }
    // Learned Q and visit count of one stratum.
    double q(int region, int stratum) const { return table_.q(size_t(region))[stratum]; }
    uint64_t visits(int region, int stratum) const {
        return table_.visits(size_t(region))[stratum];
    }
    // Raw tables, for bitwise comparisons: Q, visits, CDFs (n + 1 floats per region).
    const std::vector<double>& qTable() const { return table_.qTable(); }
    const std::vector<uint64_t>& visitTable() const { return table_.visitTable(); }
    const std::vector<float>& cdfTable() const { return table_.cdfTable(); }

private:
    // The saved field's bytes (save() writes them to a file), and their loading (`name`
    // names them in messages).
    std::string serialize() const;
    // Whether the field holds what its files cannot (directions=tree, spots); then *error
    // says "hemi with FEATURE ACTION".
    bool refusesSaving(const char* action, std::string* error) const;
    bool loadBytes(const std::string& data, const std::string& name, std::string* error);
    // The CDF of one region from its Q (with the cosine product when params_.cosine).
    void buildPolicy(const double* q, float* cdf) const;
    // The factor of stratum j's Q in the policy: its centre's cosine, or 1 without the cosine
    // product (buildPolicy, and policyRadiance's inverse).
    double policyWeight(int j) const {
        return params_.cosine ? double(layout_.centre(j).z) : 1.0;
    }
    // Starts loading the data the per-vertex queries read for a region; returns region.
    int prefetched(int region) const;
    // Refreshes a region's moment (from its estimates q) and confidence (after a CDF build).
    void updateRegion(int region, const double* q);

    bool validRegion(int region) const { return region >= 0 && region < numRegions(); }
    const float* cdf(int region) const { return table_.cdf(size_t(region)); }
    // The learned choices' policy for n options (their CDF proportional to the means).
    static StrataTable::PolicyBuilder choicesPolicy(int n);
    // Rebuilds a region's CDF, then its moment and confidence (called per updated region,
    // concurrently for distinct regions).
    StrataTable::PolicyBuilder policy() {
        return [this](int region, const double* q, float* c) {
            buildPolicy(q, c);
            if (size_t(region) < frames_.size()) updateRegion(region, q);
        };
    }

    // A bin flag: the direction was drawn from the spot lobes (sampleAt); bins with it are
    // out of the strata's range, so radiance() and policyRadiance() find the stratum again.
    static constexpr int kSpotBin = 1 << 24;
    // The tag of a saved field's spot-lobe section.
    static constexpr uint32_t kSpotsSection = 0x53504f54;  // "SPOT"
    // ... and of its learned choices' section (enableChoices).
    static constexpr uint32_t kChoicesSection = 0x43484f49;  // "CHOI"
    // How far a region's learned choice is trusted: its confidence with kChoiceWarmup records
    // per option (records / (records + warmup x options)), 0 below kChoiceMinWeight: a
    // handful of shadow rays cannot tell a hidden light from an unlucky one.
    static constexpr double kChoiceWarmup = 16.0;
    static constexpr float kChoiceMinWeight = 0.25f;
    // A region stops learning its choice at kChoiceFull records per option (its weight then
    // 1024 / (1024 + 16)): the mean of each light moves little after that, and the records
    // cost the time of a few percent of the render (sorting and merging at every pass).
    static constexpr double kChoiceFull = 1024.0;
    static constexpr float kChoiceFullWeight = float(kChoiceFull / (kChoiceFull + kChoiceWarmup));
    void updateChoiceWeights();

    HemiParams params_;
    StrataLayout layout_;
    glm::vec3 sceneMin_, sceneMax_;  // the scene fingerprint of saved fields
    double sceneArea_;
    int strata_;
    float cosMaxAngle_;
    std::vector<glm::vec3> positions_;  // one per surface sample
    std::vector<glm::vec3> normals_;    // unit geometric normal per surface sample
    int numRegions_ = 0;                // 2 x the points (validRegion on every query)
    std::unique_ptr<PointKdTree> tree_;
    std::unique_ptr<CellCache> cache_;  // lookup=cell only
    std::unique_ptr<SpotLobes> spots_;  // spots > 0 only
    // Learned choices (enableChoices): per region the running mean of each option's value,
    // its CDF proportional to the means.
    std::unique_ptr<StrataTable> choices_;
    std::vector<float> choiceWeight_;  // per region (choice()), set at endPass
    // lookup=patch: per patch 0 (not yet filled), point + 1, or kNoPoint (no admissible
    // point), read and written with relaxed atomics (a fill is a pure function of the patch,
    // so racing fills agree); zeroed pages from calloc, so a large table of patches that no
    // path reaches costs address space only.
    static constexpr uint32_t kNoPoint = UINT32_MAX;
    struct FreeDeleter {
        void operator()(void* p) const { std::free(p); }
    };
    std::unique_ptr<uint32_t[], FreeDeleter> patchPoint_;
    uint32_t numPatches_ = 0;
    std::function<bool(uint32_t, glm::vec3*, glm::vec3*)> patchCentre_;
    // The judge's verdict (HemiParams::judge): direction guiding stopped for good.
    bool directionsOff_ = false;
    // The spot verdict's worth (sceneMeasures().spotWorth when it stopped the lobes), for
    // describe().
    double spotWorthAtVerdict_ = 0.0;
    // Judges directions (judge) and spot lobes (spotJudge) once the regions' confidence
    // suffices (endPass, endPassShared, loads).
    void judgeScene();
    // The memo entry of a patch (kNoPoint if none admissible).
    uint32_t fillPatch(uint32_t patch) const;
    // Of a point's two hemispheres (n, -n), the region on n's side if the point's normal is
    // admissible for n (|dot(n, normal)| >= threshold = cos(normal-angle) * |n|), else -1.
    int admissibleRegion(uint32_t point, const glm::vec3& n, float threshold) const {
        const float c = glm::dot(n, normals_[point]);
        return std::abs(c) >= threshold ? int(point) * 2 + (c >= 0.f ? 0 : 1) : -1;
    }
    // Per region, one cache line: the frame of its hemisphere (z = normal), the moment
    // sum_j Q_j w_j (2pi/n) over the world stratum centres w_j, its confidence, and the scale
    // that turns a stratum's probability back into its Q (policyRadiance).
    struct alignas(64) RegionFrame {
        Frame frame;
        glm::vec3 moment{0.f};
        float confidence = 0.f;   // visits / (visits + warmup * strata), frozen per pass
        float policyScale = 0.f;  // sum_j Q_j cos_j / (1 - epsilon); 0 for a uniform CDF
        bool learns = true;       // below the learn cap (HemiParams::learnCap), frozen per pass
        bool guides = true;       // not pruned (HemiParams::prune), frozen per pass
    };
    std::vector<RegionFrame> frames_;
    // Per stratum, 1 / the cosine factor of the policy (1 without the cosine product), and
    // the uniform share of every stratum's probability, epsilon / n: for policyRadiance.
    std::vector<float> invCosine_;
    float uniformShare_ = 0.f;
    // The integrator reads the estimates at every vertex (target=sample or sum, for Eq. 1's
    // bootstrap; epsilon = 1, where policyRadiance reads them): the lookup prefetches them
    // too. With target=path and epsilon < 1 it reads the CDF only (policyRadiance).
    bool prefetchEstimates_ = false;
    StrataTable table_;              // Q, float Q, visits, CDFs, record buffers, counters
    // directions=tree: the regions' adaptive tables (table_ then keeps only the learned
    // selections of mix=learn).
    std::unique_ptr<TreeTable> trees_;
    // A world direction's point on the square of a region's hemisphere (false: outside).
    bool treePoint(int region, const glm::vec3& w, glm::vec2* a) const {
        glm::vec3 unit;
        if (!validRegion(region) || !unitDirection(w, &unit)) return false;
        return DirTree::hemispherePoint(frames_[size_t(region)].frame.toLocal(unit), a);
    }
    // After the trees' endPass: every learned region's moment and confidence.
    void updateTreeRegions();
    // The sum of every target a region has learned (its strata's Q x visits): the spot
    // lobes' share is set against it.
    double learnedTotal(size_t region) const;
    // learnedTotal as the function SpotLobes' endPass and refitAll take.
    auto learnedTotals() const {
        return [this](size_t region) { return learnedTotal(region); };
    }
    uint64_t attempts_ = 0;  // samplePoint calls made at construction
};

}  // namespace rlpbrt::guiding
