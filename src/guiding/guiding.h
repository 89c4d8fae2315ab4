// The guiding layer's interface: a learned incident-radiance field that a path integrator
// queries per vertex (lookup, sample, pdf), feeds with training targets (record) and updates
// between passes (endPass), after Dahm & Keller 2017, "Learning Light Transport the
// Reinforced Way". Backends are created by name through createGuidingField, the only place
// that names them. Depends on the standard library, GLM, TBB and (in vdb.cpp only) OpenVDB.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rlpbrt::guiding {

// Configuration from --guide=NAME and repeated --guide-param key=value.
struct GuideConfig {
    std::string backend = "none";
    std::map<std::string, std::string> params;
};

// What the field may know of the scene: its bounds and a way to draw points uniformly over
// the scene's surface area (u in [0,1)^3 -> point and unit geometric normal; false if the
// scene has no surface). Nothing else (no materials, no render types).
struct SceneInfo {
    glm::vec3 boundsMin{0.f}, boundsMax{0.f};
    double totalArea = 0.0;  // total surface area in scene units squared
    std::function<bool(const glm::vec3& u, glm::vec3* p, glm::vec3* n)> samplePoint;
    // A box bounding where the scene's participating media can scatter light (empty,
    // mediaMin > mediaMax, for a scene without media): backends that guide at medium
    // vertices place their volume cells in it.
    glm::vec3 mediaMin{1.f}, mediaMax{0.f};
    bool hasMedia() const {
        return mediaMin.x <= mediaMax.x && mediaMin.y <= mediaMax.y && mediaMin.z <= mediaMax.z;
    }
};

// Counters of the learning process, cumulative over all passes.
struct GuidingStats {
    uint64_t mediumCells = 0;       // volume cells (medium vertices' tables) in use
    uint64_t passes = 0;            // completed endPass() calls
    uint64_t records = 0;           // targets applied to the field
    uint64_t rejectedTargets = 0;   // NaN, Inf or negative targets dropped by record()
    uint64_t rejectedRecords = 0;   // bad slot/region or direction outside the hemisphere
    uint64_t activeVoxels = 0;      // vdb backend: active voxels of the grid (0 otherwise)
    uint64_t learnedRegions = 0;    // regions with tables of their own (hemi, vdb surfaces)
    uint64_t cappedRegions = 0;     // of those, regions that stopped learning (learn-cap)
    uint64_t prunedRegions = 0;     // regions that sample the BSDF only (prune)
    uint64_t selectionRegions = 0;  // regions with a learned selection (mix=learn)
    double selectionMean = 0.0;     // their mean selection probability
};

// How the integrator drew a direction x at a region, for learning the region's selection
// probability (GuidingField::selection, guiding/selection.h): it took the guide with
// probability c * scale (c the selection in force, scale the region's confidence times the
// BSDF's diffuse share), else the BSDF or phase function, whose pdfs at x are pGuide and
// pOther; pdf = the mixture's pdf of x; integrand = the estimate of f cos Li at x that the
// path delivered (its contribution after x times pdf; luminance).
struct SelectionSample {
    float integrand = 0.f;
    float pdf = 0.f;
    float pGuide = 0.f;
    float pOther = 0.f;
    float scale = 0.f;
};

// Sums flat arrays element-wise over all the processes that learn one field together (the
// ranks of a distributed render), leaving the same sums, bit for bit, in every process's
// array. Every process makes the same calls in the same order with arrays of the same sizes.
// The guiding layer knows no more of the processes than this.
struct SumAcrossProcesses {
    // Doubles, added in a fixed order of the processes.
    std::function<void(std::vector<double>&)> doubles;
    // Counts: exact, so the order does not matter; every element's total over the processes
    // must stay below countLimit (the caller checks, and sends larger counts as doubles;
    // half the bytes of doubles).
    std::function<void(std::vector<uint32_t>&)> counts;
    double countLimit = 4294967296.0;  // 2^32
    // Bytes: every process's, concatenated in process order, in every process's string (the
    // spot lobes' candidates, whose number differs between processes).
    std::function<void(std::string&)> gather;
    void operator()(std::vector<double>& v) const { doubles(v); }
    // Sums counts whose totals over the processes are at most `bound`: through `counts` when
    // bound < countLimit, else as doubles (exact below 2^53).
    void sumCounts(std::vector<uint64_t>& v, double bound) const;
};

class GuidingField;
class VertexGuide;
class TrainingSlot;

