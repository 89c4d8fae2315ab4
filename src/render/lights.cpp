// Light sources with pbrt-v3's semantics (lights/*.cpp of pbrt-v3 read for behaviour only).
#include "render/lights.h"

#include <cmath>

#include "render/distribution.h"
#include "render/image_io.h"
#include "render/mipmap.h"
#include "render/quadrics.h"
#include "render/sampling.h"
#include "render/spectrum.h"
#include "render/transform.h"

namespace rlpbrt {

Light::~Light() = default;

Spectrum Light::L(const Vec3&, const Vec3&, const Vec2&, const Vec3&) const {
    return Spectrum(0.f);
}

Spectrum Light::Le(const Vec3&) const { return Spectrum(0.f); }

namespace {

// ---------------------------------------------------------------------------------------
// Parameter helpers. A parameter of the wrong type is left unread, so that reportUnused()
// warns about it (pbrt-v3's ParamSet lookups are typed and silently miss other types).

Spectrum spectrumParam(const ParamList& params, const std::string& name, Spectrum def) {
    const Param* p = params.find(name);
    if (!p || !isSpectral(p->type)) return def;
    params.getSpectral(name);  // marks it used
    return spectrumFromParam(*p);
}

Vec3 point3Param(const ParamList& params, const std::string& name, Vec3 def) {
    const Param* p = params.find(name);
    if (!p || p->type != ParamType::Point3) return def;
    Float3 v = params.getPoint3(name, {def.x, def.y, def.z});
    return Vec3(v[0], v[1], v[2]);
}

float floatParam(const ParamList& params, const std::string& name, float def) {
    const Param* p = params.find(name);
    if (!p || p->type != ParamType::Float) return def;
    return params.getFloat(name, def);
}

bool boolParam(const ParamList& params, const std::string& name, bool def) {
    const Param* p = params.find(name);
    if (!p || p->type != ParamType::Bool) return def;
    return params.getBool(name, def);
}

std::string filenameParam(const ParamList& params, const std::string& name) {
    const Param* p = params.find(name);
    if (!p || p->type != ParamType::String) return std::string();
    return params.getFilename(name);
}

void markIntUsed(const ParamList& params, const std::string& name) {
    const Param* p = params.find(name);
    if (p && p->type == ParamType::Integer) params.getInt(name, 1);
}

// Reads an image map (values as stored) into an RGB MIP map with repeat wrapping, as
// pbrt-v3's lights do. Null (with a warning, as pbrt-v3 carries on) when unreadable.
std::shared_ptr<MipMap<Spectrum>> readLightMap(const std::string& path, const Spectrum& scale,
                                               const FileLoc& loc, Diagnostics& diag,
                                               int* width, int* height) {
    if (path.empty()) return nullptr;
    Image img;
    std::string error;
    if (!readImage(path, &img, &error)) {
        diag.substituted(loc, "cannot read light map \"" + path + "\": " + error +
                                  "; using a constant map (as pbrt-v3)");
        return nullptr;
    }
    std::vector<Spectrum> texels(size_t(img.width) * img.height);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            texels[size_t(y) * img.width + x] =
                Spectrum(img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2)) * scale;
    *width = img.width;
    *height = img.height;
    return std::make_shared<MipMap<Spectrum>>(img.width, img.height, std::move(texels),
                                              ImageWrap::Repeat);
}

// pbrt-v3's Lookup(st) with zero width: bilinear on the finest level.
Spectrum lookupMap(const MipMap<Spectrum>& m, const Vec2& st) { return m.bilerp(0, st); }

// pbrt-v3's Lookup((.5,.5), .5): the coarse-level average used by Power().
Spectrum averageMap(const MipMap<Spectrum>& m) { return m.trilinear(Vec2(0.5f), 0.5f); }

Vec3 linearApply(const Mat4& m, const Vec3& v) { return glm::mat3(m) * v; }

// Fills a delta-position light sample for a light at pLight with intensity Iw towards ctx.
bool fillPointSample(const Vec3& pLight, const LightSampleContext& ctx, const Spectrum& I,
                     LightSample* s, float* dist2Out = nullptr) {
    Vec3 d = pLight - ctx.p;
    float dist2 = glm::dot(d, d);
    *s = LightSample();
    s->isDelta = true;
    if (!(dist2 > 0.f)) return false;
    float dist = std::sqrt(dist2);
    s->wi = d / dist;
    s->dist = dist;
    s->pdf = 1.f;
    s->L = I / dist2;
    if (dist2Out) *dist2Out = dist2;
    return s->valid();
}

// ---------------------------------------------------------------------------------------
// point

// Lights at a point or from one direction: sampled only by sampleLi, never hit by rays.
template <LightKind Kind>
class DeltaLight : public Light {
public:
    LightKind kind() const override { return Kind; }
    float pdfLi(const LightSampleContext&, const Vec3&, const Vec3&,
                const Vec3&) const override {
        return 0.f;
    }
};

class PointLight final : public DeltaLight<LightKind::DeltaPosition> {
public:
    PointLight(const Vec3& p, const Spectrum& I) : p_(p), I_(I) {}
    bool sampleLi(const LightSampleContext& ctx, Vec2, LightSample* s) const override {
        return fillPointSample(p_, ctx, I_, s);
    }
    Spectrum power() const override { return 4.f * Pi * I_; }

private:
    Vec3 p_;
    Spectrum I_;
};

// ---------------------------------------------------------------------------------------
// spot

class SpotLight final : public DeltaLight<LightKind::DeltaPosition> {
public:
    SpotLight(const Mat4& worldFromLight, const Spectrum& I, float totalWidthDeg,
              float falloffStartDeg)
        : lightFromWorld_(glm::inverse(worldFromLight)),
          p_(transformPoint(worldFromLight, Vec3(0.f))),
          I_(I),
          cosTotalWidth_(std::cos(radians(totalWidthDeg))),
          cosFalloffStart_(std::cos(radians(falloffStartDeg))) {}

