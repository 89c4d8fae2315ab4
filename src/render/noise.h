// Perlin gradient noise, fractional Brownian motion and turbulence with pbrt-v3's semantics
// (same permutation table, gradient selection, quintic fade and octave clamping), so that
// the procedural textures built on them (fbm, wrinkled, windy, marble, dots) match pbrt-v3.
#pragma once

#include "render/math.h"

namespace rlpbrt {

// Perlin noise at (x, y, z); values lie in about [-1, 1] and are 0 at integer lattice points.
// The defaults y = z = 0.5 give pbrt-v3's 1D/2D noise.
float perlinNoise(float x, float y = 0.5f, float z = 0.5f);
// Perlin noise at point p.
float perlinNoise(const Vec3& p);

// Fractional Brownian motion: sum of octaves of noise with frequency ratio 1.99 and
// amplitude ratio omega. The number of octaves is reduced (smoothly) when the screen-space
// differentials dpdx/dpdy of p are large, to avoid aliasing; zero differentials give
// maxOctaves octaves.
float fbm(const Vec3& p, const Vec3& dpdx, const Vec3& dpdy, float omega, int maxOctaves);

// Turbulence: like fbm but sums |noise|; octaves removed for antialiasing are replaced by
// their average value 0.2 (pbrt-v3's rule).
float turbulence(const Vec3& p, const Vec3& dpdx, const Vec3& dpdy, float omega,
                 int maxOctaves);

}  // namespace rlpbrt
