// The cost of guiding, measured while rendering (`--stats`: guide_ns_per_guided_vertex): one
// path in kGuideClockEvery per thread is timed, and on it every call into the guide (the
// region lookup, sampling and pdf evaluation, the roulette's learned light, and the training
// records of the PathRecorder) adds its wall time to PathStats::guideNanos. Timing every path
// would cost about as much as the work it measures; one in 16 still cost 2-3% of a guided
// render in this VM (its clock reads are slow: profiled on cornell-box), one in 128 costs
// well under 1%, and the mean converges over the render's millions of paths. A timer's own
// cost (two clock reads, tens of ns: as much as a pdf evaluation) is measured once
// (timerOverheadNanos) and taken off per timed call. A call that took longer than
// kPreemptedNanos was descheduled (a guide call takes ns to us; the scheduler's slice is ms):
// it is left out with its count, else one preemption among a small render's few timed paths
// made the guide's share of the render exceed 1 on a loaded machine.
#pragma once

#include <chrono>
#include <cstdint>

namespace rlpbrt {

constexpr uint64_t kGuideClockEvery = 128;
constexpr uint64_t kPreemptedNanos = 200'000;

// The time measured on timed paths, and the number of timed calls.
struct GuideClockSums {
    uint64_t nanos = 0, calls = 0;
    void add(const GuideClockSums& o) {
        nanos += o.nanos;
        calls += o.calls;
    }
    // The guide's time: the measured time less the timers' own.
    double guideNanos() const;
};

// The measured time of an empty GuideTimer (median of a few batches; computed once).
double timerOverheadNanos();

// Adds the time from construction to destruction to *sums (nothing when sums is null).
class GuideTimer {
public:
    explicit GuideTimer(GuideClockSums* sums) : sums_(sums) {
        if (sums_) t0_ = std::chrono::steady_clock::now();
    }
    ~GuideTimer() {
        if (!sums_) return;
        const uint64_t ns = uint64_t(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                         std::chrono::steady_clock::now() - t0_)
                                         .count());
        if (ns > kPreemptedNanos) return;
        sums_->nanos += ns;
        ++sums_->calls;
    }
    GuideTimer(const GuideTimer&) = delete;
    GuideTimer& operator=(const GuideTimer&) = delete;

private:
    GuideClockSums* sums_;
    std::chrono::steady_clock::time_point t0_;
};

}  // namespace rlpbrt
