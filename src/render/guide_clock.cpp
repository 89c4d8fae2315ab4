#include "render/guide_clock.h"

#include <algorithm>
#include <array>

namespace rlpbrt {

double timerOverheadNanos() {
    static const double overhead = [] {
        std::array<double, 9> batches{};
        for (double& b : batches) {
            GuideClockSums sums;
            constexpr int kCalls = 2000;
            for (int i = 0; i < kCalls; ++i) {
                GuideTimer timer(&sums);
            }
            b = double(sums.nanos) / kCalls;
        }
        std::nth_element(batches.begin(), batches.begin() + 4, batches.end());
        return batches[4];
    }();
    return overhead;
}

double GuideClockSums::guideNanos() const {
    return std::max(0.0, double(nanos) - double(calls) * timerOverheadNanos());
}

}  // namespace rlpbrt