    // pbrt-v3's smooth quartic falloff for the world direction w leaving the light.
    float falloff(const Vec3& w) const {
        Vec3 wl = glm::normalize(linearApply(lightFromWorld_, w));
        float cosTheta = wl.z;
        if (cosTheta < cosTotalWidth_) return 0.f;
        if (cosTheta > cosFalloffStart_) return 1.f;
        float delta = (cosTheta - cosTotalWidth_) / (cosFalloffStart_ - cosTotalWidth_);
        return (delta * delta) * (delta * delta);
    }
    bool sampleLi(const LightSampleContext& ctx, Vec2, LightSample* s) const override {
        if (!fillPointSample(p_, ctx, I_, s)) return false;
        s->L *= falloff(-s->wi);
        return s->valid();
    }
    Spectrum power() const override {
        return I_ * 2.f * Pi * (1.f - 0.5f * (cosFalloffStart_ + cosTotalWidth_));
    }

private:
    Mat4 lightFromWorld_;
    Vec3 p_;
    Spectrum I_;
    float cosTotalWidth_, cosFalloffStart_;
};

// ---------------------------------------------------------------------------------------
// goniometric

class GoniometricLight final : public DeltaLight<LightKind::DeltaPosition> {
public:
    GoniometricLight(const Mat4& worldFromLight, const Spectrum& I,
                     std::shared_ptr<MipMap<Spectrum>> map)
        : lightFromWorld_(glm::inverse(worldFromLight)),
          p_(transformPoint(worldFromLight, Vec3(0.f))),
          I_(I),
          map_(std::move(map)) {}

