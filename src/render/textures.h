// Textures with pbrt-v3's semantics: float and spectrum (RGB) textures evaluated at a shading
// point, 2D/3D texture-coordinate mappings, the texture factory, and bump mapping.
//
// Texture types (float and spectrum unless noted): constant, scale, mix, bilerp, imagemap,
// uv (spectrum only), checkerboard (2D with aamode closedform/none, and 3D), dots, fbm,
// wrinkled, windy, marble (spectrum only). ptex is not supported.
//
// Transforms: the factory takes the CTM at the Texture directive (`worldFromTexture`, pbrt-v3's
// `tex2world`). As in pbrt-v3, the spherical and cylindrical 2D mappings use its inverse, but
// the 3D identity mapping (fbm, wrinkled, windy, marble, 3D checkerboard) applies the CTM
// itself to world-space points: pbrt-v3 passes tex2world where IdentityMapping3D expects
// WorldToTexture, and scenes are authored against that behaviour.
#pragma once

#include <memory>
#include <string>

#include <glm/glm.hpp>

#include "parser/params.h"
#include "render/math.h"
#include "render/mipmap.h"

namespace rlpbrt {

// Geometry at which a texture is evaluated.
struct TextureContext {
    Vec3 p{0.f};                // world-space point
    Vec3 dpdx{0.f}, dpdy{0.f};  // screen-space differentials of p (zero: no filtering)
    Vec3 n{0.f};                // shading normal
    Vec2 uv{0.f};               // surface (u, v) parameterization
    float dudx = 0, dudy = 0, dvdx = 0, dvdy = 0;  // screen-space differentials of (u, v)
};

class FloatTexture {
public:
    virtual ~FloatTexture();
    // Value of the texture at the context's point (unitless unless the use defines one).
    virtual float evaluate(const TextureContext& ctx) const = 0;
};

class SpectrumTexture {
public:
    virtual ~SpectrumTexture();
    // Linear RGB value of the texture at the context's point.
    virtual Spectrum evaluate(const TextureContext& ctx) const = 0;
};

// A float texture with the same value everywhere (materials may test for it to skip work).
class ConstantFloatTexture : public FloatTexture {
public:
    explicit ConstantFloatTexture(float value) : value_(value) {}
    float evaluate(const TextureContext&) const override { return value_; }
    // The constant value.
    float value() const { return value_; }

private:
    float value_;
};

// A spectrum texture with the same value everywhere.
class ConstantSpectrumTexture : public SpectrumTexture {
public:
    explicit ConstantSpectrumTexture(const Spectrum& value) : value_(value) {}
    Spectrum evaluate(const TextureContext&) const override { return value_; }
    // The constant value.
    const Spectrum& value() const { return value_; }

private:
    Spectrum value_;
};

// ---------------------------------------------------------------------------------------------
// Texture-coordinate mappings.

// Maps a shading point to 2D texture coordinates (s, t) and their screen-space differentials.
class TextureMapping2D {
public:
    virtual ~TextureMapping2D();
    // (s, t) at ctx; *dstdx, *dstdy receive d(s,t)/dx and d(s,t)/dy.
    virtual Vec2 map(const TextureContext& ctx, Vec2* dstdx, Vec2* dstdy) const = 0;
};

// (s, t) = (su * u + du, sv * v + dv).
class UVMapping2D : public TextureMapping2D {
public:
    UVMapping2D(float su = 1, float sv = 1, float du = 0, float dv = 0)
        : su_(su), sv_(sv), du_(du), dv_(dv) {}
    Vec2 map(const TextureContext& ctx, Vec2* dstdx, Vec2* dstdy) const override;

private:
    float su_, sv_, du_, dv_;
};

// (s, t) = (theta / pi, phi / 2pi) of the direction from the texture-space origin to the point
// (theta measured from +z, phi from +x in [0, 2pi)).
class SphericalMapping2D : public TextureMapping2D {
public:
    explicit SphericalMapping2D(const Mat4& textureFromWorld)
        : textureFromWorld_(textureFromWorld) {}
    Vec2 map(const TextureContext& ctx, Vec2* dstdx, Vec2* dstdy) const override;

private:
    Vec2 sphere(const Vec3& p) const;
    Mat4 textureFromWorld_;
};

// (s, t) = ((pi + atan2(y, x)) / 2pi, z) of the normalized texture-space direction to the
// point (pbrt-v3 normalizes before taking z).
class CylindricalMapping2D : public TextureMapping2D {
public:
    explicit CylindricalMapping2D(const Mat4& textureFromWorld)
        : textureFromWorld_(textureFromWorld) {}
    Vec2 map(const TextureContext& ctx, Vec2* dstdx, Vec2* dstdy) const override;

private:
    Vec2 cylinder(const Vec3& p) const;
    Mat4 textureFromWorld_;
};

// (s, t) = (ds + p . vs, dt + p . vt) with p in world space (pbrt-v3 ignores the CTM here).
class PlanarMapping2D : public TextureMapping2D {
public:
    PlanarMapping2D(const Vec3& vs, const Vec3& vt, float ds = 0, float dt = 0)
        : vs_(vs), vt_(vt), ds_(ds), dt_(dt) {}
    Vec2 map(const TextureContext& ctx, Vec2* dstdx, Vec2* dstdy) const override;

private:
    Vec3 vs_, vt_;
    float ds_, dt_;
};

// Maps a shading point to a 3D texture-space point and its screen-space differentials.
class TextureMapping3D {
public:
    virtual ~TextureMapping3D();
    // Texture-space point at ctx; *dpdx, *dpdy receive its differentials.
    virtual Vec3 map(const TextureContext& ctx, Vec3* dpdx, Vec3* dpdy) const = 0;
};

// p_tex = M * p_world (M: see the note at the top of this file).
class IdentityMapping3D : public TextureMapping3D {
public:
    explicit IdentityMapping3D(const Mat4& m) : m_(m) {}
    Vec3 map(const TextureContext& ctx, Vec3* dpdx, Vec3* dpdy) const override;

private:
    Mat4 m_;
};

// ---------------------------------------------------------------------------------------------
// Creation.

// Resolves a material/texture parameter: a "texture" param naming a declared texture,
// or an inline float/spectral value, or the default. Provided by the caller (scene builder).
struct TextureResolver {
    virtual ~TextureResolver() = default;
    // The float texture for parameter `name` of the list, or a constant `def` when absent.
    virtual std::shared_ptr<FloatTexture> floatTex(const ParamList&, const std::string& name,
                                                   float def) = 0;
    // The spectrum texture for parameter `name` of the list, or a constant `def` when absent.
    virtual std::shared_ptr<SpectrumTexture> spectrumTex(const ParamList&,
                                                         const std::string& name,
                                                         Spectrum def) = 0;
};

// Creates a float texture of pbrt-v3 type `type` ("constant", "imagemap", ...) from the
// Texture directive's parameters. `worldFromTexture` is the CTM at the directive. Image maps
// are shared through `cache` (a private cache is used when null: no sharing). Returns null and
// sets *error for unknown/unsupported types, bad parameter values or unreadable images.
// Warnings (e.g. an unknown aamode) go to params.diagnostics() when set.
std::shared_ptr<FloatTexture> createFloatTexture(const std::string& type, const ParamList& params,
                                                 const glm::mat4& worldFromTexture,
                                                 TextureResolver& resolver, std::string* error,
                                                 MipMapCache* cache = nullptr);

// Creates a spectrum ("color"/"spectrum" kind) texture; same contract as createFloatTexture.
std::shared_ptr<SpectrumTexture> createSpectrumTexture(const std::string& type,
                                                       const ParamList& params,
                                                       const glm::mat4& worldFromTexture,
                                                       TextureResolver& resolver,
                                                       std::string* error,
                                                       MipMapCache* cache = nullptr);

// ---------------------------------------------------------------------------------------------
// Bump mapping.

// Shading geometry at a hit point, as needed by bump().
struct BumpInput {
    Vec3 p{0.f};                // world-space point
    Vec3 n{0.f};                // geometric normal (unit; its side decides the result's side)
    Vec3 ns{0.f};               // shading normal (unit)
    Vec3 dpdu{0.f}, dpdv{0.f};  // shading partial derivatives of p
    Vec3 dndu{0.f}, dndv{0.f};  // shading normal derivatives
    Vec2 uv{0.f};               // surface parameterization
    Vec3 dpdx{0.f}, dpdy{0.f};  // screen-space differentials of p (may be zero)
    float dudx = 0, dudy = 0, dvdx = 0, dvdy = 0;  // screen-space differentials of (u, v)
};

// pbrt-v3's Material::Bump: displaces the surface along ns by the float texture d (in world
// units), using forward differences of d in u and v with steps of half the screen-space
// (u, v) footprint (0.01 when the footprint is zero). Returns the new shading dpdu, dpdv and
// unit normal normalize(dpdu x dpdv), flipped to the side of the geometric normal n.
void bump(const FloatTexture& d, const BumpInput& in, Vec3* dpdu, Vec3* dpdv, Vec3* ns);

}  // namespace rlpbrt
