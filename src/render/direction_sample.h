// A direction drawn at a path vertex by the integrator's sampling seam: from the BSDF (or the
// phase function), or from the guide mixed with it (one-sample MIS).
#pragma once

#include "render/math.h"
#include "render/spectrum.h"

namespace rlpbrt {

struct DirectionSample {
    Spectrum f{0.f};  // BSDF value (phase value in a medium) at wi
    Vec3 wi{0.f};
    float pdf = 0.f;  // of the whole strategy (the mixture's pdf when guided)
    bool specular = false;
    bool transmission = false;
    // Guided strategies only: the guide's and the BSDF's (phase function's) pdfs of wi, and the
    // factor of the region's selection in the guide probability (confidence x share).
    float pGuide = 0.f, pOther = 0.f, scale = 0.f;
    // The guide's bin of wi in the region it was drawn with (GuidingField::pdf), or -1.
    int bin = -1;
};

}  // namespace rlpbrt