// What a path vertex asks the field: a surface vertex at p whose hemisphere of interest is
// around unit normal n (the integrator passes the shading normal flipped to wo's side), or a
// scattering vertex inside a participating medium, whose directions cover the whole sphere.
// patch is a hint (setPatches): the surface piece the vertex lies on, or kNoPatch.
struct VertexQuery {
    static constexpr uint32_t kNoPatch = UINT32_MAX;
    glm::vec3 p{0.f};
    glm::vec3 n{0.f};
    uint32_t patch = kNoPatch;
    bool medium = false;
    static VertexQuery surface(const glm::vec3& p, const glm::vec3& n,
                               uint32_t patch = kNoPatch) {
        return VertexQuery{p, n, patch, false};
    }
    static VertexQuery inMedium(const glm::vec3& p) {
        return VertexQuery{p, glm::vec3(0.f), kNoPatch, true};
    }
};

// A learned directional distribution per spatial region: the field learns (beginPass,
// records through its slots, endPass), saves and reports; per vertex it answers with a region
// (locate), which the integrator reads through a VertexGuide (sample, pdf, radiance).
// locate/sample/pdf/scatteredEstimate/irradianceEstimate are const and thread-safe; they read
// the policy frozen at the last endPass() and must not run concurrently with endPass().
// record() is thread-safe across distinct slots.
class GuidingField {
public:
    virtual ~GuidingField();

    // ---- Per vertex.
    // The region for a vertex; -1 = no data there: use the BSDF (or the phase function). A
    // backend that guides on surfaces only answers -1 to medium queries.
    virtual int locate(const VertexQuery& q) const = 0;
    // Whether locate() can find a region for a medium vertex at all (false: the integrator
    // skips the lookup, the medium request and the guide's sample dimension at every medium
    // vertex). Default: false.
    virtual bool guidesMedia() const;
    // A hint that locate(q) follows soon (q.p and q.patch are set, q.n may not be yet): a
    // backend may start loading what it will read. No effect on results. Default: nothing.
    virtual void prefetch(const VertexQuery& q) const;
    // The guide at a vertex.
    VertexGuide guide(const VertexQuery& q) const;
    // locate() for a surface vertex (with its patch) or a medium vertex.
    int lookup(const glm::vec3& p, const glm::vec3& n) const {
        return locate(VertexQuery::surface(p, n));
    }
    int lookupPatch(uint32_t patch, const glm::vec3& p, const glm::vec3& n) const {
        return locate(VertexQuery::surface(p, n, patch));
    }
    int lookupMedium(const glm::vec3& p) const { return locate(VertexQuery::inMedium(p)); }

    // Surface patches, a hint the field may use: the integrator may cut the scene's surfaces
    // into small pieces named by keys in [0, count) (render/patches.h) and pass each vertex's
    // key in VertexQuery::patch, which a backend may answer from a memo per piece instead of
    // a spatial search (where the piece's region is admissible for n). patchSize(): the piece
    // size the backend wants, in world units (0, the default: it uses none). setPatches(count,
    // centre): centre(i, &p, &n) gives a point of piece i and its unit normal (either
    // orientation; false or a zero normal: unknown); called before rendering, and centre must
    // stay valid and thread-safe for the field's life. Default: ignored.
    static constexpr uint32_t kNoPatch = VertexQuery::kNoPatch;
    virtual float patchSize() const;
    virtual void setPatches(uint32_t count,
                            std::function<bool(uint32_t, glm::vec3*, glm::vec3*)> centre);