    // The map value for the world direction w leaving the light; the map's polar axis is
    // the light's +y (pbrt-v3 swaps y and z before the spherical lookup).
    Spectrum scale(const Vec3& w) const {
        if (!map_) return Spectrum(1.f);
        Vec3 wp = glm::normalize(linearApply(lightFromWorld_, w));
        std::swap(wp.y, wp.z);
        Vec2 st(sphericalPhi(wp) * Inv2Pi, sphericalTheta(wp) * InvPi);
        return lookupMap(*map_, st);
    }
    bool sampleLi(const LightSampleContext& ctx, Vec2, LightSample* s) const override {
        if (!fillPointSample(p_, ctx, I_, s)) return false;
        s->L *= scale(-s->wi);
        return s->valid();
    }
    Spectrum power() const override {
        return 4.f * Pi * I_ * (map_ ? averageMap(*map_) : Spectrum(1.f));
    }

private:
    Mat4 lightFromWorld_;
    Vec3 p_;
    Spectrum I_;
    std::shared_ptr<MipMap<Spectrum>> map_;
};

// ---------------------------------------------------------------------------------------
// projection

class ProjectionLight final : public DeltaLight<LightKind::DeltaPosition> {
public:
    ProjectionLight(const Mat4& worldFromLight, const Spectrum& I, float fovDeg,
                    std::shared_ptr<MipMap<Spectrum>> map, int mapWidth, int mapHeight)
        : lightFromWorld_(glm::inverse(worldFromLight)),
          p_(transformPoint(worldFromLight, Vec3(0.f))),
          I_(I),
          map_(std::move(map)) {
        float aspect = map_ ? float(mapWidth) / float(mapHeight) : 1.f;
        if (aspect > 1.f) {
            screenMin_ = Vec2(-aspect, -1.f);
            screenMax_ = Vec2(aspect, 1.f);
        } else {
            screenMin_ = Vec2(-1.f, -1.f / aspect);
            screenMax_ = Vec2(1.f, 1.f / aspect);
        }
        tanHalfFov_ = std::tan(radians(fovDeg) / 2.f);
        // pbrt-v3's cone around the projected directions (used for power only).
        float tanDiag = tanHalfFov_ * std::sqrt(1.f + 1.f / (aspect * aspect));
        cosTotalWidth_ = std::cos(std::atan(tanDiag));
    }

    // The projected value for the world direction w leaving the light (pbrt-v3's
    // perspective projection with near plane 1e-3; screen window [-aspect,aspect]x[-1,1]).
    Spectrum projection(const Vec3& w) const {
        Vec3 wl = linearApply(lightFromWorld_, w);
        if (wl.z < 1e-3f) return Spectrum(0.f);
        Vec2 p(wl.x / (wl.z * tanHalfFov_), wl.y / (wl.z * tanHalfFov_));
        if (!(p.x >= screenMin_.x && p.x <= screenMax_.x && p.y >= screenMin_.y &&
              p.y <= screenMax_.y))
            return Spectrum(0.f);
        if (!map_) return Spectrum(1.f);
        Vec2 st = (p - screenMin_) / (screenMax_ - screenMin_);
        return lookupMap(*map_, st);
    }
    bool sampleLi(const LightSampleContext& ctx, Vec2, LightSample* s) const override {
        if (!fillPointSample(p_, ctx, I_, s)) return false;
        s->L *= projection(-s->wi);
        return s->valid();
    }
    Spectrum power() const override {
        return (map_ ? averageMap(*map_) : Spectrum(1.f)) * I_ * 2.f * Pi *
               (1.f - cosTotalWidth_);
    }

private:
    Mat4 lightFromWorld_;
    Vec3 p_;
    Spectrum I_;
    std::shared_ptr<MipMap<Spectrum>> map_;
    Vec2 screenMin_, screenMax_;
    float tanHalfFov_ = 1.f, cosTotalWidth_ = 0.f;
};

// ---------------------------------------------------------------------------------------
// distant

class DistantLight final : public DeltaLight<LightKind::DeltaDirection> {
public:
    DistantLight(const Spectrum& L, const Vec3& wLight) : L_(L), w_(wLight) {}
    bool sampleLi(const LightSampleContext&, Vec2, LightSample* s) const override {
        *s = LightSample();
        s->isDelta = true;
        s->wi = w_;
        s->pdf = 1.f;
        s->dist = Infinity;
        s->L = L_;
        return s->valid();
    }
    Spectrum power() const override { return L_ * Pi * radius_ * radius_; }
    void preprocess(const Vec3&, float sceneRadius) override { radius_ = sceneRadius; }

private:
    Spectrum L_;
    Vec3 w_;
    float radius_ = 0.f;
};

// ---------------------------------------------------------------------------------------
// infinite

class InfiniteLight final : public Light {
public:
    // map null: constant radiance L.
    InfiniteLight(const Mat4& worldFromLight, const Spectrum& L,
                  std::shared_ptr<MipMap<Spectrum>> map)
        : worldFromLight_(worldFromLight),
          lightFromWorld_(glm::inverse(worldFromLight)),
          L_(L),
          map_(std::move(map)) {
        if (!map_) return;
        // The map's luminance (filtered lookups) times sin(theta), 2x oversampled as pbrt-v3
        // does while that table stays within 2^20 entries (8 MB with its CDF); larger maps at
        // their own resolution. 2x of a 1000x500 map is 16 MB whose cache misses took 16% of
        // metal-spheres' render time, for no less error per sample (session 34: 128 spp,
        // relMSE 0.001104 / 0.001108, 9.0 -> 7.6 s); small maps need the finer table (a 16x8
        // map's samples were 1.5x noisier at 1x).
        const int w0 = map_->width(0), h0 = map_->height(0);
        const int over = int64_t(w0) * h0 * 4 <= (int64_t(1) << 20) ? 2 : 1;
        const int w = over * w0, h = over * h0;
        std::vector<float> img(size_t(w) * h);
        float fwidth = 0.5f / float(std::min(w, h));
        for (int v = 0; v < h; ++v) {
            float vp = (float(v) + 0.5f) / float(h);
            float sinTheta = std::sin(Pi * (float(v) + 0.5f) / float(h));
            for (int u = 0; u < w; ++u) {
                float up = (float(u) + 0.5f) / float(w);
                img[size_t(v) * w + u] = luminance(map_->trilinear(Vec2(up, vp), fwidth)) *
                                         sinTheta;
            }
        }
        distribution_ = Distribution2D(img.data(), w, h);
    }
    LightKind kind() const override { return LightKind::Infinite; }

