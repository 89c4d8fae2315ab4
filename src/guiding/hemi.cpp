#include "guiding/hemi.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "guiding/field_io.h"

namespace rlpbrt::guiding {

namespace {

bool finite3(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

double hemiEstimatedBytes(const HemiParams& p) {
    const double perRegion = StrataTable::regionBytes(p.cols * p.rows) + 64.0;  // + RegionFrame
    // Per point: position, normal, the tree's copy, its index entry and a share of the nodes,
    // and up to 16 entries of the lookup's cell memo (8, rounded up to a power of two).
    const double perPoint = 3 * sizeof(glm::vec3) + sizeof(uint32_t) + 8.0 +
                            (p.cellLookup ? 16.0 * 64.0 : 0.0);
    return double(p.points) * (2.0 * perRegion + perPoint);
}

HemiField::HemiField(const HemiParams& params, const SceneInfo& scene)
    : params_(params),
      layout_(params.cols, params.rows),
      sceneMin_(scene.boundsMin),
      sceneMax_(scene.boundsMax),
      sceneArea_(scene.totalArea),
      strata_(params.cols * params.rows),
      cosMaxAngle_(static_cast<float>(std::cos(params.normalAngleDeg * PiDouble / 180.0))) {
    // Uniform points over the surface: a Halton sequence through the scene's area sampler.
    // Failed draws and non-finite or zero normals are skipped, within a bounded budget.
    positions_.reserve(params.points);
    normals_.reserve(params.points);
    const uint64_t maxAttempts = 2 * params.points + 64;
    for (uint64_t i = 0; positions_.size() < params.points && i < maxAttempts; ++i) {
        ++attempts_;
        glm::vec3 u(radicalInverse(i, 2), radicalInverse(i, 3), radicalInverse(i, 5));
        glm::vec3 p(0.f), n(0.f);
        if (!scene.samplePoint || !scene.samplePoint(u, &p, &n)) {
            if (positions_.empty() && i >= 63) break;  // the scene has no surface
            continue;
        }
        float len = glm::length(n);
        if (!finite3(p) || !(len > 0.f) || !std::isfinite(len)) continue;
        positions_.push_back(p);
        normals_.push_back(n / len);
    }
    // Number the points in the tree's leaf order, so that nearby points have nearby tables
    // (fewer cache misses along paths), then index the renumbered points.
    {
        PointKdTree order(positions_);
        std::vector<glm::vec3> pos(positions_.size()), nrm(normals_.size());
        for (size_t i = 0; i < positions_.size(); ++i) {
            pos[i] = positions_[order.leafOrderIndex(i)];
            nrm[i] = normals_[order.leafOrderIndex(i)];
        }
        positions_.swap(pos);
        normals_.swap(nrm);
    }
    numRegions_ = static_cast<int>(normals_.size() * 2);
    tree_ = std::make_unique<PointKdTree>(positions_);
    if (params_.cellLookup && !positions_.empty() && params_.knn <= CellCache::kMaxCandidates) {
        // Cells as large as the points' mean spacing: about one to three cells per point's
        // share of the surface (more where it runs oblique to the axes), so eight entries
        // per point leave the table at most three quarters full on usual scenes.
        const double spacing =
            std::sqrt(std::max(scene.totalArea, 0.0) / double(positions_.size()));
        cache_ = std::make_unique<CellCache>(scene.boundsMin, scene.boundsMax, float(spacing),
                                             positions_.size() * 8);
    }

    invCosine_.resize(size_t(strata_));
    for (int j = 0; j < strata_; ++j)
        invCosine_[size_t(j)] = 1.f / float(policyWeight(j));
    uniformShare_ = float(params_.epsilon / strata_);
    prefetchEstimates_ = params_.bootstrapTargets || !(params_.epsilon < 1.0);

    const size_t regions = positions_.size() * 2;
    frames_.resize(regions);
    for (size_t r = 0; r < regions; ++r) frames_[r].frame = Frame::fromZ(regionNormal(int(r)));
    if (params.smooth > 0.0)
        table_.setSmoothing(layout_.quadtree(), params.smooth);
    table_.reset(regions, strata_, params.init, policy(), /*lazy=*/true);
    if (params.treeDirections) {
        TreeTable::Settings ts;
        ts.init = params.init;
        ts.epsilon = params.epsilon;
        ts.splitShare = params.treeSplit;
        ts.maxDepth = params.treeDepth;
        ts.cosine = params.cosine;
        ts.smooth = params.smooth;
        trees_ = std::make_unique<TreeTable>();
        trees_->reset(regions, ts);
    }
    if (params.spots > 0) {
        SpotSettings ss;
        ss.perRegion = params.spots;
        ss.maxShare = params.spotShare;
        ss.outlier = params.spotOutlier;
        ss.minKappa = float(strata_);
        spots_ = std::make_unique<SpotLobes>();
        spots_->reset(regions, ss);
    }
    // (reset built region 0 and copied it to the others)
    if (regions > 0) {
        std::vector<double> est(static_cast<size_t>(strata_));
        table_.estimate(0, est.data());
        for (size_t r = 1; r < regions; ++r) updateRegion(int(r), est.data());
    }
}

HemiField::~HemiField() = default;

int HemiField::lookupPoint(const glm::vec3& p, const glm::vec3& n) const {
    if (positions_.empty() || !finite3(p)) return -1;
    const float nLen = glm::length(n);
    if (!(nLen > 0.f) || !std::isfinite(nLen)) return -1;
    const float threshold = cosMaxAngle_ * nLen;
    uint32_t idx[PointKdTree::kMaxK];
    float dist2[PointKdTree::kMaxK];
    const uint32_t* candidates = idx;
    int found = 0;
    if (cache_) {
        // The knn points of the cell's centre, nearest to it first.
        found = cache_->candidates(
            p,
            [this, &dist2](const glm::vec3& centre, uint32_t* dest) {
                return tree_->knn(centre, params_.knn, dest, dist2);
            },
            idx, &candidates);
    } else {
        // Fast path: the nearest point is usually admissible, and a 1-NN query is cheaper.
        float d2 = 0.f;
        const int nearest = tree_->nearest(p, &d2);
        if (nearest >= 0) {
            const int region = admissibleRegion(uint32_t(nearest), n, threshold);
            if (region >= 0) return prefetched(region);
            if (params_.knn == 1) return -1;
        }
        found = tree_->knn(p, params_.knn, idx, dist2);
    }
    for (int i = 0; i < found; ++i) {
        const int region = admissibleRegion(candidates[i], n, threshold);
        if (region >= 0) return prefetched(region);
    }
    return -1;
}

float HemiField::patchSize() const {
    return params_.patchLookup && cache_ ? cache_->cellSize() : 0.f;
}

void HemiField::setPatches(uint32_t count,
                           std::function<bool(uint32_t, glm::vec3*, glm::vec3*)> centre) {
    patchPoint_.reset();
    numPatches_ = 0;
    patchCentre_ = nullptr;
    if (!(patchSize() > 0.f) || count == 0 || !centre) return;
    patchPoint_.reset(static_cast<uint32_t*>(std::calloc(count, sizeof(uint32_t))));
    if (!patchPoint_) return;  // out of memory: the cell lookup serves every vertex
    numPatches_ = count;
    patchCentre_ = std::move(centre);
}

uint32_t HemiField::fillPatch(uint32_t patch) const {
    glm::vec3 c(0.f), n(0.f);
    if (!patchCentre_(patch, &c, &n) || !finite3(c)) return kNoPoint;
    const float len = glm::length(n);
    if (!(len > 0.f) || !std::isfinite(len)) return kNoPoint;
    n /= len;
    uint32_t idx[PointKdTree::kMaxK];
    float dist2[PointKdTree::kMaxK];
    const int found = tree_->knn(c, params_.knn, idx, dist2);
    for (int i = 0; i < found; ++i)
        if (admissibleRegion(idx[i], n, cosMaxAngle_) >= 0) return idx[i] + 1;
    return kNoPoint;
}

int HemiField::locate(const VertexQuery& q) const {
    if (q.medium) return -1;
    const uint32_t patch = q.patch;
    const glm::vec3 &p = q.p, &n = q.n;
    if (patch < numPatches_) {
        uint32_t v = __atomic_load_n(&patchPoint_[patch], __ATOMIC_RELAXED);
        if (v == 0) {
            v = fillPatch(patch);
            __atomic_store_n(&patchPoint_[patch], v, __ATOMIC_RELAXED);
        }
        if (v != kNoPoint) {
            // The patch's point, if admissible for n as well (a shading normal may lean
            // further than the patch's). A zero or non-finite n fails here and in lookup.
            const float nLen = glm::length(n);
            const int region = nLen > 0.f && std::isfinite(nLen)
                                   ? admissibleRegion(v - 1, n, cosMaxAngle_ * nLen)
                                   : -1;
            if (region >= 0) return prefetched(region);
        }
    }
    return lookupPoint(p, n);
}

int HemiField::prefetched(int region) const {
    // The region's frame, moment and CDF are read by the queries that follow a lookup, at a
    // random place in tables larger than the L2 cache: start loading them now (the caller does
    // other work, e.g. a shadow ray, before its first query). Measured on cornell-box, 16 spp:
    // -17% profile samples of a guided render.
    prefetchLine(&frames_[size_t(region)]);
    if (spots_) spots_->prefetch(region);
    if (choices_) {  // the learned light choice, read by the vertex's next-event estimation
        prefetchLine(&choiceWeight_[size_t(region)]);
        prefetchLines(choices_->cdf(size_t(region)),
                      size_t(choices_->strata() + 1) * sizeof(float));
    }
    prefetchLines(cdf(region), size_t(strata_ + 1) * sizeof(float));
    // And its estimates where the integrator reads them at every vertex (Eq. 1's bootstrap
    // targets): a read without the prefetch waits (cornell-box, 64 spp, perf: radiance() 705
    // -> 27 samples, prefetched() 0 -> 394, lookup() 789 -> 501, of about 15000). The
    // roulette's policyRadiance reads the CDF instead, so with target=path they are not
    // prefetched (docs/BENCHMARKS_HISTORY.md, session 14).
    if (prefetchEstimates_) {
        prefetchLines(table_.estimates(size_t(region)), size_t(strata_) * sizeof(float));
    }
    return region;
}

float HemiField::pdf(int region, const glm::vec3& w, int* bin) const {
    if (trees_) {
        glm::vec2 a;
        if (!treePoint(region, w, &a)) {
            if (bin) *bin = -1;
            return 0.f;
        }
        uint32_t leaf = 0;
        const float d = trees_->density(size_t(region), a, &leaf);
        if (bin) *bin = int(leaf);
        return d * (1.f / TwoPi);
    }
    const int j = stratumOf(region, w);
    if (bin) *bin = j;
    if (j < 0) return 0.f;
    return strataProbability(cdf(region), j) * layout_.density();
}

glm::vec3 HemiField::sample(int region, glm::vec2 u, float uPick, float* pdfOut,
                            int* bin) const {
    if (!validRegion(region)) {
        *pdfOut = 0.f;
        if (bin) *bin = -1;
        return glm::vec3(0.f);
    }
    if (trees_) {
        float d = 0.f;
        const glm::vec2 a = trees_->sample(size_t(region), u, uPick, &d);
        const glm::vec3 w = glm::normalize(
            frames_[size_t(region)].frame.toWorld(DirTree::hemisphereDirection(a)));
        // The pdf of the direction as pdf() finds it (the round trip through the frame may
        // move it to a neighbouring leaf); on the horizon keep the drawn density.
        float p = pdf(region, w, bin);
        if (!(p > 0.f)) p = d * (1.f / TwoPi);
        *pdfOut = p;
        return w;
    }
    const float* c = cdf(region);
    const int j = sampleStrataCdf2D(c, layout_.cols(), layout_.rows(), u, &u);
    glm::vec3 w = glm::normalize(frames_[size_t(region)].frame.toWorld(layout_.sampleStratum(j, u)));
    const float density = strataProbability(c, j) * layout_.density();
    // Report exactly pdf(region, w), so that MIS weights computed later agree; rounding may
    // move a direction on a stratum edge to its neighbour. Away from the edges (u, now the
    // position in the stratum, at least kEdge inside, so that with up to 64x64 strata w is at
    // least 1.5e-5 in cos(theta) and 9e-5 rad in phi from an edge, and at least 5e-3 from the
    // pole: a hundred times the rounding of the frame's round trip) w's stratum is j, without
    // finding it again. On the horizon (pdf 0) keep the drawn stratum's density: such a
    // direction carries no cosine-weighted contribution.
    constexpr float kEdge = 1.f / 1024.f;
    if (u.x >= kEdge && u.x <= 1.f - kEdge && u.y >= kEdge && u.y <= 1.f - kEdge) {
        if (bin) *bin = j;
        *pdfOut = density;
        return w;
    }
    float p = pdf(region, w, bin);
    if (!(p > 0.f)) p = density;
    *pdfOut = p;
    return w;
}

float HemiField::pdfAt(int region, const glm::vec3& x, const glm::vec3& w, int* bin) const {
    const float p = pdf(region, w, bin);
    const float s = spots_ ? spots_->share(region) : 0.f;
    if (!(s > 0.f)) return p;
    glm::vec3 unit;
    if (!unitDirection(w, &unit)) return (1.f - s) * p;
    return (1.f - s) * p + s * spots_->pdf(region, x, unit);
}

glm::vec3 HemiField::sampleAt(int region, const glm::vec3& x, glm::vec2 u, float uPick,
                              float* pdfOut, int* bin) const {
    const float s = spots_ ? spots_->share(region) : 0.f;
    if (!(s > 0.f)) return sample(region, u, uPick, pdfOut, bin);
    // One-sample mixture: the lobes with probability s, else the strata; the density is the
    // mixture's.
    glm::vec3 w;
    if (uPick < s) {
        w = spots_->sample(region, x, u, std::min(uPick / s, 0.99999994f));
        if (!(glm::dot(w, w) > 0.f)) {
            *pdfOut = 0.f;
            if (bin) *bin = -1;
            return glm::vec3(0.f);
        }
        *pdfOut = pdfAt(region, x, w, bin);
        // Marked as the lobes' sample: record() keeps it out of the strata's means (a lobe
        // aims most of its samples at the bright spot inside its stratum, so their mean
        // would overstate the stratum's light many times over).
        if (bin && *bin >= 0) *bin |= kSpotBin;
        return w;
    }
    float ps = 0.f;
    w = sample(region, u, std::min((uPick - s) / (1.f - s), 0.99999994f), &ps, bin);
    *pdfOut = (1.f - s) * ps + s * spots_->pdf(region, x, w);
    return w;
}

void HemiField::recordSpot(int slot, int region, const glm::vec3& x, const glm::vec3& w,
                           const glm::vec3& hit, float light, int bin) {
    // (spots exclude directions=tree)
    if (!spots_ || directionsOff_ || !validRegion(region)) return;
    if (!frames_[size_t(region)].learns) return;
    // Only where the strata have learned enough to tell a spot from their estimate.
    if (frames_[size_t(region)].confidence < 0.5f) return;
    const int j = stratumOf(region, w, bin >= 0 ? bin & ~kSpotBin : bin);
    if (j < 0) return;
    glm::vec3 unit;
    if (!unitDirection(w, &unit)) return;
    // The policy's Q (from the CDF, which the vertex's sampling has just read).
    spots_->record(slot, region, x, unit, hit, light, policyRadiance(region, unit, j));
}

float HemiField::scatteredEstimate(int region,
                                   const std::function<float(const glm::vec3&)>& fcos) const {
    if (!validRegion(region)) return 0.f;
    const Frame& frame = frames_[size_t(region)].frame;
    if (trees_) {
        // Over the leaves: Q x fcos at the leaf's centre x its solid angle.
        const DirTree& t = trees_->tree(size_t(region));
        const std::vector<glm::vec3> sq = t.squares();
        double acc = 0.0;
        for (uint32_t i = 0; i < t.size(); ++i) {
            if (!t.node(i).leaf()) continue;
            const glm::vec2 centre(sq[i].x + 0.5f * sq[i].z, sq[i].y + 0.5f * sq[i].z);
            const float f = fcos(frame.toWorld(DirTree::hemisphereDirection(centre)));
            if (f > 0.f && std::isfinite(f))
                acc += double(trees_->radiance(size_t(region), i)) * f * sq[i].z * sq[i].z;
        }
        return float(std::min(acc * TwoPi, double(FLT_MAX)));
    }
    const float* q = table_.estimates(size_t(region));
    double acc = 0.0;
    for (int j = 0; j < strata_; ++j) {
        float f = fcos(frame.toWorld(layout_.centre(j)));
        if (f > 0.f && std::isfinite(f)) acc += q[j] * double(f);
    }
    double result = acc * layout_.stratumSolidAngle();
    return static_cast<float>(std::min(result, double(FLT_MAX)));
}

float HemiField::irradianceEstimate(int region, const glm::vec3& n) const {
    if (!validRegion(region) || !finite3(n)) return 0.f;
    // The moment's dot product: exact for n = the region normal, and without the clamp of
    // strata below n's horizon for a tilted n (at most the admissible angle away).
    return std::max(0.f, glm::dot(frames_[size_t(region)].moment, n));
}

float HemiField::confidence(int region) const {
    if (trees_) return validRegion(region) ? trees_->confidence(size_t(region), params_.warmup) : 0.f;
    return validRegion(region) ? frames_[size_t(region)].confidence : 0.f;
}

float HemiField::selection(int region) const {
    return validRegion(region) ? table_.selection().selection(size_t(region)) : -1.f;
}

void HemiField::recordSelection(int slot, int region, const SelectionSample& s) {
    // A region that stopped learning (learn-cap) keeps its selection as well.
    if (learns(region)) table_.selection().record(slot, region, s);
}

float HemiField::radiance(int region, const glm::vec3& w, int bin) const {
    if (trees_) {
        if (!validRegion(region)) return 0.f;
        if (bin >= 0 && size_t(bin) < trees_->tree(size_t(region)).size())
            return trees_->radiance(size_t(region), uint32_t(bin));
        glm::vec2 a;
        return treePoint(region, w, &a) ? trees_->radianceAt(size_t(region), a) : 0.f;
    }
    const int j = stratumOf(region, w, bin);
    return j < 0 ? 0.f : table_.estimates(size_t(region))[j];
}

float HemiField::policyRadiance(int region, const glm::vec3& w, int bin) const {
    if (prefetchEstimates_ || trees_) return radiance(region, w, bin);  // exact, and as cheap
    const int j = stratumOf(region, w, bin);
    if (j < 0) return 0.f;
    const float* c = cdf(region);
    const float q = (c[j + 1] - c[j] - uniformShare_) * frames_[size_t(region)].policyScale *
                    invCosine_[size_t(j)];
    return q > 0.f ? std::min(q, FLT_MAX) : 0.f;  // (NaN -> 0)
}

namespace {
// The learned choices' CDF: proportional to the options' mean values (uniform while all are 0).
void choicePolicy(int, const double* q, int n, float* cdf) { buildStrataCdf(q, n, 0.0, cdf); }
}  // namespace

bool HemiField::enableChoices(int n) {
    if (n < 2 || n > kMaxChoices) return false;
    choices_ = std::make_unique<StrataTable>();
    choices_->reset(size_t(numRegions()), n, 0.0, choicesPolicy(n), /*lazy=*/true);
    choiceWeight_.assign(size_t(numRegions()), 0.f);
    return true;
}

void HemiField::updateChoiceWeights() {
    for (size_t r = 0; r < choiceWeight_.size(); ++r) {
        const float c = choices_->confidence(r, kChoiceWarmup);
        choiceWeight_[r] = c >= kChoiceMinWeight ? c : 0.f;
    }
}

void HemiField::recordChoice(int slot, int region, int k, float value) {
    if (!choices_ || !validRegion(region) || k < 0 || k >= choices_->strata()) return;
    choices_->record(slot, region, value, [k] { return k; });
}

StrataTable::PolicyBuilder HemiField::choicesPolicy(int n) {
    return [n](int r, const double* q, float* cdf) { choicePolicy(r, q, n, cdf); };
}

void HemiField::beginPass(int numSlots) {
    table_.beginPass(numSlots);
    if (choices_) choices_->beginPass(numSlots);
    if (spots_) spots_->beginPass(numSlots);
    if (trees_) trees_->beginPass(numSlots);
}

void HemiField::record(int slot, int region, const glm::vec3& w, float target, int bin) {
    if (directionsOff_) return;
    if (trees_) {
        glm::vec2 a(-1.f);  // outside the square: counted as rejected
        treePoint(region, w, &a);
        trees_->record(slot, validRegion(region) ? uint32_t(region) : UINT32_MAX, a, target);
        return;
    }
    if (bin >= 0 && (bin & kSpotBin)) return;  // sampled by a spot lobe (sampleAt)
    if (validRegion(region) && !frames_[size_t(region)].learns) return;
    table_.record(slot, region, target, [&] { return stratumOf(region, w, bin); });
}

void HemiField::updateRegion(int region, const double* q) {
    double m[3] = {0.0, 0.0, 0.0};
    for (int j = 0; j < strata_; ++j) {
        const glm::vec3& c = layout_.centre(j);
        m[0] += q[j] * double(c.x);
        m[1] += q[j] * double(c.y);
        m[2] += q[j] * double(c.z);
    }
    RegionFrame& rf = frames_[size_t(region)];
    rf.confidence = table_.confidence(size_t(region), params_.warmup);
    rf.learns = table_.belowCap(size_t(region), params_.learnCap);
    rf.guides = trees_ || !cosineSamplingSuffices(q, layout_, params_.prune, rf.confidence);
    // buildPolicy's normalisation: p_j = (1 - epsilon) Q_j cos_j / sum + epsilon / n, or 1 / n
    // where the sum is not positive and finite (then Q_j = 0 for all j).
    double sum = 0.0;
    for (int j = 0; j < strata_; ++j) sum += q[j] * policyWeight(j);
    const double scale = sum > 0.0 && std::isfinite(sum) && params_.epsilon < 1.0
                             ? sum / (1.0 - params_.epsilon)
                             : 0.0;
    rf.policyScale = float(std::min(scale, double(FLT_MAX)));
    const double sa = layout_.stratumSolidAngle();
    const Frame& f = rf.frame;
    glm::vec3 world;
    for (int i = 0; i < 3; ++i) {
        double v = (double(f.s[i]) * m[0] + double(f.t[i]) * m[1] + double(f.n[i]) * m[2]) * sa;
        world[i] = float(std::max(-double(FLT_MAX), std::min(v, double(FLT_MAX))));
    }
    rf.moment = finite3(world) ? world : glm::vec3(0.f);
}

void HemiField::buildPolicy(const double* q, float* cdf) const {
    if (!params_.cosine) {
        buildStrataCdf(q, strata_, params_.epsilon, cdf);
        return;
    }
    double qc[64 * 64];
    for (int j = 0; j < strata_; ++j) qc[j] = q[j] * policyWeight(j);
    buildStrataCdf(qc, strata_, params_.epsilon, cdf);
}

double HemiField::learnedTotal(size_t region) const {
    const double* q = table_.q(region);
    const uint64_t* v = table_.visits(region);
    double total = 0.0;
    for (int j = 0; j < strata_; ++j) total += q[j] * double(v[j]);
    return total;
}

void HemiField::endPass() {
    table_.endPass(params_.alphaVisits, params_.fixedAlpha, policy());
    if (choices_) {
        choices_->endPass(/*alphaVisits=*/true, 0.0, choicesPolicy(choices_->strata()));
        updateChoiceWeights();
    }
    if (spots_) spots_->endPass(learnedTotals());
    if (trees_) {
        trees_->endPass();
        updateTreeRegions();
    }
    judgeScene();
}

HemiField::SceneMeasures HemiField::sceneMeasures() const {
    std::vector<double> q(static_cast<size_t>(strata_));
    // visits: of the regions with learned light (the ratio's and the confidence's weights);
    // all: of every visited region (the spot worth's).
    double visits = 0.0, conf = 0.0, cosine = 0.0, mixture = 0.0, all = 0.0, worth = 0.0;
    const double n = double(strata_), eps = params_.epsilon;
    for (int r = 0; r < numRegions(); ++r) {
        const double v = table_.visitsTotal(size_t(r));
        if (!(v > 0.0)) continue;
        all += v;
        if (spots_) worth += v * double(spots_->worth(r));
        table_.estimate(size_t(r), q.data());
        double qc = 0.0, cs = 0.0;
        for (int j = 0; j < strata_; ++j) {
            const double c = double(layout_.centre(j).z);
            qc += q[size_t(j)] * c;
            cs += c;
        }
        if (!(qc > 0.0) || !std::isfinite(qc)) continue;
        const RegionFrame& f = frames_[size_t(r)];
        // The guide's share in the mixture, as the integrator's default mix 0.5 times the
        // confidence; its CDF p_j = (1 - epsilon) Q_j cos_j / sum + epsilon / n.
        const double mix = f.guides ? 0.5 * double(f.confidence) : 0.0;
        // Second moments relative to (sum Q cos)^2: cosine sampling's is 1 + its relative
        // variance (the `prune` test's), the mixture's is summed here.
        const double sc = 1.0 + cosineSamplingVariance(q.data(), layout_);
        double sm = 0.0;
        for (int j = 0; j < strata_; ++j) {
            const double c = double(layout_.centre(j).z), x = q[size_t(j)] * c;
            if (!(x > 0.0)) continue;
            const double pc = c / cs, pg = (1.0 - eps) * x / qc + eps / n;
            sm += x * x / ((1.0 - mix) * pc + mix * pg);
        }
        sm /= qc * qc;
        const double s = spots_ ? double(spots_->share(r)) : 0.0;
        if (s > 0.0) sm = std::min(sm, (1.0 - s) * sc);
        visits += v;
        conf += v * double(f.confidence);
        cosine += v * sc;
        mixture += v * sm;
    }
    SceneMeasures m;
    if (visits > 0.0) m.confidence = conf / visits;
    if (all > 0.0) m.spotWorth = worth / all;
    if (cosine > 0.0 && std::isfinite(mixture / cosine)) m.ratio = mixture / cosine;
    return m;
}

namespace {
constexpr double kSpotJudgeConfidence = 0.8;
}  // namespace

void HemiField::judgeScene() {
    if (directionsOff_ || trees_) return;
    const bool directions = params_.judge > 0.0;
    const bool spots = params_.spotJudge > 0.0 && spots_ && !spots_->silenced();
    if (!directions && !spots) return;
    const SceneMeasures m = sceneMeasures();
    if (m.confidence < 0.5) return;
    if (directions && m.ratio > params_.judge) directionsOff_ = true;
    // Lobes sharpen and gain light share as they learn: their worth is judged later, at
    // confidence 0.8 (session 45: at 0.5 glossy-lamps' lobes were worth 0.14, at 0.8 8.5).
    if (spots && !directionsOff_ && m.confidence >= kSpotJudgeConfidence &&
        m.spotWorth < params_.spotJudge) {
        spotWorthAtVerdict_ = m.spotWorth;
        spots_->setSilenced(true);
    }
}

void HemiField::updateTreeRegions() {
    // The moment sum over leaves of Q x direction x solid angle, for irradianceEstimate; the
    // confidence is the trees' own (confidence()).
    for (size_t r = 0; r < frames_.size(); ++r) {
        if (!(trees_->visits(r) > 0.0)) continue;
        const DirTree& t = trees_->tree(r);
        const std::vector<glm::vec3> sq = t.squares();
        glm::dvec3 m(0.0);
        for (uint32_t i = 0; i < t.size(); ++i) {
            if (!t.node(i).leaf()) continue;
            const glm::vec2 centre(sq[i].x + 0.5f * sq[i].z, sq[i].y + 0.5f * sq[i].z);
            m += glm::dvec3(DirTree::hemisphereDirection(centre)) *
                 (double(trees_->radiance(r, i)) * sq[i].z * sq[i].z * TwoPi);
        }
        const Frame& f = frames_[r].frame;
        const glm::vec3 world = f.toWorld(glm::vec3(m));
        frames_[r].moment = finite3(world) ? world : glm::vec3(0.f);
    }
}

void HemiField::endPassShared(const SumAcrossProcesses& sum) {
    table_.endPassShared(params_.alphaVisits, params_.fixedAlpha, policy(), sum);
    if (choices_) {
        choices_->endPassShared(/*alphaVisits=*/true, 0.0, choicesPolicy(choices_->strata()),
                                sum);
        updateChoiceWeights();
    }
    if (spots_) {
        // Every rank's candidates, merged in slot order on each (SpotLobes::takeCandidates).
        std::string candidates = spots_->takeCandidates();
        sum.gather(candidates);
        if (!spots_->putCandidates(candidates))
            throw std::runtime_error("hemi: the ranks' spot candidates are corrupt");
        spots_->endPass(learnedTotals());
    }
    judgeScene();
}

size_t HemiField::bytes() const {
    return table_.bytes() + (trees_ ? trees_->bytes() : 0) + (spots_ ? spots_->bytes() : 0) +
           (choices_ ? choices_->bytes() : 0) +
           (positions_.capacity() + normals_.capacity()) * sizeof(glm::vec3) +
           frames_.capacity() * sizeof(RegionFrame) + tree_->bytes() +
           (cache_ ? cache_->bytes() : 0) + size_t(numPatches_) * sizeof(uint32_t);
}

size_t HemiField::scratchBytes() const { return table_.scratchBytes(); }

std::string HemiField::describe() const {
    char alpha[32];
    if (params_.alphaVisits)
        std::snprintf(alpha, sizeof(alpha), "visits");
    else
        std::snprintf(alpha, sizeof(alpha), "%g", params_.fixedAlpha);
    char buf[512];
    std::snprintf(buf, sizeof(buf),
                  "hemi: %zu points (%d hemispheres, %llu draws), %dx%d strata, alpha=%s, "
                  "normal-angle=%g, knn=%d, init=%g, epsilon=%g, warmup=%g, smooth=%g, "
                  "%.1f MiB (+%.1f MiB record "
                  "buffers; %zu hemispheres with tables of their own, the others share the untrained one); "
                  "passes=%llu, records=%llu, rejected targets=%llu, "
                  "rejected records=%llu",
                  positions_.size(), numRegions(), (unsigned long long)attempts_, params_.cols,
                  params_.rows, alpha, params_.normalAngleDeg, params_.knn, params_.init,
                  params_.epsilon, params_.warmup, params_.smooth,
                  double(bytes()) / (1024.0 * 1024.0),
                  double(scratchBytes()) / (1024.0 * 1024.0), learnedRegions(),
                  (unsigned long long)stats().passes, (unsigned long long)stats().records,
                  (unsigned long long)stats().rejectedTargets,
                  (unsigned long long)stats().rejectedRecords);
    std::string line = buf;
    if (cache_) {
        std::snprintf(buf, sizeof(buf), "; lookup memo: %zu of %zu cells filled",
                      cache_->size(), cache_->capacity());
        line += buf;
    }
    if (trees_) {
        size_t leaves = 0;
        for (size_t r = 0; r < size_t(numRegions()); ++r) leaves += trees_->tree(r).leaves();
        std::snprintf(buf, sizeof(buf),
                      "; directions=tree (split %g, depth %d): %zu leaves in all, %.1f MiB",
                      params_.treeSplit, params_.treeDepth, leaves,
                      double(trees_->bytes()) / (1024.0 * 1024.0));
        line += buf;
    }
    const SceneMeasures measures = trees_ ? SceneMeasures() : sceneMeasures();
    if (spots_) {
        std::snprintf(buf, sizeof(buf), "; spots=%d (share %g, outlier %g): %zu lobes in %zu hemispheres",
                      params_.spots, params_.spotShare, params_.spotOutlier,
                      spots_->activeLobes(), spots_->activeRegions());
        line += buf;
        if (params_.spotJudge > 0.0 && !trees_) {
            const bool off = spots_->silenced();
            std::snprintf(buf, sizeof(buf), ", spot judge %g: worth %.3g, %s", params_.spotJudge,
                          off ? spotWorthAtVerdict_ : measures.spotWorth, off ? "lobes off" : "lobes on");
            line += buf;
        }
    }
    if (choices_) {
        size_t used = 0, full = 0;
        for (size_t r = 0; r < choiceWeight_.size(); ++r) {
            used += choiceWeight_[r] > 0.f;
            full += choiceWeight_[r] >= kChoiceFullWeight;
        }
        std::snprintf(buf, sizeof(buf),
                      "; lights=learned (%d emitters): used in %zu hemispheres, done learning "
                      "in %zu",
                      choices_->strata(), used, full);
        line += buf;
    }
    if (numPatches_ > 0) {
        std::snprintf(buf, sizeof(buf), "; %u surface patches", numPatches_);
        line += buf;
    }
    if (params_.judge > 0.0 && !trees_) {
        std::snprintf(buf, sizeof(buf), "; judge %g: predicted second moment %.3f of cosine "
                      "sampling's at confidence %.2f, %s", params_.judge, measures.ratio,
                      measures.confidence,
                      directionsOff_ ? (active() ? "directions off" : "field off")
                                     : "guiding");
        line += buf;
    }
    const SelectionLearner& sel = table_.selection();
    if (sel.learnedRegions() > 0) {
        std::snprintf(buf, sizeof(buf), "; learned selection in %zu regions, mean %.3f",
                      sel.learnedRegions(), sel.meanSelection());
        line += buf;
    }
    return line;
}

GuidingStats HemiField::stats() const {
    GuidingStats s = trees_ ? trees_->stats() : table_.stats();
    s.learnedRegions = learnedRegions();
    for (const RegionFrame& f : frames_) s.cappedRegions += f.learns ? 0 : 1;
    for (int r = 0; r < numRegions(); ++r) s.prunedRegions += guides(r) ? 0 : 1;
    return s;
}

bool HemiField::refusesSaving(const char* action, std::string* error) const {
    const char* feature = trees_ ? "directions=tree" : nullptr;
    if (feature) *error = std::string("hemi with ") + feature + " " + action;
    return feature != nullptr;
}

bool HemiField::save(const std::string& path, std::string* error) const {
    if (refusesSaving("cannot be saved yet", error)) return false;
    return fieldio::writeFile(path, serialize(), error);
}

std::string HemiField::serialize() const {
    fieldio::Writer w;
    w.raw(fieldio::kMagic, 8);
    w.u32(fieldio::kVersion);
    w.str("hemi");
    w.vec3(sceneMin_);
    w.vec3(sceneMax_);
    w.f64(sceneArea_);
    w.u64(positions_.size());
    w.u64(attempts_);
    w.u32(uint32_t(params_.cols));
    w.u32(uint32_t(params_.rows));
    const GuidingStats& st = table_.stats();
    w.u64(st.passes);
    w.u64(st.records);
    w.u64(st.rejectedTargets);
    w.u64(st.rejectedRecords);
    w.u64(uint64_t(numRegions()));
    const std::vector<double> q = table_.denseQ();
    const std::vector<uint64_t> visits = table_.denseVisits();
    w.data.reserve(w.data.size() + q.size() * 16);
    for (double d : q) w.f64(d);
    for (uint64_t v : visits) w.u64(v);
    // The spot lobes (docs/GUIDE_FILES.md: an optional section after the tables).
    if (spots_) {
        w.u32(kSpotsSection);
        w.blob(spots_->write());
    }
    // The learned choices (an optional section after the lobes): options, then Q and visits
    // of every region.
    if (choices_) {
        fieldio::Writer c;
        c.u32(uint32_t(choices_->strata()));
        for (double d : choices_->denseQ()) c.f64(d);
        for (uint64_t v : choices_->denseVisits()) c.u64(v);
        w.u32(kChoicesSection);
        w.blob(c.data);
    }
    return std::move(w.data);
}

bool HemiField::load(const std::string& path, std::string* error) {
    if (trees_) {
        *error = "hemi with directions=tree cannot load a saved field yet";
        return false;
    }
    const std::string kind = fieldio::fileKind(path);
    if (kind.empty()) {
        *error = "'" + path + "' is not a saved guiding field (or cannot be read)";
        return false;
    }
    if (kind != "hemi") {
        *error = "'" + path + "' holds a '" + kind +
                 "' guiding field; the hemi backend loads only fields it saved";
        return false;
    }
    std::string data;
    if (!fieldio::readFile(path, &data, error)) return false;
    return loadBytes(data, path, error);
}

bool HemiField::loadBytes(const std::string& data, const std::string& name,
                          std::string* error) {
    auto fail = [&](const std::string& why) {
        *error = "'" + name + "': " + why;
        return false;
    };
    if (data.size() < 16 || std::memcmp(data.data(), fieldio::kMagic, 8) != 0)
        return fail("not a saved hemi field");
    fieldio::Reader r(data);
    r.skip(8);
    const uint32_t version = r.u32();
    if (r.str(32) != "hemi") return fail("not a saved hemi field");
    if (version != fieldio::kVersion) return fail("unsupported version " + std::to_string(version));
    const glm::vec3 bmin = r.vec3(), bmax = r.vec3();
    const double area = r.f64();
    const uint64_t points = r.u64(), attempts = r.u64();
    const uint32_t cols = r.u32(), rows = r.u32();
    GuidingStats s;
    s.passes = r.u64();
    s.records = r.u64();
    s.rejectedTargets = r.u64();
    s.rejectedRecords = r.u64();
    const uint64_t regions = r.u64();
    if (!r.ok()) return fail("truncated header");
    std::string why;
    if (!fieldio::sameScene(bmin, bmax, area, sceneMin_, sceneMax_, sceneArea_, &why))
        return fail(why);
    if (points != positions_.size() || attempts != attempts_ || regions != uint64_t(numRegions()))
        return fail("made with " + std::to_string(points) + " points, this field has " +
                    std::to_string(positions_.size()) + " (use the same points parameter)");
    if (int(cols) != params_.cols || int(rows) != params_.rows)
        return fail("strata " + std::to_string(cols) + "x" + std::to_string(rows) +
                    ", this field has " + std::to_string(params_.cols) + "x" +
                    std::to_string(params_.rows));
    const size_t count = size_t(numRegions()) * size_t(strata_);
    if (r.remaining() < count * 16) return fail("table size does not match the header");
    std::vector<double> q(count);
    std::vector<uint64_t> visits(count);
    for (double& d : q) {
        d = r.f64();
        if (!(d >= 0.0) || !std::isfinite(d)) return fail("corrupt Q table");
    }
    for (uint64_t& v : visits) v = r.u64();
    if (!r.ok()) return fail("truncated tables");
    // The spot lobes, if saved: a field without spots uses the strata alone; one with spots
    // loading a field saved without them starts its lobes empty.
    std::string lobes, choices;
    while (r.remaining() > 0) {
        const uint32_t tag = r.u32();
        if (tag == kSpotsSection && lobes.empty()) {
            lobes = r.blob();
            if (!r.ok()) return fail("truncated spot lobes");
        } else if (tag == kChoicesSection && choices.empty()) {
            choices = r.blob();
            if (!r.ok()) return fail("truncated learned choices");
        } else {
            return fail("unknown data after the tables");
        }
    }
    // The learned choices, if both the file and this field have them (a field that loads a
    // file without them starts them empty; one without choices ignores the file's).
    std::vector<double> choiceQ;
    std::vector<uint64_t> choiceVisits;
    if (choices_ && !choices.empty()) {
        fieldio::Reader c(choices);
        const uint32_t n = c.u32();
        if (!c.ok() || int(n) != choices_->strata())
            return fail("learned choices of another number of options");
        const size_t cells = size_t(numRegions()) * n;
        if (c.remaining() != cells * 16) return fail("learned choices of another size");
        choiceQ.resize(cells);
        choiceVisits.resize(cells);
        for (double& d : choiceQ) {
            d = c.f64();
            if (!(d >= 0.0) || !std::isfinite(d)) return fail("corrupt learned choices");
        }
        for (uint64_t& v : choiceVisits) v = c.u64();
    }
    if (spots_) {
        std::string why;
        if (!lobes.empty() && !spots_->read(lobes, &why)) return fail(why);
        if (lobes.empty()) spots_->reset(spots_->regions(), spots_->settings());
    }
    table_.assign(std::move(q), std::move(visits), policy());
    table_.stats() = s;
    if (choices_) {
        if (choiceQ.empty()) {
            enableChoices(choices_->strata());
        } else {
            choices_->assign(std::move(choiceQ), std::move(choiceVisits),
                             choicesPolicy(choices_->strata()));
            updateChoiceWeights();
        }
    }
    if (spots_) {
        spots_->setSilenced(false);
        spots_->refitAll(learnedTotals());
    }
    // The verdict of the tables loaded (a field saved after its verdict stopped learning
    // there, so it reaches the same one).
    directionsOff_ = false;
    judgeScene();
    return true;
}

bool HemiField::saveState(std::string* state, std::string* error) const {
    if (refusesSaving("cannot save its learning state yet", error)) return false;
    fieldio::Writer w;
    w.blob(serialize());
    table_.selection().saveState(w);
    *state = std::move(w.data);
    return true;
}

bool HemiField::loadState(const std::string& state, std::string* error) {
    if (refusesSaving("cannot restore a learning state yet", error)) return false;
    fieldio::Reader r(state);
    const std::string tables = r.blob();
    if (!r.ok()) {
        *error = "truncated hemi state";
        return false;
    }
    if (!loadBytes(tables, "hemi state", error)) return false;
    if (!table_.selection().loadState(r) || r.remaining() != 0) {
        *error = "corrupt selection state of the hemi field";
        return false;
    }
    table_.stats().selectionRegions = table_.selection().learnedRegions();
    table_.stats().selectionMean = table_.selection().meanSelection();
    return true;
}

}  // namespace rlpbrt::guiding
