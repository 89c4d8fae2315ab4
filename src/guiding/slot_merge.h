// The deterministic merge of per-slot record buffers that every learned table of the guiding
// layer applies between passes: a stable counting sort by region, so that within a region
// the records keep slot order, then record order, whatever the thread schedule was.
// Standard library only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace rlpbrt::guiding {

// Gathers the records of all slots (recordsOf(slot) returns a slot's vector; each record has
// a `region` in [0, regions)) into *merged, grouped by region; afterwards (*end)[r] is one
// past region r's last record (region r spans [r == 0 ? 0 : (*end)[r - 1], (*end)[r])).
template <class Record, class Slots, class RecordsOf>
void mergeByRegion(const Slots& slots, RecordsOf recordsOf, size_t regions,
                   std::vector<uint64_t>* end, std::vector<Record>* merged) {
    size_t total = 0;
    for (const auto& s : slots) total += recordsOf(s).size();
    end->assign(regions + 1, 0);
    for (const auto& s : slots)
        for (const Record& r : recordsOf(s)) ++(*end)[r.region + 1];
    for (size_t r = 0; r < regions; ++r) (*end)[r + 1] += (*end)[r];
    merged->resize(total);
    for (const auto& s : slots)
        for (const Record& r : recordsOf(s)) (*merged)[(*end)[r.region]++] = r;
}

}  // namespace rlpbrt::guiding
