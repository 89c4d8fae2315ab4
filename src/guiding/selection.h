// Learning, per region, the probability with which the integrator samples the guide rather
// than the BSDF (or the phase function): the one-sample MIS mixture's selection probability.
// The integrator samples a direction x with probability m = c * scale from the guide (c the
// selection in force, scale the region's confidence times the BSDF's diffuse share), else
// from the BSDF, and pays the mixture pdf p_c(x). Its variance is set by the second moment
// E[(pi/p_c)^2], pi = f cos Li the integrand (Li estimated by the rest of the path). For any candidate c' the same samples give that moment without bias, reweighted:
// E_{p_c}[pi^2 / (p_c p_c')]. Each region sums these over a grid of candidates (older passes
// decayed, as the guide changes), and adopts the candidate with the smallest sum. All
// candidates are below 1, so the BSDF keeps covering directions the guide cannot sample.
// Standard library and TBB only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "guiding/field_io.h"
#include "guiding/guiding.h"
#include "guiding/slot_merge.h"

namespace rlpbrt::guiding {

class SelectionLearner {
public:
    // Candidates c = 0, 0.1, ..., 0.9.
    static constexpr int kCandidates = 10;
    static float candidate(int i) { return 0.1f * float(i); }
    // Weight of the sums of earlier passes at each endPass (the guide they were drawn from
    // has changed since).
    static constexpr double kDecay = 0.5;
    // Decayed number of contributing samples a region needs before it adopts a candidate.
    static constexpr double kMinSamples = 32.0;
    // Learned data per region once allocated (sums, weight, selection): the memory estimates
    // of the backends count it for every region.
    static constexpr double kBytesPerRegion =
        kCandidates * sizeof(double) + sizeof(double) + sizeof(float);

    // `regions` regions, none learned.
    void reset(size_t regions);
    // Appends unlearned regions (up to `regions` in all); not during a pass.
    void grow(size_t regions);
    void beginPass(int numSlots);
    // One sample of a region (see SelectionSample); thread-safe across slots. Samples with a
    // zero, negative or non-finite integrand are skipped.
    void record(int slot, int region, const SelectionSample& s);
    // Merges the pass's samples in slot order (deterministic) and updates the selections.
    void endPass();
    // Samples recorded in this pass so far (all slots).
    size_t pendingSamples() const;
    // endPass for a learner that several processes share (GuidingField::endPassShared):
    // `total` is the sum over the processes of pendingSamples(); each region's sample count
    // and sums over the candidates are summed through `sum` (each process adds its samples
    // in slot order, the processes' sums are added in rank order), then applied as endPass
    // applies its own.
    void endPassShared(const SumAcrossProcesses& sum, uint64_t total);

    // The learned selection of a region, or -1 if it has none (too few samples, or none that
    // carried light).
    float selection(size_t region) const {
        return region < selection_.size() ? selection_[region] : -1.f;
    }
    // Regions with a learned selection, and their mean selection (0 if none).
    size_t learnedRegions() const;
    double meanSelection() const;
    size_t bytes() const;
    size_t scratchBytes() const;

    // The learned state (regions, decayed sums and weights, selections) between passes, for
    // GuidingField::saveState: loadState restores it into a learner of as many regions
    // (false, and the learner unchanged, for another count or corrupt data).
    void saveState(fieldio::Writer& w) const;
    bool loadState(fieldio::Reader& r);

private:
    struct Sample {
        uint32_t region;
        float a;  // pi^2 / p_c
        float b;  // candidate pdf p_c'(x) = b + c' d
        float d;
    };
    struct alignas(64) SlotBuffer {
        std::vector<Sample> samples;
    };
    // Allocates the learned data at the first pass with samples; false while there is none.
    bool allocate(uint64_t total);
    // A region's candidate sums of the pass's samples [begin, end) (merged_ positions).
    void candidateSums(size_t begin, size_t end, double* add) const;
    // Decays region r's sums, adds the pass's (add, count samples) and picks its selection.
    void update(size_t r, const double* add, double count);

    size_t regions_ = 0;
    std::vector<SlotBuffer> slots_;
    // Allocated at the first pass with samples (a render that does not learn selections
    // pays nothing).
    std::vector<double> sums_;     // regions x kCandidates decayed second-moment sums
    std::vector<double> weights_;  // decayed sample count per region
    std::vector<float> selection_;
    std::vector<uint64_t> start_;  // endPass scratch: counting sort by region
    MergedRecords<Sample> merged_;
};

}  // namespace rlpbrt::guiding
