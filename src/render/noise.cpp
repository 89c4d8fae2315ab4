// Perlin noise, fBm and turbulence (pbrt-v3 semantics; see noise.h).
#include "render/noise.h"

#include <cstdint>

namespace rlpbrt {

namespace {

// Permutation of 0..255 from Ken Perlin's reference implementation of "Improved Noise"
// (SIGGRAPH 2002), the table pbrt-v3 uses in src/core/texture.cpp (where it is stored
// twice in a row; here indices are wrapped with & 255 instead, which is equivalent).
constexpr uint8_t kPerm[256] = {
    151, 160, 137,  91,  90,  15, 131,  13, 201,  95,  96,  53, 194, 233,   7, 225,
    140,  36, 103,  30,  69, 142,   8,  99,  37, 240,  21,  10,  23, 190,   6, 148,
    247, 120, 234,  75,   0,  26, 197,  62,  94, 252, 219, 203, 117,  35,  11,  32,
     57, 177,  33,  88, 237, 149,  56,  87, 174,  20, 125, 136, 171, 168,  68, 175,
     74, 165,  71, 134, 139,  48,  27, 166,  77, 146, 158, 231,  83, 111, 229, 122,
     60, 211, 133, 230, 220, 105,  92,  41,  55,  46, 245,  40, 244, 102, 143,  54,
     65,  25,  63, 161,   1, 216,  80,  73, 209,  76, 132, 187, 208,  89,  18, 169,
    200, 196, 135, 130, 116, 188, 159,  86, 164, 100, 109, 198, 173, 186,   3,  64,
     52, 217, 226, 250, 124, 123,   5, 202,  38, 147, 118, 126, 255,  82,  85, 212,
    207, 206,  59, 227,  47,  16,  58,  17, 182, 189,  28,  42, 223, 183, 170, 213,
    119, 248, 152,   2,  44, 154, 163,  70, 221, 153, 101, 155, 167,  43, 172,   9,
    129,  22,  39, 253,  19,  98, 108, 110,  79, 113, 224, 232, 178, 185, 112, 104,
    218, 246,  97, 228, 251,  34, 242, 193, 238, 210, 144,  12, 191, 179, 162, 241,
     81,  51, 145, 235, 249,  14, 239, 107,  49, 192, 214,  31, 181, 199, 106, 157,
    184,  84, 204, 176, 115, 121,  50,  45, 127,   4, 150, 254, 138, 236, 205,  93,
    222, 114,  67,  29,  24,  72, 243, 141, 128, 195,  78,  66, 215,  61, 156, 180,
};

inline int perm(int i) { return kPerm[i & 255]; }

// Dot product of the gradient picked by the hash of lattice point (x, y, z) with the offset
// (dx, dy, dz): one of the 12 cube-edge directions (4 of them repeated), as in pbrt-v3.
inline float gradient(int x, int y, int z, float dx, float dy, float dz) {
    int h = perm(perm(perm(x) + y) + z) & 15;
    float u = (h < 8 || h == 12 || h == 13) ? dx : dy;
    float v = (h < 4 || h == 12 || h == 13) ? dy : dz;
    return ((h & 1) ? -u : u) + ((h & 2) ? -v : v);
}

// Quintic fade curve 6t^5 - 15t^4 + 10t^3.
inline float fade(float t) {
    float t3 = t * t * t;
    return t3 * (t * (6 * t - 15) + 10);
}

inline float smoothStep(float lo, float hi, float v) {
    float t = clamp((v - lo) / (hi - lo), 0.f, 1.f);
    return t * t * (3 - 2 * t);
}

// Number of octaves (fractional) that the screen-space footprint allows: the Nyquist limit
// for a footprint of length sqrt(len2) is -1 - log2(len), clamped to [0, maxOctaves].
inline float octaveCount(const Vec3& dpdx, const Vec3& dpdy, int maxOctaves) {
    float len2 = std::max(glm::dot(dpdx, dpdx), glm::dot(dpdy, dpdy));
    return clamp(-1.f - 0.5f * std::log2(len2), 0.f, float(maxOctaves));
}

}  // namespace

float perlinNoise(float x, float y, float z) {
    float fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
    float dx = x - fx, dy = y - fy, dz = z - fz;
    int ix = int(fx) & 255, iy = int(fy) & 255, iz = int(fz) & 255;

    float w000 = gradient(ix, iy, iz, dx, dy, dz);
    float w100 = gradient(ix + 1, iy, iz, dx - 1, dy, dz);
    float w010 = gradient(ix, iy + 1, iz, dx, dy - 1, dz);
    float w110 = gradient(ix + 1, iy + 1, iz, dx - 1, dy - 1, dz);
    float w001 = gradient(ix, iy, iz + 1, dx, dy, dz - 1);
    float w101 = gradient(ix + 1, iy, iz + 1, dx - 1, dy, dz - 1);
    float w011 = gradient(ix, iy + 1, iz + 1, dx, dy - 1, dz - 1);
    float w111 = gradient(ix + 1, iy + 1, iz + 1, dx - 1, dy - 1, dz - 1);

    float wx = fade(dx), wy = fade(dy), wz = fade(dz);
    float y0 = lerp(wy, lerp(wx, w000, w100), lerp(wx, w010, w110));
    float y1 = lerp(wy, lerp(wx, w001, w101), lerp(wx, w011, w111));
    return lerp(wz, y0, y1);
}

float perlinNoise(const Vec3& p) { return perlinNoise(p.x, p.y, p.z); }

float fbm(const Vec3& p, const Vec3& dpdx, const Vec3& dpdy, float omega, int maxOctaves) {
    float n = octaveCount(dpdx, dpdy, maxOctaves);
    int nInt = int(std::floor(n));
    float sum = 0, lambda = 1, o = 1;
    for (int i = 0; i < nInt; ++i) {
        sum += o * perlinNoise(lambda * p);
        lambda *= 1.99f;
        o *= omega;
    }
    // Fade the last, partial octave in smoothly.
    float partial = n - float(nInt);
    sum += o * smoothStep(0.3f, 0.7f, partial) * perlinNoise(lambda * p);
    return sum;
}

float turbulence(const Vec3& p, const Vec3& dpdx, const Vec3& dpdy, float omega,
                 int maxOctaves) {
    float n = octaveCount(dpdx, dpdy, maxOctaves);
    int nInt = int(std::floor(n));
    float sum = 0, lambda = 1, o = 1;
    for (int i = 0; i < nInt; ++i) {
        sum += o * std::abs(perlinNoise(lambda * p));
        lambda *= 1.99f;
        o *= omega;
    }
    // Blend the partial octave towards the average |noise| (0.2), then add that average for
    // every octave that was cut off (pbrt-v3 keeps the amplitude o unchanged here).
    float partial = n - float(nInt);
    sum += o * lerp(smoothStep(0.3f, 0.7f, partial), 0.2f, std::abs(perlinNoise(lambda * p)));
    for (int i = nInt; i < maxOctaves; ++i) {
        sum += o * 0.2f;
        o *= omega;
    }
    return sum;
}

}  // namespace rlpbrt
