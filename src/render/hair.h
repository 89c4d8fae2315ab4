// The "hair" material (pbrt-v3's semantics): HairBxDF (declared in bxdfs.h, the lobe
// variant's home; implemented in hair.cpp) with its absorption given directly ("sigma_a"), by
// a colour ("color"), or by pigment concentrations ("eumelanin", "pheomelanin").
#pragma once

#include <memory>

#include "parser/diagnostics.h"
#include "render/materials.h"
#include "render/scene_desc.h"
#include "render/textures.h"

namespace rlpbrt {

// Absorption coefficient of hair with the given eumelanin and pheomelanin concentrations.
Spectrum hairSigmaAFromConcentration(float eumelanin, float pheomelanin);
// Absorption coefficient that gives hair of azimuthal roughness betaN the colour c after
// multiple scattering (Chiang et al. 2016's fit).
Spectrum hairSigmaAFromReflectance(const Spectrum& c, float betaN);

// The material of a "hair" Material entity (parameters sigma_a, color, eumelanin,
// pheomelanin, eta, beta_m, beta_n, alpha); the parameters that one of higher priority
// overrides are reported as warnings at the entity.
std::unique_ptr<Material> createHairMaterial(const MaterialEntity& e, TextureResolver& tex,
                                             Diagnostics& diag);

}  // namespace rlpbrt
