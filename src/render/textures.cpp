// Textures, mappings, the texture factory and bump mapping (see textures.h).
#include "render/textures.h"

#include <cctype>
#include <sstream>
#include <utility>

#include "render/image_io.h"
#include "render/noise.h"

namespace rlpbrt {

FloatTexture::~FloatTexture() = default;
SpectrumTexture::~SpectrumTexture() = default;
TextureMapping2D::~TextureMapping2D() = default;
TextureMapping3D::~TextureMapping3D() = default;

// ---------------------------------------------------------------------------------------------
// Mappings.

namespace {

inline Vec3 transformPoint(const Mat4& m, const Vec3& p) {
    Vec4 r = m * Vec4(p, 1.f);
    return (r.w == 1.f || r.w == 0.f) ? Vec3(r) : Vec3(r) / r.w;
}

inline Vec3 transformVector(const Mat4& m, const Vec3& v) { return Vec3(m * Vec4(v, 0.f)); }

// Removes the jump of 1 in t across the seam phi = 0 from a finite-difference derivative.
inline float unwrapSeam(float d) {
    if (d > 0.5f) return 1.f - d;
    if (d < -0.5f) return -(d + 1.f);
    return d;
}

}  // namespace

Vec2 UVMapping2D::map(const TextureContext& ctx, Vec2* dstdx, Vec2* dstdy) const {
    *dstdx = Vec2(su_ * ctx.dudx, sv_ * ctx.dvdx);
    *dstdy = Vec2(su_ * ctx.dudy, sv_ * ctx.dvdy);
    return Vec2(su_ * ctx.uv.x + du_, sv_ * ctx.uv.y + dv_);
}

Vec2 SphericalMapping2D::sphere(const Vec3& p) const {
    Vec3 v = glm::normalize(transformPoint(textureFromWorld_, p));
    float theta = safeAcos(v.z);
    float phi = std::atan2(v.y, v.x);
    if (phi < 0) phi += 2 * Pi;
    return Vec2(theta * InvPi, phi * Inv2Pi);
}

Vec2 SphericalMapping2D::map(const TextureContext& ctx, Vec2* dstdx, Vec2* dstdy) const {
    // Forward differences over a step of 0.1 pixel footprints (pbrt-v3).
    const float delta = 0.1f;
    Vec2 st = sphere(ctx.p);
    *dstdx = (sphere(ctx.p + delta * ctx.dpdx) - st) / delta;
    *dstdy = (sphere(ctx.p + delta * ctx.dpdy) - st) / delta;
    dstdx->y = unwrapSeam(dstdx->y);
    dstdy->y = unwrapSeam(dstdy->y);
    return st;
}

Vec2 CylindricalMapping2D::cylinder(const Vec3& p) const {
    Vec3 v = glm::normalize(transformPoint(textureFromWorld_, p));
    return Vec2((Pi + std::atan2(v.y, v.x)) * Inv2Pi, v.z);
}

Vec2 CylindricalMapping2D::map(const TextureContext& ctx, Vec2* dstdx, Vec2* dstdy) const {
    const float delta = 0.01f;
    Vec2 st = cylinder(ctx.p);
    *dstdx = (cylinder(ctx.p + delta * ctx.dpdx) - st) / delta;
    *dstdy = (cylinder(ctx.p + delta * ctx.dpdy) - st) / delta;
    dstdx->y = unwrapSeam(dstdx->y);
    dstdy->y = unwrapSeam(dstdy->y);
    return st;
}

Vec2 PlanarMapping2D::map(const TextureContext& ctx, Vec2* dstdx, Vec2* dstdy) const {
    *dstdx = Vec2(glm::dot(ctx.dpdx, vs_), glm::dot(ctx.dpdx, vt_));
    *dstdy = Vec2(glm::dot(ctx.dpdy, vs_), glm::dot(ctx.dpdy, vt_));
    return Vec2(ds_ + glm::dot(ctx.p, vs_), dt_ + glm::dot(ctx.p, vt_));
}

Vec3 IdentityMapping3D::map(const TextureContext& ctx, Vec3* dpdx, Vec3* dpdy) const {
    *dpdx = transformVector(m_, ctx.dpdx);
    *dpdy = transformVector(m_, ctx.dpdy);
    return transformPoint(m_, ctx.p);
}

// ---------------------------------------------------------------------------------------------
// Texture types. Each is a template over the value type T (float or Spectrum) where pbrt-v3
// has both variants.

namespace {

template <typename T> struct TexBase;
template <> struct TexBase<float> { using Type = FloatTexture; };
template <> struct TexBase<Spectrum> { using Type = SpectrumTexture; };
template <typename T> using TexPtr = std::shared_ptr<typename TexBase<T>::Type>;
template <typename T> struct ConstantOf;
template <> struct ConstantOf<float> { using Type = ConstantFloatTexture; };
template <> struct ConstantOf<Spectrum> { using Type = ConstantSpectrumTexture; };

TexPtr<float> resolve(TextureResolver& r, const ParamList& ps, const std::string& name,
                      float def) {
    return r.floatTex(ps, name, def);
}
TexPtr<Spectrum> resolve(TextureResolver& r, const ParamList& ps, const std::string& name,
                         Spectrum def) {
    return r.spectrumTex(ps, name, def);
}

template <typename T>
class ScaleTexture : public TexBase<T>::Type {
public:
    ScaleTexture(TexPtr<T> a, TexPtr<T> b) : a_(std::move(a)), b_(std::move(b)) {}
    T evaluate(const TextureContext& ctx) const override {
        return a_->evaluate(ctx) * b_->evaluate(ctx);
    }

private:
    TexPtr<T> a_, b_;
};

template <typename T>
class MixTexture : public TexBase<T>::Type {
public:
    MixTexture(TexPtr<T> a, TexPtr<T> b, std::shared_ptr<FloatTexture> amount)
        : a_(std::move(a)), b_(std::move(b)), amount_(std::move(amount)) {}
    T evaluate(const TextureContext& ctx) const override {
        float t = amount_->evaluate(ctx);
        return (1 - t) * a_->evaluate(ctx) + t * b_->evaluate(ctx);
    }

private:
    TexPtr<T> a_, b_;
    std::shared_ptr<FloatTexture> amount_;
};

// Bilinear interpolation of four corner values over (s, t) (unclamped, as pbrt-v3). The
// corners are textures here, a superset of pbrt-v3's constant corners.
template <typename T>
class BilerpTexture : public TexBase<T>::Type {
public:
    BilerpTexture(std::unique_ptr<TextureMapping2D> mapping, TexPtr<T> v00, TexPtr<T> v01,
                  TexPtr<T> v10, TexPtr<T> v11)
        : mapping_(std::move(mapping)), v00_(std::move(v00)), v01_(std::move(v01)),
          v10_(std::move(v10)), v11_(std::move(v11)) {}
    T evaluate(const TextureContext& ctx) const override {
        Vec2 dstdx, dstdy;
        Vec2 st = mapping_->map(ctx, &dstdx, &dstdy);
        float s = st.x, t = st.y;
        return (1 - s) * (1 - t) * v00_->evaluate(ctx) + (1 - s) * t * v01_->evaluate(ctx) +
               s * (1 - t) * v10_->evaluate(ctx) + s * t * v11_->evaluate(ctx);
    }

private:
    std::unique_ptr<TextureMapping2D> mapping_;
    TexPtr<T> v00_, v01_, v10_, v11_;
};

template <typename T>
class ImageTexture : public TexBase<T>::Type {
public:
    ImageTexture(std::unique_ptr<TextureMapping2D> mapping, std::shared_ptr<const MipMap<T>> map,
                 MipFilter filter, float maxAnisotropy)
        : mapping_(std::move(mapping)), map_(std::move(map)), filter_(filter),
          maxAnisotropy_(maxAnisotropy) {}
    T evaluate(const TextureContext& ctx) const override {
        Vec2 dstdx, dstdy;
        Vec2 st = mapping_->map(ctx, &dstdx, &dstdy);
        return map_->lookup(st, dstdx, dstdy, filter_, maxAnisotropy_);
    }

private:
    std::unique_ptr<TextureMapping2D> mapping_;
    std::shared_ptr<const MipMap<T>> map_;
    MipFilter filter_;
    float maxAnisotropy_;
};

// (s - floor(s), t - floor(t), 0).
class UVTexture : public SpectrumTexture {
public:
    explicit UVTexture(std::unique_ptr<TextureMapping2D> mapping) : mapping_(std::move(mapping)) {}
    Spectrum evaluate(const TextureContext& ctx) const override {
        Vec2 dstdx, dstdy;
        Vec2 st = mapping_->map(ctx, &dstdx, &dstdy);
        return Spectrum(st.x - std::floor(st.x), st.y - std::floor(st.y), 0.f);
    }

private:
    std::unique_ptr<TextureMapping2D> mapping_;
};

// tex1 on checks with even floor(s) + floor(t), tex2 on odd ones; "closedform" box-filters
// the pattern over the (s, t) footprint.
// x mod 2 in {0, 1}, also for negative x.
inline int mod2(int x) { return x & 1; }

template <typename T>
class Checkerboard2DTexture : public TexBase<T>::Type {
public:
    Checkerboard2DTexture(std::unique_ptr<TextureMapping2D> mapping, TexPtr<T> tex1,
                          TexPtr<T> tex2, bool closedForm)
        : mapping_(std::move(mapping)), tex1_(std::move(tex1)), tex2_(std::move(tex2)),
          closedForm_(closedForm) {}
    T evaluate(const TextureContext& ctx) const override {
        Vec2 dstdx, dstdy;
        Vec2 st = mapping_->map(ctx, &dstdx, &dstdy);
        if (closedForm_) {
            // Half-widths of the box footprint in s and t.
            float ds = std::max(std::abs(dstdx.x), std::abs(dstdy.x));
            float dt = std::max(std::abs(dstdx.y), std::abs(dstdy.y));
            float s0 = st.x - ds, s1 = st.x + ds, t0 = st.y - dt, t1 = st.y + dt;
            if (!(std::floor(s0) == std::floor(s1) && std::floor(t0) == std::floor(t1))) {
                // Integral of the 1D square wave (1 on odd unit intervals) from 0 to x.
                auto bumpInt = [](float x) {
                    float h = std::floor(x / 2);
                    return h + 2 * std::max(x / 2 - h - 0.5f, 0.f);
                };
                // Average of the wave over [s0, s1]; for a zero width (pbrt-v3 divides
                // 0 by 0 there) its limit, the wave's value at s.
                auto average = [&](float a, float b, float half, float x) {
                    if (half == 0) return float(mod2(int(std::floor(x))));
                    return (bumpInt(b) - bumpInt(a)) / (2 * half);
                };
                float sint = average(s0, s1, ds, st.x);
                float tint = average(t0, t1, dt, st.y);
                // Fraction of the footprint on odd checks (XOR of the two square waves).
                float area2 = sint + tint - 2 * sint * tint;
                if (ds > 1 || dt > 1) area2 = 0.5f;
                return (1 - area2) * tex1_->evaluate(ctx) + area2 * tex2_->evaluate(ctx);
            }
        }
        if ((int(std::floor(st.x)) + int(std::floor(st.y))) % 2 == 0)
            return tex1_->evaluate(ctx);
        return tex2_->evaluate(ctx);
    }

private:
    std::unique_ptr<TextureMapping2D> mapping_;
    TexPtr<T> tex1_, tex2_;
    bool closedForm_;
};

template <typename T>
class Checkerboard3DTexture : public TexBase<T>::Type {
public:
    Checkerboard3DTexture(std::unique_ptr<TextureMapping3D> mapping, TexPtr<T> tex1,
                          TexPtr<T> tex2)
        : mapping_(std::move(mapping)), tex1_(std::move(tex1)), tex2_(std::move(tex2)) {}
    T evaluate(const TextureContext& ctx) const override {
        Vec3 dpdx, dpdy;
        Vec3 p = mapping_->map(ctx, &dpdx, &dpdy);
        int sum = int(std::floor(p.x)) + int(std::floor(p.y)) + int(std::floor(p.z));
        return sum % 2 == 0 ? tex1_->evaluate(ctx) : tex2_->evaluate(ctx);
    }

private:
    std::unique_ptr<TextureMapping3D> mapping_;
    TexPtr<T> tex1_, tex2_;
};

// Randomly placed dots of radius 0.35 on the unit (s, t) lattice; cells are chosen and
// jittered with Perlin noise.
template <typename T>
class DotsTexture : public TexBase<T>::Type {
public:
    DotsTexture(std::unique_ptr<TextureMapping2D> mapping, TexPtr<T> outside, TexPtr<T> inside)
        : mapping_(std::move(mapping)), outside_(std::move(outside)),
          inside_(std::move(inside)) {}
    T evaluate(const TextureContext& ctx) const override {
        Vec2 dstdx, dstdy;
        Vec2 st = mapping_->map(ctx, &dstdx, &dstdy);
        int sCell = int(std::floor(st.x + 0.5f)), tCell = int(std::floor(st.y + 0.5f));
        if (perlinNoise(sCell + 0.5f, tCell + 0.5f) > 0) {
            const float radius = 0.35f, maxShift = 0.5f - radius;
            float sCenter = sCell + maxShift * perlinNoise(sCell + 1.5f, tCell + 2.8f);
            float tCenter = tCell + maxShift * perlinNoise(sCell + 4.5f, tCell + 9.8f);
            Vec2 d = st - Vec2(sCenter, tCenter);
            if (glm::dot(d, d) < radius * radius) return inside_->evaluate(ctx);
        }
        return outside_->evaluate(ctx);
    }

private:
    std::unique_ptr<TextureMapping2D> mapping_;
    TexPtr<T> outside_, inside_;
};

enum class NoiseKind { FBm, Wrinkled, Windy };

// fbm: fBm(p); wrinkled: turbulence(p); windy: |fBm(0.1 p, 3 octaves)| * fBm(p, 6 octaves).
template <typename T>
class NoiseTexture : public TexBase<T>::Type {
public:
    NoiseTexture(NoiseKind kind, std::unique_ptr<TextureMapping3D> mapping, int octaves,
                 float omega)
        : kind_(kind), mapping_(std::move(mapping)), octaves_(octaves), omega_(omega) {}
    T evaluate(const TextureContext& ctx) const override {
        Vec3 dpdx, dpdy;
        Vec3 p = mapping_->map(ctx, &dpdx, &dpdy);
        switch (kind_) {
        case NoiseKind::FBm: return T(fbm(p, dpdx, dpdy, omega_, octaves_));
        case NoiseKind::Wrinkled: return T(turbulence(p, dpdx, dpdy, omega_, octaves_));
        case NoiseKind::Windy: {
            float windStrength = fbm(0.1f * p, 0.1f * dpdx, 0.1f * dpdy, 0.5f, 3);
            float waveHeight = fbm(p, dpdx, dpdy, 0.5f, 6);
            return T(std::abs(windStrength) * waveHeight);
        }
        }
        return T(0.f);
    }

private:
    NoiseKind kind_;
    std::unique_ptr<TextureMapping3D> mapping_;
    int octaves_;
    float omega_;
};

// pbrt-v3's marble: sin(scale * p.y + variation * fBm) mapped through a cubic Bezier color
// spline. Reproduces pbrt-v3 exactly, including its segment choice first = min(1, floor(6t))
// (so the curve parameter ranges over [0, 5] and the spline is extrapolated, giving values
// well outside [0, 1]); the breakfast reference images were rendered with that behaviour.
class MarbleTexture : public SpectrumTexture {
public:
    MarbleTexture(std::unique_ptr<TextureMapping3D> mapping, int octaves, float omega,
                  float scale, float variation)
        : mapping_(std::move(mapping)), octaves_(octaves), omega_(omega), scale_(scale),
          variation_(variation) {}
    Spectrum evaluate(const TextureContext& ctx) const override {
        Vec3 dpdx, dpdy;
        Vec3 p = mapping_->map(ctx, &dpdx, &dpdy) * scale_;
        float marble = p.y + variation_ * fbm(p, scale_ * dpdx, scale_ * dpdy, omega_, octaves_);
        float t = 0.5f + 0.5f * std::sin(marble);
        // Control colors (data from pbrt-v3's textures/marble.h).
        static const Spectrum c[] = {
            {.58f, .58f, .6f}, {.58f, .58f, .6f}, {.58f, .58f, .6f},
            {.5f, .5f, .5f},   {.6f, .59f, .58f}, {.58f, .58f, .6f},
            {.58f, .58f, .6f}, {.2f, .2f, .33f},  {.58f, .58f, .6f},
        };
        const int nSeg = int(sizeof(c) / sizeof(c[0])) - 3;
        int first = std::min(1, int(std::floor(t * nSeg)));
        t = t * nSeg - float(first);
        // Cubic Bezier by de Casteljau.
        Spectrum s0 = glm::mix(c[first], c[first + 1], t);
        Spectrum s1 = glm::mix(c[first + 1], c[first + 2], t);
        Spectrum s2 = glm::mix(c[first + 2], c[first + 3], t);
        s0 = glm::mix(s0, s1, t);
        s1 = glm::mix(s1, s2, t);
        // pbrt-v3's extra factor 1.5 to increase the color variation.
        return 1.5f * glm::mix(s0, s1, t);
    }

private:
    std::unique_ptr<TextureMapping3D> mapping_;
    int octaves_;
    float omega_, scale_, variation_;
};

// ---------------------------------------------------------------------------------------------
// Factory helpers.

// A substitute for a parameter value rlpbrt does not understand (an error with --strict).
void warn(const ParamList& ps, const std::string& name, const std::string& msg) {
    if (Diagnostics* d = ps.diagnostics()) {
        const Param* p = ps.find(name);
        d->substituted(p ? p->loc : FileLoc{}, msg);
    }
}

std::string formatFloat(float v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

bool hasExtension(const std::string& filename, const char* ext) {
    std::string e(ext);
    if (filename.size() < e.size()) return false;
    for (size_t i = 0; i < e.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(filename[filename.size() - e.size() + i])) !=
            e[i])
            return false;
    return true;
}

// The 2D mapping from the "mapping" parameter and its options; null and *error when unknown.
std::unique_ptr<TextureMapping2D> makeMapping2D(const ParamList& ps, const Mat4& worldFromTexture,
                                                std::string* error) {
    std::string type = ps.getString("mapping", "uv");
    if (type == "uv") {
        return std::make_unique<UVMapping2D>(ps.getFloat("uscale", 1.f), ps.getFloat("vscale", 1.f),
                                             ps.getFloat("udelta", 0.f),
                                             ps.getFloat("vdelta", 0.f));
    }
    if (type == "spherical")
        return std::make_unique<SphericalMapping2D>(glm::inverse(worldFromTexture));
    if (type == "cylindrical")
        return std::make_unique<CylindricalMapping2D>(glm::inverse(worldFromTexture));
    if (type == "planar") {
        Float3 v1 = ps.getVector3("v1", {1, 0, 0}), v2 = ps.getVector3("v2", {0, 1, 0});
        return std::make_unique<PlanarMapping2D>(Vec3(v1[0], v1[1], v1[2]),
                                                 Vec3(v2[0], v2[1], v2[2]),
                                                 ps.getFloat("udelta", 0.f),
                                                 ps.getFloat("vdelta", 0.f));
    }
    if (error) *error = "unknown 2D texture mapping \"" + type + "\"";
    return nullptr;
}

std::unique_ptr<TextureMapping3D> makeMapping3D(const Mat4& worldFromTexture) {
    // pbrt-v3 semantics: the CTM itself is applied to world points (see textures.h).
    return std::make_unique<IdentityMapping3D>(worldFromTexture);
}

template <typename T>
std::shared_ptr<const MipMap<T>> getMipMap(MipMapCache& cache, const MipMapKey& key,
                                           std::string* error);
template <>
std::shared_ptr<const MipMap<float>> getMipMap(MipMapCache& cache, const MipMapKey& key,
                                               std::string* error) {
    return cache.getFloat(key, error);
}
template <>
std::shared_ptr<const MipMap<Spectrum>> getMipMap(MipMapCache& cache, const MipMapKey& key,
                                                  std::string* error) {
    return cache.getSpectrum(key, error);
}

template <typename T>
TexPtr<T> makeImageTexture(const ParamList& ps, const Mat4& worldFromTexture,
                           MipMapCache* cache, std::string* error) {
    auto mapping = makeMapping2D(ps, worldFromTexture, error);
    if (!mapping) return nullptr;

    // pbrt-v3 selects the filter with "bool trilinear" (false: EWA); pbrt-v4's
    // "string filter" is accepted as well.
    MipFilter filter = MipFilter::EWA;
    if (ps.has("filter")) {
        std::string f = ps.getString("filter", "ewa");
        if (!parseMipFilter(f, &filter)) {
            if (error) *error = "unknown image texture filter \"" + f + "\"";
            return nullptr;
        }
    } else if (ps.getBool("trilinear", false)) {
        filter = MipFilter::Trilinear;
    }
    float maxAniso = ps.getFloat("maxanisotropy", 8.f);

    MipMapKey key;
    key.filename = ps.getFilename("filename");
    if (key.filename.empty()) {
        if (error) *error = "imagemap texture requires a \"string filename\"";
        return nullptr;
    }
    std::string wrap = ps.getString("wrap", "repeat");
    if (!parseImageWrap(wrap, &key.wrap)) {
        if (error) *error = "unknown image wrap mode \"" + wrap + "\"";
        return nullptr;
    }
    key.scale = ps.getFloat("scale", 1.f);
    key.invert = ps.getBool("invert", false);
    // 8-bit formats store sRGB-encoded values: pbrt-v3's rule (.png, .tga) plus the 8-bit
    // formats pbrt-v3 cannot read.
    key.gamma = pbrtDefaultGamma(key.filename) || hasExtension(key.filename, ".jpg") ||
                hasExtension(key.filename, ".jpeg") || hasExtension(key.filename, ".bmp") ||
                hasExtension(key.filename, ".gif");
    if (ps.has("encoding")) {  // pbrt-v4 spelling
        std::string enc = ps.getString("encoding", "sRGB");
        if (enc == "sRGB") key.gamma = true;
        else if (enc == "linear") key.gamma = false;
        else warn(ps, "encoding", "unsupported image encoding \"" + enc + "\"; using default");
    }
    key.gamma = ps.getBool("gamma", key.gamma);

    MipMapCache local;
    std::string readError;
    auto map = getMipMap<T>(cache ? *cache : local, key, &readError);
    if (!map) {
        // pbrt-v3 reports the unreadable image and uses a one-texel map of value "scale".
        if (Diagnostics* d = ps.diagnostics()) {
            const Param* f = ps.find("filename");
            d->substituted(f ? f->loc : FileLoc{},
                           readError + "; using the constant " + formatFloat(key.scale) +
                               " (\"scale\") instead (as pbrt-v3)");
        }
        return std::make_shared<typename ConstantOf<T>::Type>(T(key.scale));
    }
    return std::make_shared<ImageTexture<T>>(std::move(mapping), std::move(map), filter,
                                             maxAniso);
}

// Shared creation for the types that exist for both float and spectrum values.
template <typename T>
TexPtr<T> createCommon(const std::string& type, const ParamList& ps, const Mat4& worldFromTexture,
                       TextureResolver& resolver, std::string* error, MipMapCache* cache,
                       bool* known) {
    *known = true;
    if (type == "constant") return resolve(resolver, ps, "value", T(1.f));
    if (type == "scale") {
        return std::make_shared<ScaleTexture<T>>(resolve(resolver, ps, "tex1", T(1.f)),
                                                 resolve(resolver, ps, "tex2", T(1.f)));
    }
    if (type == "mix") {
        return std::make_shared<MixTexture<T>>(resolve(resolver, ps, "tex1", T(0.f)),
                                               resolve(resolver, ps, "tex2", T(1.f)),
                                               resolver.floatTex(ps, "amount", 0.5f));
    }
    if (type == "bilerp") {
        auto mapping = makeMapping2D(ps, worldFromTexture, error);
        if (!mapping) return nullptr;
        return std::make_shared<BilerpTexture<T>>(
            std::move(mapping), resolve(resolver, ps, "v00", T(0.f)),
            resolve(resolver, ps, "v01", T(1.f)), resolve(resolver, ps, "v10", T(0.f)),
            resolve(resolver, ps, "v11", T(1.f)));
    }
    if (type == "imagemap") return makeImageTexture<T>(ps, worldFromTexture, cache, error);
    if (type == "checkerboard") {
        int dim = ps.getInt("dimension", 2);
        if (dim != 2 && dim != 3) {
            if (error)
                *error = std::to_string(dim) + "-dimensional checkerboard texture not supported";
            return nullptr;
        }
        auto tex1 = resolve(resolver, ps, "tex1", T(1.f));
        auto tex2 = resolve(resolver, ps, "tex2", T(0.f));
        if (dim == 3) {
            return std::make_shared<Checkerboard3DTexture<T>>(makeMapping3D(worldFromTexture),
                                                              std::move(tex1), std::move(tex2));
        }
        auto mapping = makeMapping2D(ps, worldFromTexture, error);
        if (!mapping) return nullptr;
        std::string aa = ps.getString("aamode", "closedform");
        bool closedForm = aa != "none";
        if (aa != "none" && aa != "closedform")
            warn(ps, "aamode", "checkerboard aamode \"" + aa + "\" not understood; using "
                               "\"closedform\"");
        return std::make_shared<Checkerboard2DTexture<T>>(std::move(mapping), std::move(tex1),
                                                          std::move(tex2), closedForm);
    }
    if (type == "dots") {
        auto mapping = makeMapping2D(ps, worldFromTexture, error);
        if (!mapping) return nullptr;
        // pbrt-v3 passes "inside" (default 1) as the texture *outside* the dots and "outside"
        // (default 0) as the one inside them; kept for fidelity with pbrt-v3 renders.
        return std::make_shared<DotsTexture<T>>(std::move(mapping),
                                                resolve(resolver, ps, "inside", T(1.f)),
                                                resolve(resolver, ps, "outside", T(0.f)));
    }
    if (type == "fbm" || type == "wrinkled") {
        NoiseKind kind = type == "fbm" ? NoiseKind::FBm : NoiseKind::Wrinkled;
        return std::make_shared<NoiseTexture<T>>(kind, makeMapping3D(worldFromTexture),
                                                 ps.getInt("octaves", 8),
                                                 ps.getFloat("roughness", 0.5f));
    }
    if (type == "windy") {
        return std::make_shared<NoiseTexture<T>>(NoiseKind::Windy,
                                                 makeMapping3D(worldFromTexture), 0, 0.f);
    }
    if (type == "ptex") {
        // No Ptex library in Debian 12: a constant grey stands in (an error with --strict).
        ps.markAllUsed();
        if (Diagnostics* d = ps.diagnostics()) {
            const Param* f = ps.find("filename");
            d->ignored(f ? f->loc : FileLoc{},
                       "texture type \"ptex\" is not supported (no Ptex library); a constant "
                       "0.5 is used instead");
        }
        return std::make_shared<typename ConstantOf<T>::Type>(T(0.5f));
    }
    *known = false;
    return nullptr;
}

}  // namespace

std::shared_ptr<FloatTexture> createFloatTexture(const std::string& type, const ParamList& params,
                                                 const glm::mat4& worldFromTexture,
                                                 TextureResolver& resolver, std::string* error,
                                                 MipMapCache* cache) {
    bool known = false;
    auto tex =
        createCommon<float>(type, params, worldFromTexture, resolver, error, cache, &known);
    if (known) return tex;
    if (error) {
        if (type == "uv" || type == "marble")
            *error = "texture type \"" + type + "\" has no float variant (only \"color\")";
        else
            *error = "unknown float texture type \"" + type + "\"";
    }
    return nullptr;
}

std::shared_ptr<SpectrumTexture> createSpectrumTexture(const std::string& type,
                                                       const ParamList& params,
                                                       const glm::mat4& worldFromTexture,
                                                       TextureResolver& resolver,
                                                       std::string* error, MipMapCache* cache) {
    bool known = false;
    auto tex =
        createCommon<Spectrum>(type, params, worldFromTexture, resolver, error, cache, &known);
    if (known) return tex;
    if (type == "uv") {
        auto mapping = makeMapping2D(params, worldFromTexture, error);
        if (!mapping) return nullptr;
        return std::make_shared<UVTexture>(std::move(mapping));
    }
    if (type == "marble") {
        return std::make_shared<MarbleTexture>(
            makeMapping3D(worldFromTexture), params.getInt("octaves", 8),
            params.getFloat("roughness", 0.5f), params.getFloat("scale", 1.f),
            params.getFloat("variation", 0.2f));
    }
    if (error) *error = "unknown spectrum texture type \"" + type + "\"";
    return nullptr;
}

// ---------------------------------------------------------------------------------------------
// Bump mapping.

void bump(const FloatTexture& d, const BumpInput& in, Vec3* dpdu, Vec3* dpdv, Vec3* ns) {
    TextureContext ctx;
    ctx.p = in.p;
    ctx.dpdx = in.dpdx;
    ctx.dpdy = in.dpdy;
    ctx.n = in.ns;
    ctx.uv = in.uv;
    ctx.dudx = in.dudx;
    ctx.dudy = in.dudy;
    ctx.dvdx = in.dvdx;
    ctx.dvdy = in.dvdy;
    float displace = d.evaluate(ctx);
    Vec3 nCross = glm::cross(in.dpdu, in.dpdv);

    // Shift by du in u: half the screen-space u footprint, or 0.01 without differentials.
    float du = 0.5f * (std::abs(in.dudx) + std::abs(in.dudy));
    if (du == 0) du = 0.01f;
    TextureContext shifted = ctx;
    shifted.p = in.p + du * in.dpdu;
    shifted.uv = in.uv + Vec2(du, 0.f);
    shifted.n = glm::normalize(nCross + du * in.dndu);
    float uDisplace = d.evaluate(shifted);

    float dv = 0.5f * (std::abs(in.dvdx) + std::abs(in.dvdy));
    if (dv == 0) dv = 0.01f;
    shifted.p = in.p + dv * in.dpdv;
    shifted.uv = in.uv + Vec2(0.f, dv);
    shifted.n = glm::normalize(nCross + dv * in.dndv);
    float vDisplace = d.evaluate(shifted);

    // Partial derivatives of p' = p + d(u, v) ns(u, v).
    *dpdu = in.dpdu + (uDisplace - displace) / du * in.ns + displace * in.dndu;
    *dpdv = in.dpdv + (vDisplace - displace) / dv * in.ns + displace * in.dndv;
    Vec3 n = glm::normalize(glm::cross(*dpdu, *dpdv));
    // Keep the shading normal on the geometric normal's side (pbrt-v3's SetShadingGeometry).
    *ns = glm::dot(n, in.n) < 0 ? -n : n;
}

}  // namespace rlpbrt
