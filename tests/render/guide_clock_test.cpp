// render/guide_clock.h: a timer adds its interval and one call, and nothing for an interval
// longer than kPreemptedNanos (a descheduled call); the calibrated overhead is positive and
// small, and the guide's time never goes below zero.
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "render/guide_clock.h"

namespace rlpbrt {
namespace {

TEST(GuideClock, TimersAddTheirIntervalAndCount) {
    GuideClockSums sums;
    // A 50 us call is counted (tried again if this thread was descheduled during it).
    for (int attempt = 0; attempt < 10 && sums.calls == 0; ++attempt) {
        GuideTimer t(&sums);
        const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(50);
        while (std::chrono::steady_clock::now() < until) {
        }
    }
    { GuideTimer untimed(nullptr); }
    EXPECT_EQ(sums.calls, 1u);
    EXPECT_GE(sums.nanos, 50000u);
    EXPECT_GE(sums.guideNanos(), 50000.0 - timerOverheadNanos());
    // A call as long as a scheduler's slice was preempted: left out, time and count.
    {
        GuideTimer t(&sums);
        std::this_thread::sleep_for(std::chrono::nanoseconds(2 * kPreemptedNanos));
    }
    EXPECT_EQ(sums.calls, 1u);
    EXPECT_LT(sums.nanos, kPreemptedNanos);
    const uint64_t nanos = sums.nanos;
    GuideClockSums more;
    more.nanos = 5, more.calls = 2;
    sums.add(more);
    EXPECT_EQ(sums.calls, 3u);
    EXPECT_EQ(sums.nanos, nanos + 5u);
}

TEST(GuideClock, OverheadIsCalibratedAndTakenOff) {
    const double overhead = timerOverheadNanos();
    EXPECT_GT(overhead, 0.0);
    EXPECT_LT(overhead, 10000.0);  // a clock read is tens of ns, never 10 us
    GuideClockSums empty;
    for (int i = 0; i < 1000; ++i) GuideTimer t(&empty);
    EXPECT_EQ(empty.calls, 1000u);
    // Empty timers: what is left after the overhead is near zero (never negative).
    EXPECT_GE(empty.guideNanos(), 0.0);
    EXPECT_LT(empty.guideNanos() / 1000.0, 5.0 * overhead + 100.0);
    GuideClockSums tiny;
    tiny.nanos = 1, tiny.calls = 100;
    EXPECT_EQ(tiny.guideNanos(), 0.0);
}

}  // namespace
}  // namespace rlpbrt