    Spectrum Le(const Vec3& dir) const override {
        if (!map_) return L_;
        Vec3 w = glm::normalize(linearApply(lightFromWorld_, dir));
        return lookupMap(*map_, Vec2(sphericalPhi(w) * Inv2Pi, sphericalTheta(w) * InvPi));
    }

    bool sampleLi(const LightSampleContext& ctx, Vec2 u, LightSample* s) const override {
        *s = LightSample();
        s->dist = Infinity;
        if (!map_) return sampleConstant(ctx, u, s);
        float mapPdf = 0.f;
        Vec2 uv = distribution_.sampleContinuous(u, &mapPdf);
        if (!(mapPdf > 0.f)) return false;
        float theta = uv.y * Pi, phi = uv.x * 2.f * Pi;
        float sinTheta = std::sin(theta);
        if (!(sinTheta > 0.f)) return false;
        Vec3 wl = sphericalDirection(sinTheta, std::cos(theta), phi);
        s->wi = glm::normalize(linearApply(worldFromLight_, wl));
        s->pdf = mapPdf / (2.f * Pi * Pi * sinTheta);
        s->L = lookupMap(*map_, uv);
        return s->valid();
    }

    float pdfLi(const LightSampleContext& ctx, const Vec3& wi, const Vec3&,
                const Vec3&) const override {
        if (!map_) return pdfConstant(ctx, wi);
        Vec3 w = glm::normalize(linearApply(lightFromWorld_, wi));
        float theta = sphericalTheta(w), phi = sphericalPhi(w);
        float sinTheta = std::sin(theta);
        if (!(sinTheta > 0.f)) return 0.f;
        return distribution_.pdf(Vec2(phi * Inv2Pi, theta * InvPi)) /
               (2.f * Pi * Pi * sinTheta);
    }

    Spectrum power() const override {
        return Pi * radius_ * radius_ * (map_ ? averageMap(*map_) : L_);
    }
    void preprocess(const Vec3&, float sceneRadius) override { radius_ = sceneRadius; }

private:
    // Unit normal of ctx, or zero (points in media).
    static Vec3 contextNormal(const LightSampleContext& ctx) {
        float len = glm::length(ctx.n);
        return len > 0.f && std::isfinite(len) ? ctx.n / len : Vec3(0.f);
    }
    // Constant radiance: cosine-weighted about +n or -n (probability 1/2 each) at surface
    // points, uniform over the sphere in media.
    bool sampleConstant(const LightSampleContext& ctx, Vec2 u, LightSample* s) const {
        Vec3 n = contextNormal(ctx);
        if (n == Vec3(0.f)) {
            s->wi = sampleUniformSphere(u);
            s->pdf = uniformSpherePdf();
        } else {
            bool flip = u.x >= 0.5f;
            u.x = flip ? std::min(2.f * u.x - 1.f, OneMinusEpsilon) : 2.f * u.x;
            Vec3 wl = sampleCosineHemisphere(u);
            if (flip) wl.z = -wl.z;
            s->wi = glm::normalize(Frame::fromZ(n).toWorld(wl));
            s->pdf = 0.5f * cosineHemispherePdf(std::abs(glm::dot(s->wi, n)));
        }
        s->L = L_;
        return s->valid();
    }
    float pdfConstant(const LightSampleContext& ctx, const Vec3& wi) const {
        Vec3 n = contextNormal(ctx);
        if (n == Vec3(0.f)) return uniformSpherePdf();
        return 0.5f * cosineHemispherePdf(std::abs(glm::dot(glm::normalize(wi), n)));
    }