    // ---- The policy of a region (what VertexGuide reads). Every call accepts -1 (an
    // invalid region) and medium regions.
    // Samples a unit world direction from the frozen policy of `region`; all values in [0,1).
    // u places the direction: a backend with a table of strata picks the stratum and the
    // position in it from u alone, continuously (sampleStrataCdf2D), so that the sampler's
    // 2D stratification carries over to the directions; uPick chooses among the parts of a
    // mixture (hemi's spot lobes) or a tree's leaf (directions=tree). *pdf is per steradian
    // and equals pdf(region, result) (> 0 for a valid region; 0 and a zero vector for an
    // invalid one). *bin (if given) receives the result's bin, as pdf() does.
    virtual glm::vec3 sample(int region, glm::vec2 u, float uPick, float* pdf,
                             int* bin = nullptr) const = 0;
    // Solid-angle pdf of sample() for any world direction (0 outside the region's hemisphere
    // and for an invalid region); w need not be normalised. *bin (if given) receives w's bin
    // in the region (its stratum; -1 outside): a token that record() and radiance() accept
    // for the same region and w instead of finding the bin again.
    virtual float pdf(int region, const glm::vec3& w, int* bin = nullptr) const = 0;
    // sample() and pdf() for a vertex at x in the region: a backend whose distribution
    // depends on the vertex's position (hemi's spot lobes aim at points) answers here; the
    // defaults are sample() and pdf(). VertexGuide calls these.
    virtual glm::vec3 sampleAt(int region, const glm::vec3& x, glm::vec2 u, float uPick,
                               float* pdf, int* bin = nullptr) const;
    virtual float pdfAt(int region, const glm::vec3& x, const glm::vec3& w,
                        int* bin = nullptr) const;
    // The bootstrap part of Eq. 1 at a region y: (2pi/n) * sum_j Q(y,j) * fcos(w_j), where
    // fcos(world dir) returns f_s(w_j, y, -w) * max(0, cos) as a scalar (luminance). w_j are
    // the unit world directions of the stratum centres. Non-finite or negative fcos values
    // count as 0; the result is finite and >= 0 (0 for an invalid region).
    virtual float scatteredEstimate(int region,
                                    const std::function<float(const glm::vec3&)>& fcos) const = 0;
    // The irradiance estimate at a region for a unit shading normal n, so a Lambertian y of
    // albedo rho has scattered = rho / pi * this: (2pi/n) * sum_j Q(y,j) * max(0, dot(w_j, n))
    // by default (scatteredEstimate with fcos = max(0, dot(w, n)), without the callbacks). A
    // backend may return a cheaper estimate that is exact for n = the region's normal: hemi
    // returns max(0, dot(M, n)) with the precomputed moment M = (2pi/n) sum_j Q(y,j) w_j.
    virtual float irradianceEstimate(int region, const glm::vec3& n) const;
    // The learned incident radiance Q(region, stratum of w) (0 for an invalid region or a
    // direction outside the region's hemisphere): for one-sample estimates of the Eq. 1 sum.
    // bin: w's bin from pdf()/sample() for this region, or -1 (found from w).
    virtual float radiance(int region, const glm::vec3& w, int bin = -1) const = 0;
    // radiance(region, w, bin) as far as the frozen policy alone tells it (the data sample()
    // and pdf() read for the same region and w), for per-vertex decisions that need no exact
    // Q, such as the integrator's roulette: a backend may answer it without loading its
    // estimates. Finite and >= 0. Default: radiance().
    virtual float policyRadiance(int region, const glm::vec3& w, int bin = -1) const;

    // How far the policy of `region` is trusted, in [0, 1] (0 for an invalid region): the
    // integrator multiplies its guide/BSDF mixture probability by it, so regions with little
    // data sample mostly the BSDF. Frozen between passes like the policy. Default: 1.
    virtual float confidence(int region) const;
    // Whether `region` still learns: false once it holds the records the field's learn-cap
    // asks for (its guide then stays as learned, and record() and recordSpot() ignore it),
    // so that the integrator can skip the training work of its vertices. Frozen between
    // passes like the policy. Default: true.
    virtual bool learns(int region) const;
    // Whether the integrator samples directions from `region`'s guide at all: false where
    // the field judges its learned light too even to gain over the BSDF (the vertex then
    // takes the BSDF's sample alone and needs no guide pdf). Frozen between passes like the
    // policy. Default: true.
    virtual bool guides(int region) const;
    // Whether the field may still change a path: false where no region guides, learns or
    // chooses anything any more (the integrator then skips the field: plain path tracing).
    // Frozen between passes like the policy. Default: true.
    virtual bool active() const { return true; }

    // The learned probability of choosing the guide over the BSDF (or phase function) at a
    // region, frozen per pass like the policy, or -1 where none has been learned (the
    // integrator then uses its mix setting). Default: -1.
    virtual float selection(int region) const;

    // ---- Learned choices (the integrator's light selection for next-event estimation): a
    // field may learn, per region, the mean value each of n options found (the light a shadow
    // ray went to, and the contribution it brought: zero where the light was hidden) and
    // answer with a distribution proportional to the means, frozen per pass like the policy.
    // Enables n options (2..kMaxChoices), before the first beginPass; false where the backend
    // does not learn choices (the default).
    static constexpr int kMaxChoices = 64;
    virtual bool enableChoices(int n);
    // The learned distribution of `region`: a CDF of n + 1 floats (cdf[0] = 0, cdf[n] = 1)
    // and how far it is trusted (weight in (0, 1], growing with the region's records), or
    // {nullptr, 0} where the region has none yet (or choices are off); and whether the region
    // still learns (takes recordChoice's records: a region stops once it holds enough).
    // Default: none, not learning.
    struct Choice {
        const float* cdf = nullptr;
        float weight = 0.f;
        bool learning = false;
    };
    virtual Choice choice(int region) const;
    // Records that at `region` option k found `value` (luminance, >= 0 and finite, else
    // counted as rejected); thread-safe across slots like record(). Default: ignored.
    virtual void recordChoice(int slot, int region, int k, float value);

