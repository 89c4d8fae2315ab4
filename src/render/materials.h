// Materials with pbrt-v3's semantics: they evaluate their textures at a surface point and set
// up a BSDF (bsdf.h). Types: matte, plastic, metal, glass, mirror, uber, substrate,
// translucent, mix, disney, fourier, hair (hair.h); "" / "none" / "interface" mark medium
// boundaries (no Material object).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "parser/diagnostics.h"
#include "render/bsdf.h"
#include "render/interaction.h"
#include "render/scene_desc.h"
#include "render/textures.h"

namespace rlpbrt {

class Material {
public:
    virtual ~Material();
    // Sets up `bsdf` at the hit `si`. `u` in [0,1) chooses between the parts of a mix
    // material (each part with the probability of its weight: unbiased on average).
    virtual void computeBSDF(const SurfaceInteraction& si, float u, BSDF* bsdf) const = 0;
};

// Creates the material of an entity. `named` resolves the names used by "mix" (index into
// `materials`, which holds the materials made so far; -1 if undefined). Errors and ignored
// features are reported at the entity's (or parameter's) location. Returns null for an
// interface material (type "", "none", "interface") and on error (then *ok is false).
std::unique_ptr<Material> createMaterial(const MaterialEntity& e, TextureResolver& textures,
                                         const std::vector<const Material*>& materials,
                                         const std::vector<std::string>& materialNames,
                                         Diagnostics& diag, bool* ok);

// The texture context of a surface hit (no ray differentials: point lookups).
TextureContext textureContext(const SurfaceInteraction& si);

}  // namespace rlpbrt
