// Tests of the per-slot record merge (guiding/slot_merge.h): the grouped parallel counting
// sort gives exactly the stable sort by region (slot order, then record order within a
// region), for small and large passes, empty slots, and at any thread count.
#include "guiding/slot_merge.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include <tbb/task_arena.h>

namespace rlpbrt::guiding {
namespace {

struct Rec {
    uint32_t region;
    uint32_t id;  // slot << 24 | index in the slot: identifies the record
};

std::vector<std::vector<Rec>> makeSlots(size_t slots, size_t perSlotMax, uint32_t regions,
                                        uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<std::vector<Rec>> out(slots);
    for (size_t s = 0; s < slots; ++s) {
        // Some slots empty, some large; regions skewed towards a few.
        const size_t n = s % 7 == 3 ? 0 : size_t(rng() % (perSlotMax + 1));
        for (size_t i = 0; i < n; ++i) {
            const uint32_t r = rng() % 4 == 0 ? uint32_t(rng() % 3) : uint32_t(rng() % regions);
            out[s].push_back(Rec{r, uint32_t(s << 24 | i)});
        }
    }
    return out;
}

void expectStableSort(const std::vector<std::vector<Rec>>& slots, size_t regions) {
    std::vector<Rec> expected;
    for (const auto& s : slots) expected.insert(expected.end(), s.begin(), s.end());
    std::stable_sort(expected.begin(), expected.end(),
                     [](const Rec& a, const Rec& b) { return a.region < b.region; });
    std::vector<uint64_t> end;
    MergedRecords<Rec> merged;
    mergeByRegion<Rec>(
        slots, [](const std::vector<Rec>& s) -> const std::vector<Rec>& { return s; }, regions,
        &end, &merged);
    ASSERT_EQ(merged.size(), expected.size());
    ASSERT_EQ(end.size(), regions + 1);
    EXPECT_EQ(end[regions], expected.size());
    for (size_t i = 0; i < expected.size(); ++i) {
        ASSERT_EQ(merged[i].id, expected[i].id) << i;
        ASSERT_EQ(merged[i].region, expected[i].region) << i;
    }
    size_t begin = 0;
    for (size_t r = 0; r < regions; ++r) {
        ASSERT_GE(end[r], begin) << r;
        for (size_t i = begin; i < end[r]; ++i) ASSERT_EQ(merged[i].region, r) << i;
        begin = end[r];
    }
    EXPECT_EQ(begin, expected.size());
}

TEST(SlotMerge, EqualsTheStableSortByRegion) {
    // Small passes (one group), large ones (up to 16 groups), few and many regions.
    expectStableSort(makeSlots(5, 10, 4, 1), 4);
    expectStableSort(makeSlots(169, 2000, 4096, 2), 4096);
    expectStableSort(makeSlots(40, 20000, 7, 3), 7);
    expectStableSort(makeSlots(3, 50000, 100000, 4), 100000);
    expectStableSort(makeSlots(0, 0, 10, 5), 10);
    expectStableSort(makeSlots(8, 0, 10, 6), 10);  // no records
}

TEST(SlotMerge, SameResultOnOneThreadAndMany) {
    const auto slots = makeSlots(200, 3000, 1000, 7);
    auto merge = [&](int threads) {
        std::vector<uint64_t> end;
        MergedRecords<Rec> merged;
        tbb::task_arena arena(threads);
        arena.execute([&] {
            mergeByRegion<Rec>(
                slots, [](const std::vector<Rec>& s) -> const std::vector<Rec>& { return s; },
                1000, &end, &merged);
        });
        std::vector<uint32_t> ids;
        for (const Rec& r : merged) ids.push_back(r.id);
        return std::make_pair(end, ids);
    };
    const auto one = merge(1);
    EXPECT_EQ(merge(2), one);
    EXPECT_EQ(merge(4), one);
}

}  // namespace
}  // namespace rlpbrt::guiding
