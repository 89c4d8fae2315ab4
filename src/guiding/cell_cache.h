// A memo in front of an expensive spatial query (the hemi backend's k-nearest kd-tree
// search): space is cut into cubic cells, and the query is evaluated once per cell, at the
// cell's centre, then its list of up to K candidates is reused by every query that falls in the
// cell. The cached list is a function of the cell alone, so results do not depend on which
// thread filled an entry or in what order: renders stay deterministic. Lock-free open
// addressing over a fixed table; when the table is three quarters full or a probe sequence is
// long, the query is evaluated directly (the same list, not cached). Standard library and GLM
// only.
#pragma once

#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include "util/prefetch.h"

namespace rlpbrt::guiding {

class CellCache {
public:
    static constexpr int kAxisBits = 21;  // cells per axis: at most 2^21
    static constexpr int kMaxProbes = 16;
    static constexpr int kMaxCandidates = 13;  // an entry is one cache line

    // Cells of edge `cellSize` (grown if needed so the bounds fit in 2^21 cells per axis)
    // from boundsMin; a table of at least `capacity` entries (a power of two), each holding up
    // to kMaxCandidates candidates.
    CellCache(const glm::vec3& boundsMin, const glm::vec3& boundsMax, float cellSize,
              size_t capacity);

    // The candidate list of p's cell: *out points to the candidates, the return value is
    // their number. fill(centre, uint32_t* dest) must write at most kMaxCandidates candidates
    // for a query at the cell centre and return their number; it must be a pure function of
    // the centre and thread-safe. `scratch` (as many entries) receives the list when it is not
    // cached. p must be finite.
    template <class Fill>
    int candidates(const glm::vec3& p, Fill&& fill, uint32_t* scratch,
                   const uint32_t** out) const;

    // Starts loading the first entry p's cell probes (p finite).
    void prefetch(const glm::vec3& p) const {
        prefetchLine(&entries_[size_t(mix(keyOf(p) + 1)) & mask_]);
    }
    // The centre of p's cell (where the candidates of p were computed).
    glm::vec3 centreOf(const glm::vec3& p) const { return centreOfKey(keyOf(p)); }
    float cellSize() const { return cell_; }
    size_t capacity() const { return mask_ + 1; }
    // Entries filled so far.
    size_t size() const { return used_.load(std::memory_order_relaxed); }
    size_t bytes() const { return capacity() * sizeof(Entry); }

private:
    static constexpr uint32_t kUnset = UINT32_MAX;
    // The key of p's cell (its three cell coordinates), and the centre of a key's cell (only
    // when a list is computed: the lookups themselves need just the key).
    uint64_t keyOf(const glm::vec3& p) const;  // (inline below)
    glm::vec3 centreOfKey(uint64_t key) const {
        constexpr uint64_t axisMask = (uint64_t(1) << kAxisBits) - 1;
        glm::vec3 centre;
        for (int a = 0; a < 3; ++a)
            centre[a] = origin_[a] + (float((key >> (a * kAxisBits)) & axisMask) + 0.5f) * cell_;
        return centre;
    }
    // A 64-bit finaliser (every key bit reaches the low bits the table indexes with).
    static uint64_t mix(uint64_t x) {
        x ^= x >> 30;
        x *= 0xBF58476D1CE4E5B9ull;
        x ^= x >> 27;
        x *= 0x94D049BB133111EBull;
        return x ^ (x >> 31);
    }

    struct alignas(64) Entry {
        std::atomic<uint64_t> key{0};        // 0 = empty, else cell key + 1
        std::atomic<uint32_t> count{kUnset};  // kUnset until the list is written
        uint32_t list[kMaxCandidates];
    };
    static_assert(sizeof(Entry) == 64, "one cache line per entry");

    glm::vec3 origin_;
    float cell_, invCell_;
    size_t mask_;
    std::unique_ptr<Entry[]> entries_;
    mutable std::atomic<size_t> used_{0};
};

inline uint64_t CellCache::keyOf(const glm::vec3& p) const {
    constexpr int64_t maxCell = (int64_t(1) << kAxisBits) - 1;
    uint64_t key = 0;
    for (int a = 0; a < 3; ++a) {
        // Truncation is the floor here: negative offsets clamp to cell 0 (no libm call; the
        // baseline x86-64 target has no inline floor).
        const float f = (p[a] - origin_[a]) * invCell_;
        const int64_t c = f <= 0.f ? 0 : f >= float(maxCell) ? maxCell : int64_t(f);
        key |= uint64_t(c) << (a * kAxisBits);
    }
    return key;
}

template <class Fill>
int CellCache::candidates(const glm::vec3& p, Fill&& fill, uint32_t* scratch,
                          const uint32_t** out) const {
    const uint64_t cell = keyOf(p), key = cell + 1;
    size_t slot = size_t(mix(key)) & mask_;
    for (int probe = 0; probe < kMaxProbes; ++probe, slot = (slot + 1) & mask_) {
        Entry& e = entries_[slot];
        const uint64_t k = e.key.load(std::memory_order_acquire);
        if (k == key) {
            const uint32_t n = e.count.load(std::memory_order_acquire);
            if (n == kUnset) break;  // being written by another thread: evaluate directly
            *out = e.list;
            return int(n);
        }
        if (k != 0) continue;
        if (used_.load(std::memory_order_relaxed) >= capacity() / 4 * 3) break;
        uint64_t expected = 0;
        if (!e.key.compare_exchange_strong(expected, key, std::memory_order_acq_rel)) {
            if (expected == key) break;  // claimed for this cell by another thread just now
            continue;                    // claimed for another cell: probe on
        }
        used_.fetch_add(1, std::memory_order_relaxed);
        const int n = fill(centreOfKey(cell), e.list);
        e.count.store(uint32_t(n), std::memory_order_release);
        *out = e.list;
        return n;
    }
    *out = scratch;
    return fill(centreOfKey(cell), scratch);
}

}  // namespace rlpbrt::guiding
