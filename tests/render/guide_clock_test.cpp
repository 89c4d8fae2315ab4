// render/guide_clock.h: a timer adds its interval and one call; the calibrated overhead is
// positive and small, and the guide's time never goes below zero.
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "render/guide_clock.h"

namespace rlpbrt {
namespace {

TEST(GuideClock, TimersAddTheirIntervalAndCount) {
    GuideClockSums sums;
    {
        GuideTimer t(&sums);
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    { GuideTimer untimed(nullptr); }
    EXPECT_EQ(sums.calls, 1u);
    EXPECT_GE(sums.nanos, 2000000u);
    EXPECT_GE(sums.guideNanos(), 2000000.0 - timerOverheadNanos());
    GuideClockSums more;
    more.nanos = 5, more.calls = 2;
    sums.add(more);
    EXPECT_EQ(sums.calls, 3u);
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
