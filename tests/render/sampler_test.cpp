// Tests of the pixel samplers: sample counts, determinism, range, stratification,
// uniformity, decorrelation and convergence.
#include "render/sampler.h"

#include <cmath>
#include <thread>
#include <set>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "render/lowdiscrepancy.h"

namespace rlpbrt {
namespace {

const char* const AllNames[] = {"random",   "stratified", "halton",         "sobol",
                                "02sequence", "lowdiscrepancy", "zerotwosequence",
                                "maxmindist"};

Param intParam(const std::string& name, int v) {
    Param p;
    p.type = ParamType::Integer;
    p.name = name;
    p.numbers = {double(v)};
    return p;
}

Param boolParam(const std::string& name, bool v) {
    Param p;
    p.type = ParamType::Bool;
    p.name = name;
    p.bools = {uint8_t(v)};
    return p;
}

// A sampler of the given name with `spp` samples (via the override), or the defaults.
std::unique_ptr<Sampler> make(const std::string& name, int spp, uint64_t seed = 7) {
    std::string error, note;
    auto s = createSampler(name, ParamList(), spp, seed, &error, &note);
    EXPECT_TRUE(s) << name << ": " << error;
    return s;
}

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
    const size_t n = a.size();
    double ma = 0, mb = 0;
    for (size_t i = 0; i < n; ++i) ma += a[i], mb += b[i];
    ma /= n;
    mb /= n;
    double sab = 0, saa = 0, sbb = 0;
    for (size_t i = 0; i < n; ++i) {
        sab += (a[i] - ma) * (b[i] - mb);
        saa += (a[i] - ma) * (a[i] - ma);
        sbb += (b[i] - mb) * (b[i] - mb);
    }
    return sab / std::sqrt(saa * sbb);
}

// ---- Low-level building blocks -----------------------------------------------------------

TEST(LowDiscrepancy, PermutationElementIsAPermutation) {
    for (uint32_t n : {1u, 2u, 3u, 5u, 8u, 9u, 12u, 16u, 17u, 100u, 1024u, 1000u}) {
        for (uint64_t seed : {1ull, 99ull, 0xdeadbeefull}) {
            std::vector<int> seen(n, 0);
            for (uint32_t i = 0; i < n; ++i) {
                uint32_t p = permutationElement(i, n, seed);
                ASSERT_LT(p, n);
                ++seen[p];
            }
            for (uint32_t j = 0; j < n; ++j) EXPECT_EQ(seen[j], 1) << "n=" << n;
        }
    }
}

// Over S seeds, count[i][j] = #(perm(i, n, seed) == j) ~ Binomial(S, 1/n); chi-square with
// (n-1)^2 dof has mean dof and sd sqrt(2 dof): bound mean + 5 sd.
template <class Permutation>
void expectUniformPositions(Permutation perm, uint32_t n) {
    const int S = 20000;
    std::vector<double> count(n * n, 0);
    for (int s = 0; s < S; ++s)
        for (uint32_t i = 0; i < n; ++i) ++count[i * n + perm(i, n, mixBits(s + 12345))];
    double chi2 = 0, e = double(S) / n;
    for (double c : count) chi2 += (c - e) * (c - e) / e;
    const double dof = (n - 1.0) * (n - 1.0);
    EXPECT_LT(chi2, dof + 5 * std::sqrt(2 * dof)) << "n=" << n;
}

TEST(LowDiscrepancy, PermutationPositionsAreUniform) {
    for (uint32_t n : {3u, 5u, 9u, 12u, 16u}) expectUniformPositions(permutationElement, n);
}

// The permutations of small n are drawn from (nearly) all of them, uniformly: Kensler's hash
// gave 8 of the 24 permutations of 4 and 16356 distinct permutations of 16 over 100000 seeds,
// so a padded sampler paired its dimensions alike from block to block (a caustic-glass
// --time render past 16 pixelsamples had 3x the error of one with blocks of 32).
TEST(LowDiscrepancy, SmallPermutationsCoverTheSymmetricGroup) {
    const int S = 100000;
    for (uint32_t n : {4u, 8u, 16u}) {
        std::map<std::vector<uint32_t>, int> seen;
        for (int s = 0; s < S; ++s) {
            std::vector<uint32_t> v(n);
            const uint64_t seed = mixBits(uint64_t(s) * 0x9E3779B97F4A7C15ull + 1);
            for (uint32_t i = 0; i < n; ++i) v[i] = permutationElement(i, n, seed);
            ++seen[v];
        }
        if (n == 4) {
            // All 24, equally often: chi-square with 23 dof below mean + 5 sd.
            ASSERT_EQ(seen.size(), 24u);
            double chi2 = 0, e = double(S) / 24;
            for (const auto& kv : seen) chi2 += (kv.second - e) * (kv.second - e) / e;
            EXPECT_LT(chi2, 23 + 5 * std::sqrt(46.0));
        } else if (n == 8) {
            // Uniform over 8! = 40320: 40320 (1 - exp(-S / 40320)) = 36950 distinct expected.
            EXPECT_GT(seen.size(), 36000u);
        } else {
            EXPECT_GT(seen.size(), 99900u);  // 16! = 2.1e13: collisions are rare
        }
    }
}

// The progressive permutation of a block's indices: a permutation that maps every aligned
// block of 16 2^k indices onto an aligned block of the same size (permutationElement itself
// for n <= 16), with element positions uniform over seeds.
TEST(LowDiscrepancy, ProgressivePermutationKeepsAlignedBlocks) {
    for (uint32_t n : {2u, 16u, 32u, 64u, 1024u}) {
        for (uint64_t seed : {1ull, 99ull, 0xdeadbeefull}) {
            std::vector<int> seen(n, 0);
            for (uint32_t i = 0; i < n; ++i) {
                const uint32_t p = progressivePermutationElement(i, n, seed);
                ASSERT_LT(p, n);
                ++seen[p];
                if (n <= 16) {
                    EXPECT_EQ(p, permutationElement(i, n, seed));
                }
                for (uint32_t k = 16; k < n; k <<= 1)  // i's aligned block of size k ...
                    ASSERT_EQ(p / k, progressivePermutationElement(i - i % k, n, seed) / k)
                        << "n=" << n << " k=" << k;  // ... maps into one block of size k
            }
            for (uint32_t j = 0; j < n; ++j) EXPECT_EQ(seen[j], 1) << "n=" << n;
        }
    }
    for (uint32_t n : {32u, 64u}) expectUniformPositions(progressivePermutationElement, n);
}

TEST(LowDiscrepancy, OwenScramblePreservesStrata) {
    // An Owen scramble maps each dyadic interval onto a dyadic interval of the same level:
    // values sharing their top k bits still share them afterwards.
    for (uint64_t seed : {3ull, 77ull}) {
        for (uint32_t v = 0; v < 4096; ++v) {
            uint32_t a = v << 20, b = (v << 20) | 0xfffffu;
            EXPECT_EQ(owenScramble(a, seed) >> 20, owenScramble(b, seed) >> 20);
        }
    }
}

TEST(LowDiscrepancy, SobolFirstDimensions) {
    EXPECT_EQ(sobolDim0(1), 0x80000000u);
    EXPECT_EQ(sobolDim0(2), 0x40000000u);
    EXPECT_EQ(sobolDim1(1), 0x80000000u);
    EXPECT_EQ(sobolDim1(2), 0xc0000000u);
    EXPECT_EQ(sobolDim1(3), 0x40000000u);  // points 0..3: (0,0) (.5,.5) (.25,.75) (.75,.25)
}

// ---- Factory -----------------------------------------------------------------------------

TEST(SamplerFactory, SampleCountsFollowPbrtV3) {
    struct Case {
        const char* name;
        int pixelsamples;  // 0: absent
        int override;
        int expected;
        bool note;
    };
    const Case cases[] = {
        {"random", 0, 0, 4, false},        {"random", 7, 0, 7, false},
        {"stratified", 0, 0, 16, false},   {"halton", 0, 0, 16, false},
        {"halton", 100, 0, 100, false},    {"sobol", 0, 0, 16, false},
        {"sobol", 100, 0, 128, true},      {"sobol", 100, 1000, 1024, true},
        {"sobol", 8192, 0, 8192, false},   {"02sequence", 5, 0, 8, true},
        {"lowdiscrepancy", 3, 0, 4, true}, {"zerotwosequence", 0, 0, 16, false},
        {"maxmindist", 100, 0, 128, true}, {"maxmindist", 200000, 0, 65536, true},
        {"random", 4, 9, 9, false},        {"stratified", 0, 12, 12, true},
    };
    for (const Case& c : cases) {
        ParamList params;
        if (c.pixelsamples) params.add(intParam("pixelsamples", c.pixelsamples));
        std::string error = "x", note = "x";
        auto s = createSampler(c.name, params, c.override, 1, &error, &note);
        ASSERT_TRUE(s) << c.name << ": " << error;
        EXPECT_EQ(s->samplesPerPixel(), c.expected) << c.name << " " << c.pixelsamples;
        EXPECT_EQ(!note.empty(), c.note) << c.name << ": " << note;
        EXPECT_TRUE(error.empty());
        if (c.note && c.expected != c.override) {
            EXPECT_NE(note.find(std::to_string(c.expected)), std::string::npos) << note;
        }
    }
}

TEST(SamplerFactory, StratifiedParameters) {
    ParamList params;
    params.add(intParam("xsamples", 3));
    params.add(intParam("ysamples", 5));
    params.add(boolParam("jitter", false));
    params.add(intParam("dimensions", 9));
    auto s = createSampler("stratified", params, 0, 1, nullptr, nullptr);
    ASSERT_TRUE(s);
    EXPECT_EQ(s->samplesPerPixel(), 15);
    for (const Param& p : params.params()) EXPECT_TRUE(p.used) << p.name;
}

TEST(SamplerFactory, RejectsUnknownNamesAndBadCounts) {
    std::string error, note;
    EXPECT_FALSE(createSampler("bluenoise", ParamList(), 0, 1, &error, &note));
    EXPECT_NE(error.find("bluenoise"), std::string::npos);
    ParamList zero;
    zero.add(intParam("pixelsamples", 0));
    error.clear();
    EXPECT_FALSE(createSampler("sobol", zero, 0, 1, &error, &note));
    EXPECT_FALSE(error.empty());
    ParamList badX;
    badX.add(intParam("xsamples", -2));
    error.clear();
    EXPECT_FALSE(createSampler("stratified", badX, 0, 1, &error, nullptr));
    EXPECT_FALSE(error.empty());
    for (const char* name : AllNames) EXPECT_TRUE(createSampler(name, ParamList(), 0, 1,
                                                                nullptr, nullptr));
}

// ---- Determinism and range ---------------------------------------------------------------

// Values of a fixed mix of get calls for one sample.
std::vector<float> sampleValues(Sampler& s, int px, int py, int index, int dim = 0) {
    s.startPixelSample(px, py, index, dim);
    std::vector<float> v;
    Vec2 p = s.getPixel2D();
    v.insert(v.end(), {p.x, p.y});
    for (int k = 0; k < 20; ++k) {
        v.push_back(s.get1D());
        Vec2 q = s.get2D();
        v.insert(v.end(), {q.x, q.y});
    }
    return v;
}

TEST(Sampler, DeterministicInSeedPixelIndexAndDimension) {
    for (const char* name : AllNames) {
        auto a = make(name, 0, 42), b = make(name, 0, 42), c = make(name, 0, 43);
        auto clone = a->clone();
        // b visits the samples in another order; results must not depend on history.
        std::vector<std::vector<float>> ref;
        for (int i = 0; i < 40; ++i) ref.push_back(sampleValues(*a, i % 7, i / 7, i % 5));
        for (int i = 39; i >= 0; --i) {
            EXPECT_EQ(sampleValues(*b, i % 7, i / 7, i % 5), ref[i]) << name;
            EXPECT_EQ(sampleValues(*clone, i % 7, i / 7, i % 5), ref[i]) << name;
        }
        EXPECT_NE(sampleValues(*c, 1, 2, 3), sampleValues(*a, 1, 2, 3)) << name;
        // Starting at dimension 5 equals skipping five dimensions with get1D.
        a->startPixelSample(3, 4, 1);
        for (int k = 0; k < 5; ++k) a->get1D();
        float skipped = a->get1D();
        a->startPixelSample(3, 4, 1, 5);
        EXPECT_EQ(a->get1D(), skipped) << name;
    }
}

TEST(Sampler, ClonesOnThreadsMatchSequentialResults) {
    auto proto = make("sobol", 16, 5);
    const int W = 32, H = 32, spp = 16;
    auto render = [&](Sampler& s, int y0, int y1, std::vector<float>* out) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < W; ++x)
                for (int i = 0; i < spp; ++i) {
                    s.startPixelSample(x, y, i);
                    float sum = s.getPixel2D().x;
                    for (int d = 0; d < 50; ++d) sum += s.get1D();
                    (*out)[(y * W + x) * spp + i] = sum;
                }
    };
    std::vector<float> seq(W * H * spp), par(W * H * spp);
    auto single = proto->clone();
    render(*single, 0, H, &seq);
    auto s0 = proto->clone(), s1 = proto->clone();
    std::thread t0([&] { render(*s0, 0, H / 2, &par); });
    std::thread t1([&] { render(*s1, H / 2, H, &par); });
    t0.join();
    t1.join();
    EXPECT_EQ(seq, par);
}

