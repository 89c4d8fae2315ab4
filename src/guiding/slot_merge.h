// The deterministic merge of per-slot record buffers that every learned table of the guiding
// layer applies between passes: a stable counting sort by region, so that within a region
// the records keep slot order, then record order, whatever the thread schedule was.
// Standard library and TBB.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include <tbb/parallel_for.h>

namespace rlpbrt::guiding {

// Memory for a large buffer that is written in full soon after (the merged records of a
// pass): from 4 MiB on it is aligned to 2 MiB and the kernel is asked for transparent huge
// pages, so that first touching it takes one page fault per 2 MiB instead of one per 4 KiB
// (profiled: the faults were 2-3% of a guided render's time on cornell-box). Smaller sizes
// come from operator new. Both are released with releaseLargeBuffer(p, bytes).
void* allocateLargeBuffer(size_t bytes);
void releaseLargeBuffer(void* p, size_t bytes) noexcept;

// An allocator whose vectors leave new elements of trivial types uninitialised on resize():
// the merge below writes every element, so zeroing them first would be a wasted pass over
// memory that is often fresh from the kernel. Its memory comes from allocateLargeBuffer.
template <class T>
struct NoInitAllocator : std::allocator<T> {
    using value_type = T;
    template <class U>
    struct rebind {
        using other = NoInitAllocator<U>;
    };
    NoInitAllocator() = default;
    template <class U>
    NoInitAllocator(const NoInitAllocator<U>&) noexcept {}
    T* allocate(size_t n) {
        if (n > size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
        return static_cast<T*>(allocateLargeBuffer(n * sizeof(T)));
    }
    void deallocate(T* p, size_t n) noexcept { releaseLargeBuffer(p, n * sizeof(T)); }
    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
};
// The merged records of a pass.
template <class Record>
using MergedRecords = std::vector<Record, NoInitAllocator<Record>>;

// Gathers the records of all slots (recordsOf(slot) returns a slot's vector; each record has
// a `region` in [0, regions)) into *merged, grouped by region; afterwards (*end)[r] is one
// past region r's last record (region r spans [r == 0 ? 0 : (*end)[r - 1], (*end)[r])).
// The slots are cut into consecutive groups that count and scatter their records in
// parallel, each into its own range of every region (groups in slot order): the result is
// the serial sort's, at any thread count. The groups' positions take groups x regions x 8
// bytes, at most about kCountBudget (else fewer groups, down to one).
template <class Record, class Slots, class RecordsOf>
void mergeByRegion(const Slots& slots, RecordsOf recordsOf, size_t regions,
                   std::vector<uint64_t>* end, MergedRecords<Record>* merged) {
    constexpr size_t kMaxGroups = 16, kCountBudget = size_t(32) << 20;
    const size_t numSlots = slots.size();
    size_t total = 0;
    for (const auto& s : slots) total += recordsOf(s).size();
    end->assign(regions + 1, 0);
    (*end)[regions] = total;
    merged->clear();  // (a larger buffer need not keep the last pass's records)
    merged->resize(total);
    if (total == 0 || regions == 0) return;
    // Groups of slots with about equal numbers of records (small passes: one group).
    size_t groups = std::min({kMaxGroups, numSlots, total / 4096 + 1,
                              std::max<size_t>(1, kCountBudget / (regions * sizeof(uint64_t)))});
    std::vector<size_t> firstSlot(groups + 1, numSlots);
    {
        size_t g = 0, seen = 0;
        firstSlot[0] = 0;
        for (size_t s = 0; s < numSlots && g + 1 < groups; ++s) {
            seen += recordsOf(slots[s]).size();
            if (seen * groups >= total * (g + 1)) firstSlot[++g] = s + 1;
        }
        groups = g + 1;
        firstSlot[groups] = numSlots;
    }
    // Records per (group, region), then each group's first position in every region.
    std::vector<uint64_t> pos(groups * regions, 0);
    tbb::parallel_for(size_t(0), groups, [&](size_t g) {
        uint64_t* count = &pos[g * regions];
        for (size_t s = firstSlot[g]; s < firstSlot[g + 1]; ++s)
            for (const Record& r : recordsOf(slots[s])) ++count[r.region];
    });
    uint64_t offset = 0;
    for (size_t r = 0; r < regions; ++r) {
        for (size_t g = 0; g < groups; ++g) {
            const uint64_t n = pos[g * regions + r];
            pos[g * regions + r] = offset;
            offset += n;
        }
        (*end)[r] = offset;
    }
    Record* out = merged->data();
    tbb::parallel_for(size_t(0), groups, [&](size_t g) {
        uint64_t* next = &pos[g * regions];
        for (size_t s = firstSlot[g]; s < firstSlot[g + 1]; ++s)
            for (const Record& r : recordsOf(slots[s])) out[next[r.region]++] = r;
    });
}

}  // namespace rlpbrt::guiding