    Mat4 worldFromLight_, lightFromWorld_;
    Spectrum L_;
    std::shared_ptr<MipMap<Spectrum>> map_;
    Distribution2D distribution_;
    float radius_ = 0.f;
};

// ---------------------------------------------------------------------------------------
// diffuse area lights

// Shared emission rule of pbrt-v3's DiffuseAreaLight.
Spectrum diffuseEmission(const Spectrum& Lemit, bool twoSided, const Vec3& n, const Vec3& w) {
    return (twoSided || glm::dot(n, w) > 0.f) ? Lemit : Spectrum(0.f);
}

// Converts an area density at pLight (unit normal nLight) to solid angle at ref.
float areaToSolidAngle(float pdfArea, const Vec3& ref, const Vec3& pLight, const Vec3& nLight,
                       const Vec3& wi) {
    Vec3 d = pLight - ref;
    float dist2 = glm::dot(d, d);
    float cosT = std::abs(glm::dot(nLight, wi));
    if (!(cosT > 0.f) || !(dist2 > 0.f)) return 0.f;
    float pdf = pdfArea * dist2 / cosT;
    return std::isfinite(pdf) ? pdf : 0.f;
}

class TriangleLight final : public Light {
public:
    TriangleLight(std::shared_ptr<const TriangleMesh> mesh, size_t tri, const Spectrum& L,
                  bool twoSided)
        : Lemit_(L), twoSided_(twoSided) {
        // The triangle's data is copied: sampling runs per shadow ray and per voxel of the
        // spatial light distribution, and should not chase the mesh's index buffer.
        const uint32_t* idx = &mesh->indices[3 * tri];
        for (int k = 0; k < 3; ++k) p_[k] = mesh->p[idx[k]];
        Vec3 c = glm::cross(p_[1] - p_[0], p_[2] - p_[0]);
        area_ = 0.5f * glm::length(c);
        ng_ = area_ > 0.f ? glm::normalize(c) : Vec3(0.f, 0.f, 1.f);
        if (mesh->flipNormals) ng_ = -ng_;
        hasNormals_ = !mesh->n.empty();
        if (hasNormals_)
            for (int k = 0; k < 3; ++k) n_[k] = mesh->n[idx[k]];
        centroid_ = (p_[0] + p_[1] + p_[2]) / 3.f;
    }
    LightKind kind() const override { return LightKind::Area; }