TEST(Sampler, ValuesInUnitInterval) {
    for (const char* name : AllNames) {
        for (int spp : {1, 3, 16, 64}) {
            auto s = make(name, spp);
            for (int px = 0; px < 16; ++px)
                for (int i = 0; i < 2 * spp; ++i) {
                    for (float v : sampleValues(*s, px, 3 - px, i)) {
                        ASSERT_GE(v, 0.f) << name;
                        ASSERT_LT(v, 1.f) << name;
                    }
                }
        }
    }
    // Stratum edges: many strata without jitter and with jitter.
    StratifiedSampler st(1, 4096, true, 1);
    for (int i = 0; i < 4096; ++i) {
        st.startPixelSample(0, 0, i);
        float v = st.get1D();
        Vec2 p = st.get2D();
        ASSERT_TRUE(v >= 0.f && v < 1.f && p.x >= 0.f && p.x < 1.f && p.y >= 0.f && p.y < 1.f);
    }
}

// ---- Stratification ----------------------------------------------------------------------

// The first spp points of a 2D pair starting at `dim` (get2D, or getPixel2D when dim == 0)
// and of the 1D dimension `dim`, for sample block `block`.
void collect(Sampler& s, int px, int py, int dim, int block, std::vector<Vec2>* pts2,
             std::vector<float>* pts1) {
    const int n = s.samplesPerPixel();
    pts2->clear();
    pts1->clear();
    for (int i = 0; i < n; ++i) {
        s.startPixelSample(px, py, block * n + i, dim);
        pts2->push_back(dim == 0 ? s.getPixel2D() : s.get2D());
        s.startPixelSample(px, py, block * n + i, dim);
        pts1->push_back(s.get1D());
    }
}