    // ---- Learning: through TrainingSlot, one per work item (film tile).
    TrainingSlot slot(int index);
    // Learning: during a pass, record that from `region` the direction w received target T
    // (the radiance the direction brought back along the path, or Eq. 1's T = Le +
    // scatteredEstimate at the next vertex, or the environment radiance). `slot` is
    // the caller's work-item index (film tile) in [0, numSlots): records are merged in slot
    // order at endPass() so results do not depend on thread scheduling. Thread-safe across
    // slots; one thread at a time per slot.
    virtual void beginPass(int numSlots) = 0;
    // Records one target (radiance, luminance); rejected if not finite or negative. bin: w's
    // bin from pdf()/sample() for this region, or -1 (found from w).
    virtual void record(int slot, int region, const glm::vec3& w, float target,
                        int bin = -1) = 0;
    // Records that direction w, sampled at the vertex x of `region`, reached the next vertex
    // at `hit`, where it found `light` (luminance: the emission and next-event estimation
    // there, as the estimator weighted them). For backends that learn small bright sources
    // (hemi's spots); thread-safe across slots like record(). Default: ignored.
    virtual void recordSpot(int slot, int region, const glm::vec3& x, const glm::vec3& w,
                            const glm::vec3& hit, float light, int bin = -1);
    // Whether recordSpot is used (the integrator then reports the next vertices). Default:
    // false.
    virtual bool learnsSpots() const;
    // Asks the field to model the medium around p (a medium vertex where locate found no
    // data) from the next pass on. Thread-safe across slots, like record(). Default: ignored.
    virtual void requestMedium(int slot, const glm::vec3& p);
    // Records how a direction was drawn at `region` and what it brought (SelectionSample),
    // for learning selection(); thread-safe across slots like record(). Default: ignored.
    virtual void recordSelection(int slot, int region, const SelectionSample& s);
    // Applies the recorded targets (a running mean per stratum: alpha = 1/(1+visits) by
    // default, or a fixed alpha) and rebuilds the CDFs.
    virtual void endPass() = 0;
    // endPass() for a field that several processes learn together: each recorded the slots
    // of its own work items (the others' slots are empty here). The pass statistics of the
    // slots (per stratum the sum of the targets and their count, the selection sums, the
    // medium requests) go through `sum` as flat arrays and are applied alike, so every
    // process ends the pass with the same field, and one that learned all the records alone
    // would differ only by the order of floating-point sums. The default applies this
    // process's records only (endPass()).
    virtual void endPassShared(const SumAcrossProcesses& sum);
    // Whether endPassShared shares everything the field learns (false: the processes' fields
    // would drift apart, so a distributed render refuses the field). Default: false.
    virtual bool sharesPasses() const;

    // ---- Reporting and saving.
    // Memory of the learned data in bytes (tables, CDFs, points, kd-tree; not the per-pass
    // record buffers).
    virtual size_t bytes() const = 0;
    // One line for logs: points, strata, parameters, memory, counters.
    virtual std::string describe() const = 0;
    // Learning counters (cumulative).
    virtual GuidingStats stats() const = 0;

    // Saves the learned field (Q, visits, counters and the scene fingerprint) to `path`;
    // false and *error on failure. Formats: docs/GUIDE_FILES.md. The default: unsupported.
    virtual bool save(const std::string& path, std::string* error) const;
    // Replaces the learned state with the one saved in `path` and rebuilds the policy, so a
    // render starts trained (pdf() equals the saved field's). The file must come from the
    // same backend, the same scene (bounds, total area) and the same structure (points or
    // voxel size, strata); otherwise false, *error says why, and the field is unchanged.
    virtual bool load(const std::string& path, std::string* error);

    // ---- Resuming a render (render/resume.h): the complete learning state, between passes.
    // saveState gives, as bytes, what save() writes and what a saved field leaves out (the
    // learned selections of mix=learn), so that a field of the same backend, parameters and
    // scene that restores it with loadState answers every query as this one does and learns
    // on alike: a resumed render continues as the uninterrupted one would. loadState checks
    // what load() checks; on failure (false, *error says why) the field is unspecified and
    // the caller must not render with it. Default: unsupported.
    virtual bool saveState(std::string* state, std::string* error) const;
    virtual bool loadState(const std::string& state, std::string* error);
};