    Spectrum L(const Vec3&, const Vec3& n, const Vec2&, const Vec3& w) const override {
        return diffuseEmission(Lemit_, twoSided_, n, w);
    }
    bool sampleLi(const LightSampleContext& ctx, Vec2 u, LightSample* s) const override {
        *s = LightSample();
        if (!(area_ > 0.f)) return false;
        Vec2 b = sampleUniformTriangle(u);
        float b2 = 1.f - b.x - b.y;
        Vec3 p = b.x * p_[0] + b.y * p_[1] + b2 * p_[2];
        Vec3 n = normal(b.x, b.y, b2);
        Vec3 d = p - ctx.p;
        float dist2 = glm::dot(d, d);
        if (!(dist2 > 0.f)) return false;
        float dist = std::sqrt(dist2);
        s->wi = d / dist;
        s->dist = dist;
        s->pdf = areaToSolidAngle(1.f / area_, ctx.p, p, n, s->wi);
        s->L = L(p, n, Vec2(0.f), -s->wi);
        return s->valid();
    }
    float pdfLi(const LightSampleContext& ctx, const Vec3& wi, const Vec3& pLight,
                const Vec3& nLight) const override {
        if (!(area_ > 0.f)) return 0.f;
        return areaToSolidAngle(1.f / area_, ctx.p, pLight, nLight, glm::normalize(wi));
    }
    Spectrum power() const override {
        return (twoSided_ ? 2.f : 1.f) * Lemit_ * area_ * Pi;
    }
    float approxContribution(const Vec3& p) const override {
        // Luminance of L times the solid angle, estimated from the centroid (at most 2 pi).
        Vec3 d = centroid_ - p;
        float dist2 = glm::dot(d, d);
        float cosL = dist2 > 0.f ? glm::dot(ng_, d) / std::sqrt(dist2) : 0.f;
        if (!twoSided_ && !hasNormals_ && cosL > 0.f) return 0.f;  // behind the emitting side
        float omega = dist2 > 0.f ? std::min(2.f * Pi, area_ * std::abs(cosL) / dist2) : 2.f * Pi;
        return luminance(Lemit_) * omega;
    }

private:
    // pbrt-v3's geometric normal: cross(p1-p0, p2-p0), flipped by flipNormals, then turned
    // to the side of the interpolated shading normal when the mesh has (non-zero) normals;
    // the same orientation as scene.cpp's intersection normal.
    Vec3 normal(float b0, float b1, float b2) const {
        Vec3 n = ng_;
        if (hasNormals_) {
            Vec3 ns = b0 * n_[0] + b1 * n_[1] + b2 * n_[2];
            if (glm::dot(n, ns) < 0.f) n = -n;
        }
        return n;
    }

    Vec3 p_[3], n_[3], ng_, centroid_;
    bool hasNormals_ = false;
    Spectrum Lemit_;
    bool twoSided_;
    float area_ = 0.f;
};

// True when m's linear part is a rotation (or reflection) times a uniform scale.
bool isSimilarity(const Mat4& m, float* scale) {
    glm::mat3 a(m);
    glm::mat3 g = glm::transpose(a) * a;
    float s2 = (g[0][0] + g[1][1] + g[2][2]) / 3.f;
    if (!(s2 > 0.f) || !std::isfinite(s2)) return false;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (std::abs(g[i][j] - (i == j ? s2 : 0.f)) > 1e-4f * s2) return false;
    *scale = std::sqrt(s2);
    return true;
}

class QuadricLight final : public Light {
public:
    QuadricLight(std::shared_ptr<const QuadricShape> shape, const Spectrum& L, bool twoSided)
        : shape_(std::move(shape)), Lemit_(L), twoSided_(twoSided) {
        const Mat4& m = shape_->worldFromObject;
        glm::mat3 a(m);
        absDet_ = std::abs(glm::determinant(a));
        objArea_ = area(shape_->quadric);
        float s = 1.f;
        similar_ = isSimilarity(m, &s);
        worldArea_ = similar_ ? objArea_ * s * s : integrateWorldArea();
    }
    LightKind kind() const override { return LightKind::Area; }

    Spectrum L(const Vec3&, const Vec3& n, const Vec2&, const Vec3& w) const override {
        return diffuseEmission(Lemit_, twoSided_, n, w);
    }

    bool sampleLi(const LightSampleContext& ctx, Vec2 u, LightSample* s) const override {
        *s = LightSample();
        const Quadric& q = shape_->quadric;
        Vec3 refObj = transformPoint(shape_->objectFromWorld, ctx.p);
        QuadricSample qs;
        Vec3 p, n;
        bool cone = useCone(refObj);
        if (cone) {
            if (!sampleSolidAngle(q, refObj, u, &qs)) return false;
        } else {
            if (!sampleArea(q, u, &qs)) return false;
        }
        p = transformPoint(shape_->worldFromObject, qs.p);
        n = worldNormal(qs.n);
        Vec3 d = p - ctx.p;
        float dist2 = glm::dot(d, d);
        if (!(dist2 > 0.f)) return false;
        float dist = std::sqrt(dist2);
        s->wi = d / dist;
        s->dist = dist;
        // Solid angles are invariant under similarities, so the cone pdf carries over.
        s->pdf = cone ? qs.pdf : areaToSolidAngle(areaPdf(n), ctx.p, p, n, s->wi);
        if (!std::isfinite(s->pdf)) s->pdf = 0.f;
        s->L = L(p, n, Vec2(0.f), -s->wi);
        return s->valid();
    }