// Counts per cell of the 2^a x 2^b elementary-interval partition.
std::vector<int> cellCounts(const std::vector<Vec2>& pts, int a, int b) {
    std::vector<int> c(size_t(1) << (a + b), 0);
    for (Vec2 p : pts) ++c[(int(p.y * (1 << b)) << a) + int(p.x * (1 << a))];
    return c;
}

TEST(Sampler, SobolFamilyPointSetsAreZeroMTwoNets) {
    std::vector<Vec2> pts2;
    std::vector<float> pts1;
    for (const char* name : {"sobol", "02sequence", "maxmindist", "halton"}) {
        for (int m = 0; m <= 10; ++m) {
            const int n = 1 << m;
            auto s = make(name, n, 11);
            for (int dim : {0, 2, 7, 300, 999}) {
                for (int block : {0, 3}) {
                    collect(*s, 5 + dim, 9, dim, block, &pts2, &pts1);
                    for (int a = 0; a <= m; ++a)
                        for (int c : cellCounts(pts2, a, m - a))
                            ASSERT_EQ(c, 1) << name << " n=" << n << " dim=" << dim
                                            << " a=" << a;
                    std::vector<int> c1(n, 0);
                    for (float v : pts1) ++c1[int(v * n)];
                    for (int c : c1) ASSERT_EQ(c, 1) << name << " n=" << n << " dim=" << dim;
                }
            }
        }
    }
}

