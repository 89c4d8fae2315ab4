// GuidingField::endPassShared, the guide's side of a distributed render (docs/DISTRIBUTED.md):
// K fields that each record the slots of their own "rank" and end their passes through a
// sum over the K of them (threads standing in for processes) learn the field of one process
// that recorded every slot and ended its passes with endPass(). hemi (with and without spot
// lobes) and vdb (surface and medium tables, voxel activation), with learned selections and
// rejected targets.
#include "guiding/guiding.h"
#include "guiding/hemi.h"
#include "guiding/vdb.h"
#include "guiding/vdb_volume.h"

#include <gtest/gtest.h>

#include <cmath>
#include <condition_variable>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "guiding/test_scenes.h"

namespace rlpbrt::guiding {
namespace {

// K threads standing in for processes: each passes its value, the last to arrive combines
// them in rank order and gives every thread the result.
template <typename T>
class Rendezvous {
public:
    explicit Rendezvous(int k) : k_(k), values_(size_t(k), nullptr) {}
    template <class Combine>
    void meet(int rank, T& v, Combine&& combine) {
        std::unique_lock<std::mutex> lock(mutex_);
        values_[size_t(rank)] = &v;
        const long generation = generation_;
        if (++arrived_ < k_) {
            cv_.wait(lock, [&] { return generation_ != generation; });
            return;
        }
        const T all = combine(values_);
        for (T* x : values_) *x = all;
        ++calls_;
        arrived_ = 0;
        ++generation_;
        cv_.notify_all();
    }
    int calls() const { return calls_; }

private:
    int k_, arrived_ = 0, calls_ = 0;
    long generation_ = 0;
    std::vector<T*> values_;
    std::mutex mutex_;
    std::condition_variable cv_;
};

// SumAcrossProcesses's sums for K threads: element-wise, in rank order.
template <typename T>
class ThreadSum : public Rendezvous<std::vector<T>> {
public:
    using Rendezvous<std::vector<T>>::Rendezvous;
    void sum(int rank, std::vector<T>& v) {
        this->meet(rank, v, [](const std::vector<std::vector<T>*>& arrays) {
            std::vector<T> total(arrays[0]->size(), T(0));
            for (const std::vector<T>* a : arrays) {
                EXPECT_EQ(a->size(), total.size()) << "every rank passes arrays of the same size";
                for (size_t i = 0; i < std::min(a->size(), total.size()); ++i) total[i] += (*a)[i];
            }
            return total;
        });
    }
};

// SumAcrossProcesses::gather for K threads: every thread's bytes in rank order.
class ThreadGather : public Rendezvous<std::string> {
public:
    using Rendezvous<std::string>::Rendezvous;
    void gather(int rank, std::string& bytes) {
        meet(rank, bytes, [](const std::vector<std::string*>& strings) {
            std::string all;
            for (const std::string* b : strings) all += *b;
            return all;
        });
    }
};

constexpr int kSlots = 7;

// A unit square floor with a box of fog above it (the vdb backend's medium tables).
SceneInfo foggyFloor() {
    SceneInfo s = test::planeScene();
    s.boundsMax = glm::vec3(1.f, 1.f, 0.5f);
    s.mediaMin = glm::vec3(0.f);
    s.mediaMax = glm::vec3(1.f, 1.f, 0.5f);
    return s;
}

// The records of pass `pass` in slot s (the same on every rank that records the slot):
// surface targets, medium requests and targets, selection samples, and a few bad targets.
// The targets are multiples of 2^-24 below 1, whose sums in doubles are exact in any order.
void recordSlot(GuidingField& f, int pass, int s) {
    std::mt19937_64 rng(uint64_t(pass) * 1000 + uint64_t(s));
    std::uniform_real_distribution<float> u(0.f, 1.f);
    auto target = [&] { return float(rng() >> 40) * 0x1p-24f; };
    for (int i = 0; i < 400; ++i) {
        const glm::vec3 p(u(rng), u(rng), 0.f), n(0.f, 0.f, 1.f);
        const int region = f.lookup(p, n);
        glm::vec3 w = test::gaussianDirection(rng);
        w.z = std::abs(w.z);
        if (region >= 0) {
            f.record(s, region, w, i % 97 == 0 ? -1.f : target());
            SelectionSample x;
            x.integrand = u(rng);
            x.pdf = 0.2f + u(rng);
            x.pGuide = u(rng);
            x.pOther = u(rng);
            x.scale = u(rng);
            // (a few regions, so that they reach the learner's minimum of samples)
            const glm::vec3 hub(i % 3 == 0 ? 0.2f : 0.7f, 0.5f, 0.f);
            f.recordSelection(s, f.lookup(hub, n), x);
            // Bright light from two small spots (hemi's spot lobes; others ignore it).
            const glm::vec3 spot = i % 2 ? glm::vec3(0.3f, 0.8f, 2.f) : glm::vec3(-1.f, 0.2f, 1.5f);
            const glm::vec3 hit = spot + 0.01f * glm::vec3(u(rng), u(rng), u(rng));
            f.recordSpot(s, region, p, glm::normalize(hit - p), hit, 1e4f + target());
            // A light choice (fields that learn choices; others ignore it).
            f.recordChoice(s, region, i % 3, i % 3 == 1 ? 0.f : target());
        }
        const glm::vec3 q(u(rng), u(rng), 0.5f * u(rng));
        const int cell = f.lookupMedium(q);
        if (cell >= 0)
            f.record(s, cell, test::gaussianDirection(rng), target());
        else if (i % 5 == 0)
            f.requestMedium(s, q);
    }
}

// Every query of the frozen policy, at every region, alike.
void expectSameField(const GuidingField& a, const GuidingField& b, int regions) {
    const GuidingStats sa = a.stats(), sb = b.stats();
    EXPECT_EQ(sa.passes, sb.passes);
    EXPECT_EQ(sa.records, sb.records);
    EXPECT_EQ(sa.rejectedTargets, sb.rejectedTargets);
    EXPECT_EQ(sa.learnedRegions, sb.learnedRegions);
    EXPECT_EQ(sa.mediumCells, sb.mediumCells);
    EXPECT_EQ(sa.selectionRegions, sb.selectionRegions);
    EXPECT_EQ(sa.selectionMean, sb.selectionMean);
    std::mt19937_64 rng(5);
    std::vector<glm::vec3> dirs;
    for (int i = 0; i < 32; ++i) dirs.push_back(test::gaussianDirection(rng));
    int mismatches = 0;
    for (int r = 0; r < regions; ++r) {
        mismatches += a.confidence(r) != b.confidence(r);
        const GuidingField::Choice ca = a.choice(r), cb = b.choice(r);
        mismatches += ca.weight != cb.weight || ca.learning != cb.learning ||
                      (ca.cdf == nullptr) != (cb.cdf == nullptr);
        if (ca.cdf && cb.cdf)
            for (int k = 0; k <= 3; ++k) mismatches += ca.cdf[k] != cb.cdf[k];
        mismatches += a.selection(r) != b.selection(r);
        for (const glm::vec3& w : dirs) {
            mismatches += a.pdf(r, w) != b.pdf(r, w);
            mismatches += a.pdfAt(r, glm::vec3(0.5f, 0.4f, 0.f), w) !=
                          b.pdfAt(r, glm::vec3(0.5f, 0.4f, 0.f), w);
            // (a small uStratum: hemi's spot lobes where a region has them)
            const glm::vec2 u(0.5f + 0.4f * w.x, 0.5f + 0.4f * w.y);
            float pa = 0.f, pb = 0.f;
            const glm::vec3 x(0.5f, 0.4f, 0.f);
            mismatches += a.sampleAt(r, x, u, 0.02f, &pa) != b.sampleAt(r, x, u, 0.02f, &pb);
            mismatches += pa != pb;
            mismatches += a.radiance(r, w) != b.radiance(r, w);
        }
    }
    EXPECT_EQ(mismatches, 0) << "over " << regions << " regions";
}

// narrowCounts false: the counts go as doubles, as in a pass of 2^32 records or more.
template <class Field>
void checkShared(const char* backend, const SceneInfo& scene,
                 std::map<std::string, std::string> params,
                 const std::function<int(const Field&)>& regions, bool narrowCounts = true,
                 const std::function<void(const Field&)>& checkOne = nullptr,
                 int choices = 0) {
    constexpr int kRanks = 3, kPasses = 3;
    auto one = test::makeField<Field>(backend, scene, params);
    std::vector<std::unique_ptr<Field>> ranks;
    for (int k = 0; k < kRanks; ++k)
        ranks.push_back(test::makeField<Field>(backend, scene, params));
    ASSERT_TRUE(one);
    if (choices > 0) {
        ASSERT_TRUE(one->enableChoices(choices));
        for (auto& f : ranks) ASSERT_TRUE(f->enableChoices(choices));
    }
    ThreadSum<double> sum(kRanks);
    ThreadSum<uint32_t> counts(kRanks);
    ThreadGather gather(kRanks);
    for (int pass = 0; pass < kPasses; ++pass) {
        one->beginPass(kSlots);
        for (int s = 0; s < kSlots; ++s) recordSlot(*one, pass, s);
        one->endPass();
        std::vector<std::thread> threads;
        for (int k = 0; k < kRanks; ++k)
            threads.emplace_back([&, k] {
                Field& f = *ranks[size_t(k)];
                f.beginPass(kSlots);
                for (int s = k; s < kSlots; s += kRanks) recordSlot(f, pass, s);
                SumAcrossProcesses across;
                across.doubles = [&](std::vector<double>& v) { sum.sum(k, v); };
                across.counts = [&](std::vector<uint32_t>& v) { counts.sum(k, v); };
                across.gather = [&](std::string& b) { gather.gather(k, b); };
                if (!narrowCounts) across.countLimit = 0.0;
                f.endPassShared(across);
            });
        for (std::thread& t : threads) t.join();
    }
    EXPECT_GT(one->stats().records, 1000u);
    EXPECT_GT(one->stats().rejectedTargets, 0u);
    EXPECT_GT(one->stats().selectionRegions, 0u);
    EXPECT_GE(sum.calls(), 2 * kPasses);
    if (checkOne) checkOne(*one);
    if (narrowCounts) {
        EXPECT_GE(counts.calls(), 2 * kPasses);
    } else {
        EXPECT_EQ(counts.calls(), 0);
    }
    for (int k = 0; k < kRanks; ++k) {
        SCOPED_TRACE(k);
        expectSameField(*one, *ranks[size_t(k)], regions(*one));
    }
}

TEST(SharedPass, HemiRanksLearnTheFieldOfOneProcess) {
    checkShared<HemiField>("hemi", test::cornerScene(), {{"mix", "learn"}},
                           [](const HemiField& f) { return f.numRegions(); });
}

TEST(SharedPass, HemiRanksLearnTheSpotLobesOfOneProcess) {
    checkShared<HemiField>(
        "hemi", test::cornerScene(), {{"mix", "learn"}, {"spots", "4"}, {"warmup", "0"}, {"points", "64"}},
        [](const HemiField& f) { return f.numRegions(); }, true, [](const HemiField& f) {
            EXPECT_GT(f.spots()->activeLobes(), 1u);
        });
}

// Learned light choices (enableChoices): every rank's records in every region's means.
TEST(SharedPass, HemiRanksLearnTheChoicesOfOneProcess) {
    checkShared<HemiField>(
        "hemi", test::cornerScene(), {{"points", "8"}},
        [](const HemiField& f) { return f.numRegions(); }, true,
        [](const HemiField& f) {
            int learned = 0;
            for (int r = 0; r < f.numRegions(); ++r) learned += f.choice(r).cdf != nullptr;
            EXPECT_GT(learned, 0);
        },
        3);
}

TEST(SharedPass, CountsAsDoublesGiveTheSameField) {
    checkShared<HemiField>(
        "hemi", test::cornerScene(), {{"mix", "learn"}},
        [](const HemiField& f) { return f.numRegions(); }, /*narrowCounts=*/false);
}

TEST(SharedPass, VdbRanksLearnTheFieldOfOneProcessWithMedia) {
    checkShared<VdbField>("vdb", foggyFloor(), {{"mix", "learn"}, {"volume-voxel", "4"}},
                          [](const VdbField& f) {
                              EXPECT_GT(f.volume()->cells(), 0);
                              return f.numRegions() + f.volume()->cells();
                          });
}

}  // namespace
}  // namespace rlpbrt::guiding