    float pdfLi(const LightSampleContext& ctx, const Vec3& wi, const Vec3& pLight,
                const Vec3& nLight) const override {
        Vec3 refObj = transformPoint(shape_->objectFromWorld, ctx.p);
        if (useCone(refObj))
            return pdfSolidAngle(shape_->quadric, refObj,
                                 linearApply(shape_->objectFromWorld, wi));
        if (shape_->quadric.kind == Quadric::Kind::Hyperboloid) return 0.f;
        Vec3 n = glm::normalize(nLight);
        return areaToSolidAngle(areaPdf(n), ctx.p, pLight, n, glm::normalize(wi));
    }

    Spectrum power() const override {
        return (twoSided_ ? 2.f : 1.f) * Lemit_ * worldArea_ * Pi;
    }

private:
    // Cone sampling (through quadrics.h) for full spheres seen from outside under a
    // similarity; the same test quadrics.cpp applies.
    bool useCone(const Vec3& refObj) const {
        return similar_ && usesSphereCone(shape_->quadric, refObj);
    }
    // World normal of an object-space unit normal, oriented as pbrt-v3's intersection
    // normal (and scene.cpp's): the object normal cross(dpdu, dpdv) flipped by flipNormals
    // (ReverseOrientation xor handedness swap), then transformed as a normal. (pbrt-v3's
    // Sphere::Sample flips by ReverseOrientation only, which disagrees with its own
    // intersection under a handedness swap; we follow the intersection.)
    Vec3 worldNormal(const Vec3& nObj) const {
        Vec3 n = glm::normalize(transformNormal(shape_->objectFromWorld, nObj));
        return shape_->flipNormals ? -n : n;
    }
    // World-space area density of uniform object-space area sampling at a point with
    // unit world normal n: 1 / (objArea * J), J = |det M| / |M^T n| the area scaling.
    float areaPdf(const Vec3& n) const {
        float mtn = glm::length(glm::transpose(glm::mat3(shape_->worldFromObject)) * n);
        float J = absDet_ / mtn;
        float pdf = 1.f / (objArea_ * J);
        return std::isfinite(pdf) ? pdf : 0.f;
    }
    // World area under a non-similarity: objArea * mean of J over a stratified grid of
    // area samples (deterministic; used for power only).
    float integrateWorldArea() const {
        constexpr int kN = 64;
        double sum = 0.0;
        int count = 0;
        for (int i = 0; i < kN; ++i)
            for (int j = 0; j < kN; ++j) {
                QuadricSample qs;
                Vec2 u((i + 0.5f) / kN, (j + 0.5f) / kN);
                if (!sampleArea(shape_->quadric, u, &qs)) continue;
                Vec3 n = worldNormal(qs.n);
                float mtn = glm::length(glm::transpose(glm::mat3(shape_->worldFromObject)) * n);
                if (mtn > 0.f) sum += absDet_ / mtn;
                ++count;
            }
        // Hyperboloids cannot be sampled: fall back to the object-space area.
        return count ? float(objArea_ * sum / count) : objArea_;
    }

    std::shared_ptr<const QuadricShape> shape_;
    Spectrum Lemit_;
    bool twoSided_;
    bool similar_ = false;
    float absDet_ = 1.f, objArea_ = 0.f, worldArea_ = 0.f;
};

}  // namespace