// A --time render that stops inside a block of the scene's pixelsamples takes its first
// samples: every prefix of 16 2^k samples of a block, and every aligned part of one that
// size, is a (0,k+4,2)-net in each 2D pair and stratified in each 1D dimension.
TEST(Sampler, SobolFamilyBlockPrefixesAreNets) {
    for (const char* name : {"sobol", "02sequence"}) {
        auto s = make(name, 256, 11);
        for (int dim : {0, 2, 7, 300}) {
            for (int first : {0, 16, 32, 64, 256 + 128}) {  // (the last in the second block)
                for (int m : {4, 6}) {
                    if (first % (1 << m) != 0) continue;  // (aligned parts only)
                    std::vector<Vec2> pts2;
                    std::vector<float> pts1;
                    for (int i = first; i < first + (1 << m); ++i) {
                        s->startPixelSample(3, 8, i, dim);
                        pts2.push_back(dim == 0 ? s->getPixel2D() : s->get2D());
                        s->startPixelSample(3, 8, i, dim);
                        pts1.push_back(s->get1D());
                    }
                    for (int a = 0; a <= m; ++a)
                        for (int c : cellCounts(pts2, a, m - a))
                            ASSERT_EQ(c, 1) << name << " dim=" << dim << " first=" << first
                                            << " m=" << m << " a=" << a;
                    std::vector<int> c1(size_t(1) << m, 0);
                    for (float v : pts1) ++c1[size_t(v * float(1 << m))];
                    for (int c : c1) ASSERT_EQ(c, 1) << name << " dim=" << dim;
                }
            }
        }
    }
}