// The guide at one vertex: the field's region there (GuidingField::guide), and what the
// integrator reads of it. A small value; invalid (region -1) where the field has no data.
// bin: a direction's bin in the region, reported by sample() and pdf() (hemi and vdb: its
// stratum), which radiance(), policyRadiance() and TrainingSlot::record() accept for the
// same direction instead of finding it again (-1: found from w).
class VertexGuide {
public:
    VertexGuide() = default;
    VertexGuide(const GuidingField* field, int region, const glm::vec3& p = glm::vec3(0.f))
        : field_(field), region_(region), p_(p) {}
    bool valid() const { return region_ >= 0; }
    int region() const { return region_; }
    // The vertex's position (the query's p).
    const glm::vec3& position() const { return p_; }
    // How far the region's policy is trusted, in [0, 1].
    float confidence() const { return field_->confidence(region_); }
    // GuidingField::learns for the region.
    bool learns() const { return field_->learns(region_); }
    // GuidingField::guides for the region.
    bool guides() const { return field_->guides(region_); }
    // The learned probability of choosing the guide, or -1 where none is learned.
    float selection() const { return field_->selection(region_); }
    // GuidingField::choice for the region (none for an invalid guide).
    GuidingField::Choice choice() const {
        return field_ ? field_->choice(region_) : GuidingField::Choice();
    }
    glm::vec3 sample(glm::vec2 u, float uPick, float* pdf, int* bin = nullptr) const {
        return field_->sampleAt(region_, p_, u, uPick, pdf, bin);
    }
    float pdf(const glm::vec3& w, int* bin = nullptr) const {
        return field_->pdfAt(region_, p_, w, bin);
    }
    float radiance(const glm::vec3& w, int bin = -1) const {
        return field_->radiance(region_, w, bin);
    }
    float policyRadiance(const glm::vec3& w, int bin = -1) const {
        return field_->policyRadiance(region_, w, bin);
    }
    float irradianceEstimate(const glm::vec3& n) const {
        return field_->irradianceEstimate(region_, n);
    }
    float scatteredEstimate(const std::function<float(const glm::vec3&)>& fcos) const {
        return field_->scatteredEstimate(region_, fcos);
    }

private:
    const GuidingField* field_ = nullptr;
    int region_ = -1;
    glm::vec3 p_{0.f};
};

// One work item's (film tile's) training slot of a field during a pass: records go to the
// slot without a lock and are merged in slot order at endPass(). One thread at a time.
class TrainingSlot {
public:
    TrainingSlot() = default;
    TrainingSlot(GuidingField* field, int slot) : field_(field), slot_(slot) {}
    // Target T (luminance) for direction w at the vertex of `guide` (GuidingField::record).
    void record(const VertexGuide& guide, const glm::vec3& w, float target, int bin = -1) {
        field_->record(slot_, guide.region(), w, target, bin);
    }
    // Option k found `value` at the vertex of `guide` (GuidingField::recordChoice).
    void recordChoice(const VertexGuide& guide, int k, float value) {
        field_->recordChoice(slot_, guide.region(), k, value);
    }
    // Direction w of the vertex of `guide` reached `hit`, which gave `light`
    // (GuidingField::recordSpot).
    void recordSpot(const VertexGuide& guide, const glm::vec3& w, const glm::vec3& hit,
                    float light, int bin = -1) {
        field_->recordSpot(slot_, guide.region(), guide.position(), w, hit, light, bin);
    }
    void recordSelection(const VertexGuide& guide, const SelectionSample& s) {
        field_->recordSelection(slot_, guide.region(), s);
    }
    void requestMedium(const glm::vec3& p) { field_->requestMedium(slot_, p); }

private:
    GuidingField* field_ = nullptr;
    int slot_ = 0;
};

inline VertexGuide GuidingField::guide(const VertexQuery& q) const {
    return VertexGuide(this, locate(q), q.p);
}
inline TrainingSlot GuidingField::slot(int index) { return TrainingSlot(this, index); }

// The factory: the only place that names backends. "none" returns nullptr with *error empty
// (parameters are ignored). Unknown backend or parameter, or a bad value => nullptr and a
// message in *error. The keys each backend takes, their defaults and accepted values are the
// one table of guiding/options.h (`rlpbrt --guide-options`; docs/GUIDING.md says what each
// does and the measurement behind its default). Keys owned by the integrator (mix, target,
// samples, auto, rr, rr-window, learn) are accepted and ignored here.
std::unique_ptr<GuidingField> createGuidingField(const GuideConfig& config,
                                                 const SceneInfo& scene, std::string* error);

}  // namespace rlpbrt::guiding
