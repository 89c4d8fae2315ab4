// The integrator's Russian roulette policies: pbrt-v3's on the throughput, and the adjoint-
// driven one on the path's expected contribution (GuideSettings::adjointRoulette). Each
// returns false if the path ends here, else true with *beta divided by the survival
// probability; each draws a sampler dimension only when it plays.
#pragma once

#include <algorithm>

#include "render/sampler.h"
#include "render/spectrum.h"

namespace rlpbrt {

// pbrt-v3's: after bounce 3, a throughput (scaled by the refraction eta) below `threshold`
// survives with probability 1 - max(0.05, 1 - its largest component), as in pbrt-v3's `path`.
inline bool pbrtRoulette(Spectrum* beta, float etaScale, int bounces, float threshold,
                         Sampler& sampler) {
    const float m = maxComponent(*beta * etaScale);
    if (!(m < threshold) || bounces <= 3) return true;
    const float q = std::max(0.05f, 1.f - m);
    if (sampler.get1D() < q) return false;
    *beta /= 1.f - q;
    return true;
}

// Adjoint-driven (Vorba and Krivanek 2016, without splitting): a path whose expected
// contribution (throughput x the learned light of its direction) is below `low` (the weight
// window's lower edge: rr-window x the pixel's estimate) survives with the ratio, at least
// minSurvival (which bounds a survivor's weight).
inline bool adjointRoulette(Spectrum* beta, float expected, float low, float minSurvival,
                            Sampler& sampler) {
    if (!(expected < low)) return true;
    const float survive = std::max(expected / low, minSurvival);
    if (sampler.get1D() >= survive) return false;
    *beta /= survive;
    return true;
}

}  // namespace rlpbrt