// A --time render continues past pixelsamples with further blocks of spp samples: each block
// must pair the dimensions afresh. Two 1D dimensions over 32 blocks of 16: 512 points in the
// 16 x 16 cells of their coarse strata. The same permutation in every block puts them in the
// same 16 cells; fresh random pairings fill about 256 (1 - e^-2) = 221 of them.
TEST(Sampler, BlocksPastPixelSamplesPairDimensionsAfresh) {
    for (const char* name : {"sobol", "02sequence", "halton"}) {
        auto s = make(name, 16, 9);
        for (int dim : {3, 40}) {
            std::set<int> cells;
            std::vector<float> a, b;
            for (int i = 0; i < 512; ++i) {
                s->startPixelSample(6, 1, i, dim);
                const float u = s->get1D(), v = s->get1D();
                cells.insert(int(u * 16) * 16 + int(v * 16));
                a.push_back(u);
            }
            EXPECT_GT(cells.size(), 190u) << name << " dim " << dim;
            // The blocks together are still the sequence's first 512 points: stratified.
            std::vector<int> c1(512, 0);
            for (float v : a) ++c1[size_t(v * 512)];
            for (int c : c1) ASSERT_EQ(c, 1) << name;
        }
    }
}

TEST(Sampler, HaltonWithNonPowerOfTwoCountIsASequencePrefix) {
    // 12 = 8 + 4 points of a (0,2)-sequence: every 4-cell elementary partition holds 3,
    // every 8-cell partition holds at least 1.
    auto s = make("halton", 12, 3);
    ASSERT_EQ(s->samplesPerPixel(), 12);
    std::vector<Vec2> pts2;
    std::vector<float> pts1;
    for (int dim : {0, 4, 51}) {
        collect(*s, 1, 2, dim, 0, &pts2, &pts1);
        for (int a = 0; a <= 2; ++a)
            for (int c : cellCounts(pts2, a, 2 - a)) EXPECT_EQ(c, 3);
        for (int a = 0; a <= 3; ++a)
            for (int c : cellCounts(pts2, a, 3 - a)) EXPECT_GE(c, 1);
        std::vector<int> c1(4, 0);
        for (float v : pts1) ++c1[int(v * 4)];
        for (int c : c1) EXPECT_EQ(c, 3);
    }
}