std::unique_ptr<Light> createLight(const std::string& type, const ParamList& params,
                                   const Mat4& worldFromLight, const FileLoc& loc,
                                   Diagnostics& diag) {
    Spectrum sc = spectrumParam(params, "scale", Spectrum(1.f));
    std::unique_ptr<Light> light;
    if (type == "point") {
        Spectrum I = spectrumParam(params, "I", Spectrum(1.f));
        Vec3 from = point3Param(params, "from", Vec3(0.f));
        // pbrt-v3 applies Translate(from) after the CTM: p = CTM(origin) + from.
        Vec3 p = transformPoint(worldFromLight, Vec3(0.f)) + from;
        light = std::make_unique<PointLight>(p, I * sc);
    } else if (type == "spot") {
        Spectrum I = spectrumParam(params, "I", Spectrum(1.f));
        float coneAngle = floatParam(params, "coneangle", 30.f);
        float coneDelta = floatParam(params, "conedeltaangle", 5.f);
        Vec3 from = point3Param(params, "from", Vec3(0.f));
        Vec3 to = point3Param(params, "to", Vec3(0.f, 0.f, 1.f));
        Vec3 dir = to - from;
        if (!(glm::dot(dir, dir) > 0.f)) {
            diag.error(loc, "spot light: \"from\" and \"to\" coincide");
            return nullptr;
        }
        Frame f = Frame::fromZ(glm::normalize(dir));
        Mat4 zToDir(Vec4(f.s, 0.f), Vec4(f.t, 0.f), Vec4(f.n, 0.f), Vec4(0.f, 0.f, 0.f, 1.f));
        Mat4 l2w = worldFromLight * translateMatrix(from) * zToDir;
        light = std::make_unique<SpotLight>(l2w, I * sc, coneAngle, coneAngle - coneDelta);
    } else if (type == "goniometric") {
        Spectrum I = spectrumParam(params, "I", Spectrum(1.f));
        std::string mapname = filenameParam(params, "mapname");
        int w = 0, h = 0;
        auto map = readLightMap(mapname, Spectrum(1.f), loc, diag, &w, &h);
        light = std::make_unique<GoniometricLight>(worldFromLight, I * sc, std::move(map));
    } else if (type == "projection") {
        Spectrum I = spectrumParam(params, "I", Spectrum(1.f));
        float fov = floatParam(params, "fov", 45.f);
        std::string mapname = filenameParam(params, "mapname");
        int w = 0, h = 0;
        auto map = readLightMap(mapname, Spectrum(1.f), loc, diag, &w, &h);
        light = std::make_unique<ProjectionLight>(worldFromLight, I * sc, fov, std::move(map),
                                                  w, h);
    } else if (type == "distant") {
        Spectrum L = spectrumParam(params, "L", Spectrum(1.f));
        Vec3 from = point3Param(params, "from", Vec3(0.f));
        Vec3 to = point3Param(params, "to", Vec3(0.f, 0.f, 1.f));
        Vec3 w = linearApply(worldFromLight, from - to);
        if (!(glm::dot(w, w) > 0.f) || !isFinite(w)) {
            diag.error(loc, "distant light: \"from\" and \"to\" coincide");
            return nullptr;
        }
        light = std::make_unique<DistantLight>(L * sc, glm::normalize(w));
    } else if (type == "infinite") {
        Spectrum L = spectrumParam(params, "L", Spectrum(1.f));
        markIntUsed(params, "nsamples");
        std::string mapname = filenameParam(params, "mapname");
        int w = 0, h = 0;
        auto map = readLightMap(mapname, L * sc, loc, diag, &w, &h);
        light = std::make_unique<InfiniteLight>(worldFromLight, L * sc, std::move(map));
    } else {
        diag.error(loc, "unknown light type \"" + type + "\"");
        return nullptr;
    }
    params.reportUnused("light \"" + type + "\"");
    return light;
}

bool createAreaLights(const std::string& type, const ParamList& params, const ShapeData& shape,
                      const FileLoc& loc, Diagnostics& diag,
                      std::vector<std::unique_ptr<Light>>* out) {
    if (type != "diffuse" && type != "area") {
        diag.error(loc, "unknown light type \"" + type + "\" for AreaLightSource");
        return false;
    }
    Spectrum L = spectrumParam(params, "L", Spectrum(1.f));
    Spectrum sc = spectrumParam(params, "scale", Spectrum(1.f));
    bool twoSided = boolParam(params, "twosided", false);
    markIntUsed(params, "nsamples");
    // Unused parameters are reported by the caller, once per AreaLightSource.
    Spectrum Lemit = L * sc;
    if (shape.mesh) {
        size_t n = shape.mesh->triangleCount();
        out->reserve(out->size() + n);
        for (size_t i = 0; i < n; ++i)
            out->push_back(std::make_unique<TriangleLight>(shape.mesh, i, Lemit, twoSided));
        return true;
    }
    if (shape.quadric) {
        if (shape.quadric->quadric.kind == Quadric::Kind::Hyperboloid)
            diag.warning(loc, "area light on a hyperboloid cannot be sampled (as in pbrt-v3); "
                              "it is only found by chance");
        out->push_back(std::make_unique<QuadricLight>(shape.quadric, Lemit, twoSided));
        return true;
    }
    diag.error(loc, "area light bound to a shape without geometry");
    return false;
}

}  // namespace rlpbrt
