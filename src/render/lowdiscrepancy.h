// Building blocks of the samplers: 64-bit hashing, bit reversal, the first two Sobol'
// dimensions, hash-based Owen scrambling (Burley 2020, "Practical Hash-based Owen Scrambling")
// and random permutations of [0, n) evaluated one element at a time.
// All functions are pure and inline: they sit on the sampler's per-dimension fast path.
#pragma once

#include <cstdint>

namespace rlpbrt {

// Bijective 64-bit finalizer; constants from Stafford's "Mix13" variant of the MurmurHash3
// finalizer (as used by SplitMix64).
inline uint64_t mixBits(uint64_t v) {
    v ^= v >> 30;
    v *= 0xbf58476d1ce4e5b9ULL;
    v ^= v >> 27;
    v *= 0x94d049bb133111ebULL;
    v ^= v >> 31;
    return v;
}

// Bijective 32-bit hash; constants from Wellons' hash-prospector ("lowbias32").
inline uint32_t mixBits32(uint32_t v) {
    v ^= v >> 16;
    v *= 0x7feb352du;
    v ^= v >> 15;
    v *= 0x846ca68bu;
    v ^= v >> 16;
    return v;
}

// Weyl increment (2^64 / golden ratio, odd): consecutive keys k + i * GoldenGamma give
// independent-looking hashes after mixBits (the SplitMix64 construction).
constexpr uint64_t GoldenGamma = 0x9e3779b97f4a7c15ULL;

// Hash of a running hash `h` and one more value.
inline uint64_t hashCombine(uint64_t h, uint64_t v) {
    return mixBits(h ^ mixBits(v + GoldenGamma));
}

// Reverses the order of the 32 bits of v.
inline uint32_t reverseBits32(uint32_t v) {
    v = (v << 16) | (v >> 16);
    v = ((v & 0x00ff00ffu) << 8) | ((v & 0xff00ff00u) >> 8);
    v = ((v & 0x0f0f0f0fu) << 4) | ((v & 0xf0f0f0f0u) >> 4);
    v = ((v & 0x33333333u) << 2) | ((v & 0xccccccccu) >> 2);
    v = ((v & 0x55555555u) << 1) | ((v & 0xaaaaaaaau) >> 1);
    return v;
}

// Maps 32 random bits to a float in [0, 1) (the top 24 bits, so the result is exact and < 1).
inline float bitsToUnitFloat(uint32_t v) { return float(v >> 8) * 0x1p-24f; }

// First Sobol' dimension (van der Corput, base 2) of index i, as a 0.32 fixed-point value.
inline uint32_t sobolDim0(uint32_t i) { return reverseBits32(i); }

// Second Sobol' dimension (primitive polynomial x + 1: its generator matrix is Pascal's
// triangle mod 2) of index i, bit-reversed: bit j of the result is the XOR of the index bits
// k whose positions are bitwise supersets of j (Lucas: C(k, j) is odd iff j is a subset of
// k), the superset-sum transform over the 5 position bits (no loop over the index bits).
inline uint32_t sobolDim1Reversed(uint32_t i) {
    i ^= (i >> 1) & 0x55555555u;
    i ^= (i >> 2) & 0x33333333u;
    i ^= (i >> 4) & 0x0f0f0f0fu;
    i ^= (i >> 8) & 0x00ff00ffu;
    i ^= (i >> 16) & 0x0000ffffu;
    return i;
}

// Second Sobol' dimension of index i as a 0.32 fixed-point value. With sobolDim0 it forms a
// (0,2)-sequence: every aligned block of 2^m indices is a (0,m,2)-net.
inline uint32_t sobolDim1(uint32_t i) { return reverseBits32(sobolDim1Reversed(i)); }

// Bijection of 32-bit words in which output bit j depends only on input bits 0..j and the
// seed (additions and x ^= x * even only carry upwards). Applied to bit-reversed values it is
// a nested uniform (Owen) scramble; the fixed multipliers were chosen by a search over random
// even constants for the best upward avalanche (|P(flip) - 0.5| < 0.01 for all bit pairs,
// averaged over seeds).
inline uint32_t ascendingHash(uint32_t x, uint64_t seed) {
    uint64_t seed2 = (seed ^ (seed >> 31)) * 0xd6e8feb86659fd93ULL;  // two more seed words
    seed2 ^= seed2 >> 29;
    x += uint32_t(seed);
    x ^= x * (uint32_t(seed >> 32) << 1);
    x ^= x * 0x1238a77au;
    x += uint32_t(seed2);
    x ^= x * (uint32_t(seed2 >> 32) << 1);
    x ^= x * 0x55fb2bbau;
    return x;
}

// Owen scramble of a 0.32 fixed-point value: bit k (from the most significant) is flipped by
// a seed-dependent function of the bits above it. Preserves (t,m,s)-net properties.
inline uint32_t owenScramble(uint32_t v, uint64_t seed) {
    return reverseBits32(ascendingHash(reverseBits32(v), seed));
}

namespace detail {
// Sixteen fixed random permutations of [0, 2^k) for k = 1..4 (Fisher-Yates driven by
// splitmix64 from a fixed state, evaluated at compile time), entry j of a permutation in bits
// 4j..4j+3: the S-boxes of the small-n permutations below. Only k = 3 and 4 are used; k = 1
// and 2 stay in the generator's stream so that the boxes in use keep their values.
struct SmallPermutationBoxes {
    uint64_t box[4][16];
};
constexpr SmallPermutationBoxes makeSmallPermutationBoxes() {
    SmallPermutationBoxes t{};
    uint64_t state = 0x243F6A8885A308D3ull;
    for (int k = 1; k <= 4; ++k) {
        const int n = 1 << k;
        for (int b = 0; b < 16; ++b) {
            uint8_t a[16] = {};
            for (int e = 0; e < n; ++e) a[e] = uint8_t(e);
            for (int e = n - 1; e > 0; --e) {
                state += 0x9E3779B97F4A7C15ull;
                uint64_t z = state;
                z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
                z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
                z ^= z >> 31;
                const int r = int(z % uint64_t(e + 1));
                const uint8_t tmp = a[e];
                a[e] = a[r];
                a[r] = tmp;
            }
            uint64_t packed = 0;
            for (int e = 0; e < n; ++e) packed |= uint64_t(a[e]) << (4 * e);
            t.box[k - 1][b] = packed;
        }
    }
    return t;
}
inline constexpr SmallPermutationBoxes kSmallPermutationBoxes = makeSmallPermutationBoxes();

// All 24 permutations of [0, 4), packed the same way (n of 3 and 4 draw one uniformly).
struct AllPermutationsOf4 {
    uint64_t perm[24];
};
constexpr AllPermutationsOf4 makeAllPermutationsOf4() {
    AllPermutationsOf4 t{};
    int count = 0;
    for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
            for (int c = 0; c < 4; ++c)
                for (int d = 0; d < 4; ++d)
                    if (a != b && a != c && a != d && b != c && b != d && c != d)
                        t.perm[count++] = uint64_t(a) | uint64_t(b) << 4 | uint64_t(c) << 8 |
                                          uint64_t(d) << 12;
    return t;
}
inline constexpr AllPermutationsOf4 kAllPermutationsOf4 = makeAllPermutationsOf4();
}  // namespace detail

// Element i of a pseudo-random permutation of [0, n) chosen by seed (which should be well
// mixed, e.g. a hash).
// - n > 16: Kensler's hash-based permutation ("Correlated Multi-Jittered Sampling", Pixar TM
//   13-01, 2013), an invertible hash on the next power of two with cycle walking.
// - n <= 16: Kensler's hash draws from a small, structured family there (16356 distinct
//   permutations of 16 over 100000 seeds, 8 of the 24 of 4), so a padded sampler's
//   dimensions were paired alike from block to block: a caustic-glass `--time 8` render
//   (blocks of 16) had relMSE 0.00051, against 0.00015 now. n <= 4: one of the 24
//   permutations of 4, uniformly; n <= 16: three rounds of (XOR with a key, one of 16 fixed
//   random S-boxes) on ceil(log2 n) bits, keys and S-box choices from the seed's bits. Both
//   with cycle walking.
inline uint32_t permutationElement(uint32_t i, uint32_t n, uint64_t seed) {
    if (n <= 1) return 0;
    uint32_t w = n - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    if (n <= 4) {
        // One of the 24 permutations of 4, uniformly (n = 3: cycle walking, also uniform).
        const uint64_t perm = detail::kAllPermutationsOf4.perm[(seed ^ (seed >> 29)) % 24];
        do i = uint32_t(perm >> (4 * i)) & 15u;
        while (i >= n);
        return i;
    }
    if (n <= 16) {
        const int k = w == 7 ? 2 : 3;
        const uint64_t* boxes = detail::kSmallPermutationBoxes.box[k];
        const uint64_t h = seed ^ (seed >> 29);
        do {
            uint32_t x = i;
            x = uint32_t(boxes[h & 15] >> (4 * ((x ^ uint32_t(h >> 4)) & w))) & 15u;
            x = uint32_t(boxes[(h >> 8) & 15] >> (4 * ((x ^ uint32_t(h >> 12)) & w))) & 15u;
            x = uint32_t(boxes[(h >> 16) & 15] >> (4 * ((x ^ uint32_t(h >> 20)) & w))) & 15u;
            i = x ^ (uint32_t(h >> 24) & w);
        } while (i >= n);
        return i;
    }
    const uint32_t p = uint32_t(seed) ^ uint32_t(seed >> 32);
    do {
        i ^= p;
        i *= 0xe170893du;
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i *= 0x0929eb3fu;
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i *= 1u | p >> 27;
        i *= 0x6935fa69u;
        i ^= (i & w) >> 11;
        i *= 0x74dcb303u;
        i ^= (i & w) >> 2;
        i *= 0x9e501cc3u;
        i ^= (i & w) >> 2;
        i *= 0xc860a3dfu;
        i &= w;
        i ^= i >> 5;
    } while (i >= n);
    return (i + p) % n;
}

// Element i of a permutation of [0, n), n a power of two, chosen by seed, that keeps prefixes
// stratified: the runs of 16 indices are shuffled by a nested uniform (Owen) scramble of
// their numbers (bit j flipped by a seed-dependent function of the bits above it, so every
// aligned block of 2^k runs maps onto an aligned block of runs), the indices within a run by
// permutationElement seeded per run. A prefix of 16 2^k indices, and any aligned block of
// that size, is then an aligned block of the unshuffled sequence: for the Sobol'
// (0,2)-sequence a net, so a render that stops inside a block of samples keeps the
// stratification of what it took (Burley 2020, "Practical Hash-based Owen Scrambling",
// section 4, shuffles by a nested scramble alone; pbrt-v4's ZSobolSampler permutes base-4
// digits alike). Within a run a random permutation, as for n <= 16 (where this is
// permutationElement): a nested scramble there pairs two dimensions' values alike level by
// level (the correlation of two dimensions over a pixel's 64 samples had 1.6 times the
// variance of a random pairing's) and cost 1.5-2% more error per sample at 16 spp.
inline uint32_t progressivePermutationElement(uint32_t i, uint32_t n, uint64_t seed) {
    if (n <= 16) return permutationElement(i, n, seed);
    const uint32_t run = owenScramble(i >> 4, seed) & ((n >> 4) - 1);
    return run << 4 | permutationElement(i & 15u, 16, mixBits(seed + (run + 1) * GoldenGamma));
}

}  // namespace rlpbrt