TEST(Sampler, StratifiedHasOneSamplePerStratum) {
    std::vector<Vec2> pts2;
    std::vector<float> pts1;
    for (bool jitter : {true, false}) {
        StratifiedSampler s(3, 5, jitter, 17);
        for (int dim : {0, 2, 9, 500}) {
            for (int block : {0, 1}) {
                collect(s, 4, dim, dim, block, &pts2, &pts1);
                std::vector<int> c2(15, 0), c1(15, 0);
                for (Vec2 p : pts2) {
                    ++c2[int(p.y * 5) * 3 + int(p.x * 3)];
                    if (!jitter) {
                        EXPECT_FLOAT_EQ(std::fmod(p.x * 3, 1.f), 0.5f);
                        EXPECT_FLOAT_EQ(std::fmod(p.y * 5, 1.f), 0.5f);
                    }
                }
                for (float v : pts1) ++c1[int(v * 15)];
                for (int k = 0; k < 15; ++k) {
                    EXPECT_EQ(c2[k], 1);
                    EXPECT_EQ(c1[k], 1);
                }
            }
        }
    }
}

// ---- Uniformity and correlation across pixels --------------------------------------------

TEST(Sampler, UniformOverManyPixels) {
    // Sample i of different pixels is independent and uniform. Chi-square of a 16x16 (1D:
    // 64-bin) histogram of M points: mean = dof, sd = sqrt(2 dof); bound mean + 5 sd.
    const int side = 128, M = side * side;
    for (const char* name : AllNames) {
        auto s = make(name, 16, 21);
        for (int dim : {0, 6}) {
            for (int index : {0, 5}) {
                std::vector<double> h2(256, 0), h1(64, 0);
                for (int y = 0; y < side; ++y)
                    for (int x = 0; x < side; ++x) {
                        s->startPixelSample(x, y, index, dim);
                        Vec2 p = s->get2D();
                        ++h2[int(p.y * 16) * 16 + int(p.x * 16)];
                        ++h1[int(s->get1D() * 64)];
                    }
                double chi2 = 0, chi1 = 0;
                for (double c : h2) chi2 += (c - M / 256.0) * (c - M / 256.0) / (M / 256.0);
                for (double c : h1) chi1 += (c - M / 64.0) * (c - M / 64.0) / (M / 64.0);
                EXPECT_LT(chi2, 255 + 5 * std::sqrt(2 * 255.0)) << name << " dim " << dim;
                EXPECT_LT(chi1, 63 + 5 * std::sqrt(2 * 63.0)) << name << " dim " << dim;
            }
        }
    }
}

TEST(Sampler, DimensionsAndNeighbourPixelsAreUncorrelated) {
    // For M independent pairs the sample correlation coefficient has sd ~ 1/sqrt(M):
    // bound 4.5/sqrt(M).
    const int side = 100, M = side * side;
    const double bound = 4.5 / std::sqrt(double(M));
    for (const char* name : AllNames) {
        auto s = make(name, 16, 33);
        for (int dim : {0, 1, 2, 41, 300}) {
            std::vector<double> d0, d1, pairX, nextPairX, left, right, up;
            for (int y = 0; y < side; ++y)
                for (int x = 0; x < side; ++x) {
                    s->startPixelSample(x, y, 3, dim);
                    d0.push_back(s->get1D());
                    d1.push_back(s->get1D());
                    s->startPixelSample(x, y, 3, dim);
                    pairX.push_back(s->get2D().x);
                    nextPairX.push_back(s->get2D().x);
                    s->startPixelSample(2 * x, y, 3, dim);
                    left.push_back(s->get1D());
                    s->startPixelSample(2 * x + 1, y, 3, dim);
                    right.push_back(s->get1D());
                    s->startPixelSample(2 * x, y + 1, 3, dim);
                    up.push_back(s->get1D());
                }
            EXPECT_LT(std::fabs(pearson(d0, d1)), bound) << name << " dim " << dim;
            EXPECT_LT(std::fabs(pearson(pairX, nextPairX)), bound) << name << " dim " << dim;
            EXPECT_LT(std::fabs(pearson(left, right)), bound) << name << " dim " << dim;
            EXPECT_LT(std::fabs(pearson(left, up)), bound) << name << " dim " << dim;
        }
    }
}

TEST(Sampler, DimensionsAreUncorrelatedWithinAPixel) {
    // Within a pixel two dimensions pair the n samples by a random permutation: r has mean
    // 0 and variance 1/(n-1). Over P pixels: |mean r| < 4.5 / sqrt((n-1) P), and the mean of
    // r^2 must stay near 1/(n-1) (structured pairings such as shared index parity give ~0.5).
    const int n = 64, P = 2000;
    for (const char* name : AllNames) {
        auto s = make(name, n, 55);
        for (int dim : {1, 10, 200}) {
            double sumR = 0, sumR2 = 0, sumPairR = 0;
            std::vector<double> a(n), b(n), c(n);
            for (int p = 0; p < P; ++p) {
                for (int i = 0; i < n; ++i) {
                    s->startPixelSample(p, 7, i, dim);
                    a[i] = s->get1D();
                    b[i] = s->get1D();
                    c[i] = s->get2D().y;
                }
                const double r = pearson(a, b);
                sumR += r;
                sumR2 += r * r;
                sumPairR += pearson(b, c);
            }
            EXPECT_LT(std::fabs(sumR / P), 4.5 / std::sqrt((n - 1.0) * P)) << name;
            EXPECT_LT(std::fabs(sumPairR / P), 4.5 / std::sqrt((n - 1.0) * P)) << name;
            EXPECT_LT(sumR2 / P, 1.3 / (n - 1)) << name << " dim " << dim;
        }
    }
}

// ---- Convergence and bias ----------------------------------------------------------------

struct ErrorStats {
    double rmse, mean, stderrOfMean;
};

// Per-pixel estimates of the integral of exp(-x^2 - y^2) over [0,1)^2 with n samples from
// the 2D pair at dimension 4 (after the film and one 1D dimension), over P pixels.
ErrorStats integrationError(Sampler& s, int n, int P) {
    const double pi = 3.14159265358979323846;
    const double exact = std::pow(0.5 * std::sqrt(pi) * std::erf(1.0), 2);
    double sum = 0, sum2 = 0;
    for (int p = 0; p < P; ++p) {
        double est = 0;
        for (int i = 0; i < n; ++i) {
            s.startPixelSample(p % 16, p / 16, i, 4);
            Vec2 u = s.get2D();
            est += std::exp(-double(u.x) * u.x - double(u.y) * u.y);
        }
        const double err = est / n - exact;
        sum += err;
        sum2 += err * err;
    }
    const double mean = sum / P, var = std::max(sum2 / P - mean * mean, 0.0);
    return {std::sqrt(sum2 / P), mean, std::sqrt(var / (P - 1))};
}

TEST(Sampler, SobolConvergesFasterThanRandom) {
    // Random sampling: rmse = sigma_f / sqrt(N); (0,2)-nets: O(N^-1) or better for smooth
    // f, so the ratio is ~sqrt(N) = 32 up to constants at N = 1024: require > 8.
    const int N = 1024, P = 256;
    auto rnd = make("random", N, 3);
    ErrorStats r = integrationError(*rnd, N, P);
    for (const char* name : {"sobol", "02sequence", "halton"}) {
        auto s = make(name, N, 3);
        ErrorStats e = integrationError(*s, N, P);
        EXPECT_GT(r.rmse, 8 * e.rmse) << name << " rmse " << e.rmse << " vs " << r.rmse;
        EXPECT_LT(std::fabs(e.mean), 3 * e.stderrOfMean + 1e-9) << name;
    }
    // Jittered 32x32 strata: rmse O(N^-1) in 2D as well; require > 4.
    StratifiedSampler st(32, 32, true, 3);
    ErrorStats e = integrationError(st, N, P);
    EXPECT_GT(r.rmse, 4 * e.rmse) << "stratified rmse " << e.rmse << " vs " << r.rmse;
    EXPECT_LT(std::fabs(e.mean), 3 * e.stderrOfMean) << "stratified";
    EXPECT_LT(std::fabs(r.mean), 3 * r.stderrOfMean) << "random";
    // A non-power-of-two halton count still beats random clearly.
    auto h = make("halton", 1000, 3);
    e = integrationError(*h, 1000, P);
    EXPECT_GT(r.rmse, 4 * e.rmse) << "halton 1000 rmse " << e.rmse;
    EXPECT_LT(std::fabs(e.mean), 3 * e.stderrOfMean) << "halton 1000";
}

}  // namespace
}  // namespace rlpbrt
