// The Embree boundary: the only file that includes Embree. Also assembles the render
// objects (camera, film, sampler, textures, materials, lights) from a SceneDesc.
#include "render/scene.h"

#include <embree3/rtcore.h>

#include <cstring>
#include <map>

#include "render/media.h"
#include "render/sampling.h"
#include "render/spectrum.h"
#include "render/transform.h"

namespace rlpbrt {

// ------------------------------------------------------------------------------------------
// Quadrics as Embree user geometry (one primitive per geometry).

namespace {

// User geometry's bounds: the object-space box [lo, hi] carried to the world, padded by a
// relative epsilon so that float rounding cannot cut off a hit.
void setWorldBounds(const Mat4& worldFromObject, const Vec3& lo, const Vec3& hi,
                    RTCBounds* out) {
    Vec3 bmin(Infinity), bmax(-Infinity);
    for (int c = 0; c < 8; ++c) {
        Vec3 corner((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
        Vec3 w = transformPoint(worldFromObject, corner);
        bmin = glm::min(bmin, w);
        bmax = glm::max(bmax, w);
    }
    Vec3 pad = 1e-5f * (glm::abs(bmin) + glm::abs(bmax)) + Vec3(1e-7f);
    out->lower_x = bmin.x - pad.x;
    out->lower_y = bmin.y - pad.y;
    out->lower_z = bmin.z - pad.z;
    out->upper_x = bmax.x + pad.x;
    out->upper_y = bmax.y + pad.y;
    out->upper_z = bmax.z + pad.z;
}

// Records a user geometry's closest hit so far.
void setUserHit(const RTCIntersectFunctionNArguments* args, float t, const Vec2& uv,
                const Vec3& n) {
    auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
    rh->ray.tfar = t;
    rh->hit.u = uv.x;
    rh->hit.v = uv.y;
    rh->hit.Ng_x = n.x;
    rh->hit.Ng_y = n.y;
    rh->hit.Ng_z = n.z;
    rh->hit.primID = args->primID;
    rh->hit.geomID = args->geomID;
    rh->hit.instID[0] = args->context->instID[0];
}

void quadricBounds(const RTCBoundsFunctionArguments* args) {
    const auto* q = static_cast<const QuadricShape*>(args->geometryUserPtr);
    Vec3 lo, hi;
    bounds(q->quadric, &lo, &hi);
    setWorldBounds(q->worldFromObject, lo, hi, args->bounds_o);
}

bool quadricHit(const QuadricShape* q, const Vec3& o, const Vec3& d, float tnear, float tfar,
                QuadricHit* hit) {
    Vec3 oo = transformPoint(q->objectFromWorld, o);
    Vec3 od = transformVector(q->objectFromWorld, d);
    return intersect(q->quadric, oo, od, tnear, tfar, hit);
}

void quadricIntersect(const RTCIntersectFunctionNArguments* args) {
    if (!args->valid[0]) return;
    const auto* q = static_cast<const QuadricShape*>(args->geometryUserPtr);
    auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
    Vec3 o(rh->ray.org_x, rh->ray.org_y, rh->ray.org_z);
    Vec3 d(rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z);
    QuadricHit hit;
    if (!quadricHit(q, o, d, rh->ray.tnear, rh->ray.tfar, &hit)) return;
    setUserHit(args, hit.t, hit.uv, hit.n);
}

void quadricOccluded(const RTCOccludedFunctionNArguments* args) {
    if (!args->valid[0]) return;
    const auto* q = static_cast<const QuadricShape*>(args->geometryUserPtr);
    auto* ray = reinterpret_cast<RTCRay*>(args->ray);
    Vec3 o(ray->org_x, ray->org_y, ray->org_z);
    Vec3 d(ray->dir_x, ray->dir_y, ray->dir_z);
    if (quadricHit(q, o, d, ray->tnear, ray->tfar, nullptr)) ray->tfar = -Infinity;
}

// ------------------------------------------------------------------------------------------
// Curves as Embree user geometry: one primitive per curve piece (CurveShape::primitive), our
// own intersection test (curves.h says why not Embree's native curves).

void curvePrimBounds(const RTCBoundsFunctionArguments* args) {
    const auto* c = static_cast<const CurveShape*>(args->geometryUserPtr);
    Vec3 lo, hi;
    curveBounds(*c, args->primID, &lo, &hi);
    setWorldBounds(c->worldFromObject, lo, hi, args->bounds_o);
}

void curvePrimIntersect(const RTCIntersectFunctionNArguments* args) {
    if (!args->valid[0]) return;
    const auto* c = static_cast<const CurveShape*>(args->geometryUserPtr);
    auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
    Vec3 o = transformPoint(c->objectFromWorld, Vec3(rh->ray.org_x, rh->ray.org_y, rh->ray.org_z));
    Vec3 d = transformVector(c->objectFromWorld, Vec3(rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z));
    CurveHit hit;
    if (!intersectCurve(*c, args->primID, o, d, rh->ray.tfar, &hit)) return;
    if (!(hit.t > rh->ray.tnear)) return;
    setUserHit(args, hit.t, hit.uv, hit.n);
}

void curvePrimOccluded(const RTCOccludedFunctionNArguments* args) {
    if (!args->valid[0]) return;
    const auto* c = static_cast<const CurveShape*>(args->geometryUserPtr);
    auto* ray = reinterpret_cast<RTCRay*>(args->ray);
    Vec3 o = transformPoint(c->objectFromWorld, Vec3(ray->org_x, ray->org_y, ray->org_z));
    Vec3 d = transformVector(c->objectFromWorld, Vec3(ray->dir_x, ray->dir_y, ray->dir_z));
    if (intersectCurve(*c, args->primID, o, d, ray->tfar, nullptr)) ray->tfar = -Infinity;
}

// Builds a coordinate system (dpdu, dpdv) around n when the parametrisation is degenerate.
void coordinateSystem(const Vec3& n, Vec3* a, Vec3* b) {
    Frame f = Frame::fromZ(n);
    *a = f.s;
    *b = f.t;
}

}  // namespace

Scene::Scene() = default;

Scene::~Scene() {
    if (top_) rtcReleaseScene(top_);
    for (auto& g : groups_)
        if (g.rtcScene && g.rtcScene != top_) rtcReleaseScene(g.rtcScene);
    if (device_) rtcReleaseDevice(device_);
}

bool Scene::intersect(const Ray& ray, SurfaceInteraction* si) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh;
    rh.ray.org_x = ray.o.x;
    rh.ray.org_y = ray.o.y;
    rh.ray.org_z = ray.o.z;
    rh.ray.dir_x = ray.d.x;
    rh.ray.dir_y = ray.d.y;
    rh.ray.dir_z = ray.d.z;
    rh.ray.tnear = 0.f;
    rh.ray.tfar = ray.tMax;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.flags = 0;
    rh.ray.time = 0.f;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(top_, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    if (rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID) {
        const Instance& inst = instances_[rh.hit.instID[0] - groups_[0].prims.size()];
        const Primitive& prim = groups_[inst.group].prims[rh.hit.geomID];
        hitDetails(prim, rh.hit.primID, rh.hit.u, rh.hit.v, ray, rh.ray.tfar, &inst, si);
    } else {
        const Primitive& prim = groups_[0].prims[rh.hit.geomID];
        hitDetails(prim, rh.hit.primID, rh.hit.u, rh.hit.v, ray, rh.ray.tfar, nullptr, si);
        si->primitive = int(rh.hit.geomID);
        si->primID = rh.hit.primID;
        si->bary = Vec2(rh.hit.u, rh.hit.v);
    }
    return true;
}

const std::vector<Primitive>& Scene::worldPrimitives() const {
    static const std::vector<Primitive> kNone;
    return groups_.empty() ? kNone : groups_[0].prims;
}

bool Scene::occluded(const Vec3& o, const Vec3& d, float tMax) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r;
    r.org_x = o.x;
    r.org_y = o.y;
    r.org_z = o.z;
    r.dir_x = d.x;
    r.dir_y = d.y;
    r.dir_z = d.z;
    r.tnear = 0.f;
    r.tfar = tMax;
    r.mask = 0xFFFFFFFFu;
    r.flags = 0;
    r.time = 0.f;
    rtcOccluded1(top_, &ctx, &r);
    return r.tfar < 0.f;
}

void Scene::hitDetails(const Primitive& prim, unsigned primID, float u, float v,
                       const Ray& ray, float t, const Instance* inst,
                       SurfaceInteraction* si) const {
    si->t = t;
    si->material = prim.material;
    si->mediumInside = prim.mediumInside;
    si->mediumOutside = prim.mediumOutside;
    si->light = -1;
    si->shadingTangent = Vec3(0.f);
    si->dndu = si->dndv = Vec3(0.f);
    if (const TriangleMesh* m = prim.shape.mesh.get()) {
        uint32_t i0 = m->indices[3 * primID], i1 = m->indices[3 * primID + 1],
                 i2 = m->indices[3 * primID + 2];
        const Vec3 &p0 = m->p[i0], &p1 = m->p[i1], &p2 = m->p[i2];
        float b0 = 1.f - u - v, b1 = u, b2 = v;
        si->p = b0 * p0 + b1 * p1 + b2 * p2;
        Vec2 uv0(0, 0), uv1(1, 0), uv2(1, 1);
        if (!m->uv.empty()) {
            uv0 = m->uv[i0];
            uv1 = m->uv[i1];
            uv2 = m->uv[i2];
        }
        si->uv = b0 * uv0 + b1 * uv1 + b2 * uv2;
        Vec3 dp02 = p0 - p2, dp12 = p1 - p2;
        Vec2 duv02 = uv0 - uv2, duv12 = uv1 - uv2;
        Vec3 ng = glm::cross(dp02, dp12);
        float ngLen = glm::length(ng);
        ng = ngLen > 0.f ? ng / ngLen : Vec3(0, 0, 1);
        float det = duv02.x * duv12.y - duv02.y * duv12.x;
        bool degenerate = std::abs(det) < 1e-8f;
        if (!degenerate) {
            float invDet = 1.f / det;
            si->dpdu = (duv12.y * dp02 - duv02.y * dp12) * invDet;
            si->dpdv = (duv02.x * dp12 - duv12.x * dp02) * invDet;
            degenerate = glm::length(glm::cross(si->dpdu, si->dpdv)) == 0.f ||
                         !isFinite(si->dpdu) || !isFinite(si->dpdv);
        }
        if (degenerate) coordinateSystem(ng, &si->dpdu, &si->dpdv);
        if (m->flipNormals) ng = -ng;
        Vec3 ns = ng;
        if (!m->n.empty()) {
            Vec3 n = b0 * m->n[i0] + b1 * m->n[i1] + b2 * m->n[i2];
            float len = glm::length(n);
            if (len > 0.f) {
                ns = n / len;
                if (glm::dot(ng, ns) < 0.f) ng = -ng;  // the normals are authoritative
                if (!degenerate) {
                    float invDet = 1.f / det;
                    Vec3 dn1 = m->n[i0] - m->n[i2], dn2 = m->n[i1] - m->n[i2];
                    si->dndu = (duv12.y * dn1 - duv02.y * dn2) * invDet;
                    si->dndv = (duv02.x * dn2 - duv12.x * dn1) * invDet;
                }
            }
        }
        if (!m->s.empty()) si->shadingTangent = b0 * m->s[i0] + b1 * m->s[i1] + b2 * m->s[i2];
        si->ng = ng;
        si->ns = ns;
        if (prim.lightBase >= 0) si->light = prim.lightBase + int(primID);
    } else if (const CurveShape* c = prim.shape.curve.get()) {
        // Recompute the hit in object space for its local geometry (pbrt-v3's point on the
        // ray at the depth of the curve's centre line).
        Vec3 o = ray.o, d = ray.d;
        if (inst) {
            o = transformPoint(inst->instanceFromWorld, o);
            d = transformVector(inst->instanceFromWorld, d);
        }
        Vec3 oo = transformPoint(c->objectFromWorld, o);
        Vec3 od = transformVector(c->objectFromWorld, d);
        CurveHit hit;
        bool found = intersectCurve(*c, primID, oo, od, t * (1.f + 1e-4f) + 1e-30f, &hit) ||
                     intersectCurve(*c, primID, oo, od, Infinity, &hit);
        si->p = o + t * d;
        Vec3 n = found ? glm::normalize(transformNormal(c->objectFromWorld, hit.n)) : Vec3(0.f);
        if (!isFinite(n) || glm::dot(n, n) == 0.f) {
            n = -glm::normalize(d);
            coordinateSystem(n, &si->dpdu, &si->dpdv);
            si->uv = Vec2(0.f, 0.5f);
        } else {
            si->uv = hit.uv;
            si->dpdu = transformVector(c->worldFromObject, hit.dpdu);
            si->dpdv = transformVector(c->worldFromObject, hit.dpdv);
        }
        si->ng = si->ns = n;
    } else {
        const QuadricShape* q = prim.shape.quadric.get();
        // Recompute the hit in object space for the full local geometry.
        Vec3 o = ray.o, d = ray.d;
        if (inst) {
            o = transformPoint(inst->instanceFromWorld, o);
            d = transformVector(inst->instanceFromWorld, d);
        }
        QuadricHit hit;
        Vec3 oo = transformPoint(q->objectFromWorld, o);
        Vec3 od = transformVector(q->objectFromWorld, d);
        if (!rlpbrt::intersect(q->quadric, oo, od, t * (1.f - 1e-4f), t * (1.f + 1e-4f) + 1e-30f, &hit)) {
            // Numerically marginal: recompute without the window.
            rlpbrt::intersect(q->quadric, oo, od, 0.f, Infinity, &hit);
        }
        si->p = transformPoint(q->worldFromObject, hit.p);
        si->uv = hit.uv;
        si->dpdu = transformVector(q->worldFromObject, hit.dpdu);
        si->dpdv = transformVector(q->worldFromObject, hit.dpdv);
        Vec3 n = glm::normalize(transformNormal(q->objectFromWorld, hit.n));
        if (q->flipNormals) n = -n;
        si->ng = si->ns = n;
        if (prim.lightBase >= 0) si->light = prim.lightBase;
    }
    if (inst) {
        const Mat4& w = inst->worldFromInstance;
        si->p = transformPoint(w, si->p);
        si->dpdu = transformVector(w, si->dpdu);
        si->dpdv = transformVector(w, si->dpdv);
        si->ng = glm::normalize(transformNormal(inst->instanceFromWorld, si->ng));
        si->ns = glm::normalize(transformNormal(inst->instanceFromWorld, si->ns));
        si->dndu = transformNormal(inst->instanceFromWorld, si->dndu);
        si->dndv = transformNormal(inst->instanceFromWorld, si->dndv);
        if (glm::dot(si->ns, si->ng) < 0.f) si->ns = -si->ns;
        if (glm::length(si->shadingTangent) > 0.f)
            si->shadingTangent = transformVector(w, si->shadingTangent);
    }
    si->wo = -ray.d;
}

// ------------------------------------------------------------------------------------------
// Uniform surface sampling (for guiding data placement).

namespace {
// Area scale of a transform for similarity transforms: |det|^(2/3).
float areaScale(const Mat4& m) {
    return std::pow(std::abs(glm::determinant(glm::mat3(m))), 2.f / 3.f);
}
float quadricWorldArea(const QuadricShape& q) {
    return area(q.quadric) * areaScale(q.worldFromObject);
}
}  // namespace

void Scene::buildAreaTables() const {
    groupAreas_.resize(groups_.size());
    for (size_t g = 0; g < groups_.size(); ++g) {
        AreaTable& t = groupAreas_[g];
        std::vector<float> primAreas;
        t.triangles.resize(groups_[g].prims.size());
        for (size_t i = 0; i < groups_[g].prims.size(); ++i) {
            const Primitive& prim = groups_[g].prims[i];
            double a = 0.0;
            if (const TriangleMesh* m = prim.shape.mesh.get()) {
                std::vector<float> tri(m->triangleCount());
                for (size_t k = 0; k < tri.size(); ++k) {
                    tri[k] = m->triangleArea(k);
                    if (!std::isfinite(tri[k])) tri[k] = 0.f;
                    a += tri[k];
                }
                if (!tri.empty()) t.triangles[i] = Distribution1D(tri);
            } else if (prim.shape.quadric) {
                a = quadricWorldArea(*prim.shape.quadric);
            }
            // Curves place no guiding data (area 0): a curve hit's normal faces the ray (flat)
            // or is turned across the band (cylinder), so no region keyed by a surface normal
            // describes it; hair, their main use, is glossy and left to its BSDF anyway; and
            // pbrt-v3 cannot sample a curve's area either. docs/ARCHITECTURE.md, "Guiding".
            if (!std::isfinite(a)) a = 0.0;
            primAreas.push_back(float(a));
            t.area += a;
        }
        if (!primAreas.empty()) t.prims = Distribution1D(primAreas);
    }
    std::vector<float> top;
    top.push_back(float(groupAreas_.empty() ? 0.0 : groupAreas_[0].area));
    totalArea_ = top[0];
    for (const Instance& inst : instances_) {
        double a = groupAreas_[size_t(inst.group)].area * areaScale(inst.worldFromInstance);
        top.push_back(float(a));
        totalArea_ += a;
    }
    topLevel_ = Distribution1D(top);
}

bool Scene::sampleGroup(int group, const Vec3& u, Vec3* p, Vec3* n) const {
    const AreaTable& t = groupAreas_[size_t(group)];
    if (!(t.area > 0.0)) return false;
    float ur;
    int i = t.prims.sampleDiscrete(u.x, nullptr, &ur);
    const Primitive& prim = groups_[size_t(group)].prims[size_t(i)];
    if (const TriangleMesh* m = prim.shape.mesh.get()) {
        float ut;
        int k = t.triangles[size_t(i)].sampleDiscrete(ur, nullptr, &ut);
        Vec2 b = sampleUniformTriangle(Vec2(ut, u.y));
        const Vec3& p0 = m->p[m->indices[3 * size_t(k)]];
        const Vec3& p1 = m->p[m->indices[3 * size_t(k) + 1]];
        const Vec3& p2 = m->p[m->indices[3 * size_t(k) + 2]];
        *p = b.x * p0 + b.y * p1 + (1.f - b.x - b.y) * p2;
        Vec3 c = glm::cross(p1 - p0, p2 - p0);
        float len = glm::length(c);
        if (!(len > 0.f)) return false;
        *n = c / len;
        return true;
    }
    if (!prim.shape.quadric) return false;
    const QuadricShape& q = *prim.shape.quadric;
    QuadricSample qs;
    if (!sampleArea(q.quadric, Vec2(ur, u.y), &qs)) return false;
    *p = transformPoint(q.worldFromObject, qs.p);
    *n = glm::normalize(transformNormal(q.objectFromWorld, qs.n));
    return isFinite(*p) && isFinite(*n);
}

bool Scene::sampleSurface(const Vec3& u, Vec3* p, Vec3* n) const {
    std::call_once(areaOnce_, [this] { buildAreaTables(); });
    if (!(totalArea_ > 0.0)) return false;
    float ur;
    int e = topLevel_.sampleDiscrete(u.x, nullptr, &ur);
    if (e == 0) return sampleGroup(0, Vec3(ur, u.y, u.z), p, n);
    const Instance& inst = instances_[size_t(e - 1)];
    if (!sampleGroup(inst.group, Vec3(ur, u.y, u.z), p, n)) return false;
    *p = transformPoint(inst.worldFromInstance, *p);
    *n = glm::normalize(transformNormal(inst.instanceFromWorld, *n));
    return isFinite(*p) && isFinite(*n);
}

bool Scene::mediaBounds(Vec3* lo, Vec3* hi) const {
    *lo = Vec3(Infinity);
    *hi = Vec3(-Infinity);
    for (const auto& m : media) {
        Vec3 a, b;
        if (!m->worldBounds(&a, &b)) a = bMin_, b = bMax_;
        if (!(a.x <= b.x && a.y <= b.y && a.z <= b.z)) continue;
        *lo = glm::min(*lo, a);
        *hi = glm::max(*hi, b);
    }
    return lo->x <= hi->x && lo->y <= hi->y && lo->z <= hi->z && isFinite(*lo) && isFinite(*hi);
}

double Scene::totalSurfaceArea() const {
    std::call_once(areaOnce_, [this] { buildAreaTables(); });
    return totalArea_;
}

// ------------------------------------------------------------------------------------------
// Assembly.

namespace {

// Resolves material/texture parameters against the named textures visible at a definition.
class DescTextures : public TextureResolver {
public:
    DescTextures(const std::vector<std::shared_ptr<FloatTexture>>& f,
                 const std::vector<std::shared_ptr<SpectrumTexture>>& s, Diagnostics& diag)
        : float_(f), spectrum_(s), diag_(diag) {}
    void setScope(const TextureScope* scope) { scope_ = scope; }

    std::shared_ptr<FloatTexture> floatTex(const ParamList& params, const std::string& name,
                                           float def) override {
        const Param* p = params.find(name);
        if (p && p->type == ParamType::Texture) {
            std::string tex = params.getTexture(name);
            auto it = scope_ ? scope_->floatTextures.find(tex) : decltype(scope_->floatTextures.end()){};
            if (!scope_ || it == scope_->floatTextures.end() || !float_[size_t(it->second)]) {
                diag_.error(p->loc, "undefined float texture \"" + tex + "\"");
                return std::make_shared<ConstantFloatTexture>(def);
            }
            return float_[size_t(it->second)];
        }
        return std::make_shared<ConstantFloatTexture>(params.getFloat(name, def));
    }

    std::shared_ptr<SpectrumTexture> spectrumTex(const ParamList& params, const std::string& name,
                                                 Spectrum def) override {
        const Param* p = params.find(name);
        if (!p) return std::make_shared<ConstantSpectrumTexture>(def);
        if (p->type == ParamType::Texture) {
            std::string tex = params.getTexture(name);
            auto it = scope_ ? scope_->spectrumTextures.find(tex)
                             : decltype(scope_->spectrumTextures.end()){};
            if (!scope_ || it == scope_->spectrumTextures.end() ||
                !spectrum_[size_t(it->second)]) {
                diag_.error(p->loc, "undefined spectrum texture \"" + tex + "\"");
                return std::make_shared<ConstantSpectrumTexture>(def);
            }
            return spectrum_[size_t(it->second)];
        }
        if (p->type == ParamType::Float) {
            // pbrt-v3 looks a spectrum parameter up among the spectra only: a float of the
            // same name is left unused (a warning) and the default applies.
            p->used = true;
            diag_.substituted(p->loc, "parameter \"float " + name +
                                          "\" where a spectrum is expected is ignored; the "
                                          "default is used (as pbrt-v3)");
            return std::make_shared<ConstantSpectrumTexture>(def);
        }
        const Param* s = params.getSpectral(name);
        if (!s) return std::make_shared<ConstantSpectrumTexture>(def);
        return std::make_shared<ConstantSpectrumTexture>(spectrumFromParam(*s));
    }

private:
    const std::vector<std::shared_ptr<FloatTexture>>& float_;
    const std::vector<std::shared_ptr<SpectrumTexture>>& spectrum_;
    Diagnostics& diag_;
    const TextureScope* scope_ = nullptr;
};

void embreeError(void* userPtr, RTCError code, const char* str) {
    auto* diag = static_cast<Diagnostics*>(userPtr);
    diag->error(FileLoc{}, std::string("Embree: ") + (str ? str : "error ") +
                               std::to_string(int(code)));
}

}  // namespace

class SceneAssembler {
public:
    SceneAssembler(Scene& s, Diagnostics& diag) : s_(s), diag_(diag) {}

    void makeDevice() {
        s_.device_ = rtcNewDevice(nullptr);
        rtcSetDeviceErrorFunction(s_.device_, embreeError, &diag_);
    }

    // Creates the Embree geometry of one primitive and attaches it with id `geomID`.
    void attach(RTCScene scene, Primitive& prim, unsigned geomID) {
        RTCGeometry g;
        if (const TriangleMesh* m = prim.shape.mesh.get()) {
            g = rtcNewGeometry(s_.device_, RTC_GEOMETRY_TYPE_TRIANGLE);
            auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
                g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m->p.size()));
            std::memcpy(vb, m->p.data(), m->p.size() * sizeof(Vec3));
            auto* ib = static_cast<uint32_t*>(
                rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                        3 * sizeof(uint32_t), m->triangleCount()));
            std::memcpy(ib, m->indices.data(), m->indices.size() * sizeof(uint32_t));
        } else if (prim.shape.curve) {
            g = rtcNewGeometry(s_.device_, RTC_GEOMETRY_TYPE_USER);
            rtcSetGeometryUserPrimitiveCount(g, unsigned(prim.shape.curve->primitiveCount()));
            rtcSetGeometryUserData(g, prim.shape.curve.get());
            rtcSetGeometryBoundsFunction(g, curvePrimBounds, nullptr);
            rtcSetGeometryIntersectFunction(g, curvePrimIntersect);
            rtcSetGeometryOccludedFunction(g, curvePrimOccluded);
        } else {
            g = rtcNewGeometry(s_.device_, RTC_GEOMETRY_TYPE_USER);
            rtcSetGeometryUserPrimitiveCount(g, 1);
            rtcSetGeometryUserData(g, prim.shape.quadric.get());
            rtcSetGeometryBoundsFunction(g, quadricBounds, nullptr);
            rtcSetGeometryIntersectFunction(g, quadricIntersect);
            rtcSetGeometryOccludedFunction(g, quadricOccluded);
        }
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene, g, geomID);
        rtcReleaseGeometry(g);
    }

    Scene& s_;
    Diagnostics& diag_;
};

namespace {

int materialIndexFor(const SceneDesc& desc, int entityMaterial, const std::vector<int>& runtime) {
    if (entityMaterial < 0 || entityMaterial >= int(desc.materials.size())) return runtime[0];
    return runtime[size_t(entityMaterial)];
}

}  // namespace

std::unique_ptr<Scene> buildScene(const SceneDesc& desc, const BuildOptions& options,
                                  Diagnostics& diag) {
    int errorsBefore = diag.errorCount();
    auto scene = std::make_unique<Scene>();
    Scene& s = *scene;
    std::string err, note;

    // --- Film, filter, camera, sampler, integrator settings.
    {
        std::string type = desc.film.present ? desc.film.type : "image";
        if (type != "image" && type != "rgb" && type != "gbuffer" && type != "spectral")
            diag.error(desc.film.loc, "unknown film type \"" + type + "\"");
        if (type != "image" && desc.film.present)
            diag.substituted(desc.film.loc, "film \"" + type + "\" is treated as \"image\"");
        s.filmParams = parseFilm(desc.film.params, &err);
        if (!err.empty()) {
            diag.error(desc.film.loc, err);
            s.filmParams = FilmParams();  // defaults: no follow-up errors from the camera
        }
        desc.film.params.reportUnused("Film \"" + type + "\"");
    }
    {
        err.clear();
        std::string type = desc.filter.present ? desc.filter.type : "box";
        std::unique_ptr<Filter> f = createFilter(type, desc.filter.params, &err);
        if (!f) diag.error(desc.filter.loc, err.empty() ? "bad pixel filter" : err);
        else desc.filter.params.reportUnused("PixelFilter \"" + type + "\"");
        s.filter = std::move(f);
    }
    {
        err.clear();
        std::string type = desc.camera.present ? desc.camera.type : "perspective";
        Mat4 worldFromCamera = glm::inverse(desc.cameraFromWorld);
        if (!isFinite(Vec3(worldFromCamera[3])) || glm::determinant(desc.cameraFromWorld) == 0.f)
            diag.error(desc.camera.loc, "the camera transform is singular");
        s.camera = createCamera(type, desc.camera.params, worldFromCamera, s.filmParams, &err);
        if (!s.camera) diag.error(desc.camera.loc, err.empty() ? "bad camera" : err);
        else desc.camera.params.reportUnused("Camera \"" + type + "\"");
    }
    {
        err.clear();
        note.clear();
        s.samplerName = desc.sampler.present ? desc.sampler.type : "halton";
        s.sampler = createSampler(s.samplerName, desc.sampler.params, options.sppOverride,
                                  options.seed, &err, &note);
        if (!s.sampler) diag.error(desc.sampler.loc, err.empty() ? "bad sampler" : err);
        else {
            if (!note.empty()) diag.warning(desc.sampler.loc, note);
            desc.sampler.params.reportUnused("Sampler \"" + s.samplerName + "\"");
        }
    }
    {
        const Entity& in = desc.integrator;
        IntegratorSettings& is = s.integrator;
        is.name = in.present ? in.type : "path";
        is.maxDepth = in.params.getInt("maxdepth", 5);
        is.rrThreshold = in.params.getFloat("rrthreshold", 1.f);
        is.lightSampleStrategy = in.params.getString("lightsamplestrategy", "spatial");
        if (is.maxDepth < 0) diag.error(in.loc, "maxdepth must not be negative");
        if (is.lightSampleStrategy != "uniform" && is.lightSampleStrategy != "power" &&
            is.lightSampleStrategy != "spatial") {
            diag.substituted(in.loc, "unknown lightsamplestrategy \"" + is.lightSampleStrategy +
                                     "\"; using \"spatial\"");
            is.lightSampleStrategy = "spatial";
        }
        static const char* known[] = {"path", "volpath", "bdpt", "mlt", "sppm", "directlighting",
                                      "whitted", "ambientocclusion"};
        bool isKnown = false;
        for (const char* k : known) isKnown |= is.name == k;
        if (!isKnown) diag.error(in.loc, "unknown integrator \"" + is.name + "\"");
        if (is.name != "path" && is.name != "volpath") {
            in.params.markAllUsed();
            diag.ignored(in.loc, "integrator \"" + is.name + "\" is rendered with rlpbrt's path "
                                 "tracer (maxdepth " + std::to_string(is.maxDepth) + ")");
        }
        in.params.reportUnused("Integrator \"" + is.name + "\"");
    }
    if (desc.accelerator.present) {
        desc.accelerator.params.markAllUsed();
        diag.ignored(desc.accelerator.loc, "Accelerator is ignored: rlpbrt always uses Embree");
    }
    // --- Media (pbrt-v3: volpath, bdpt and mlt render them; path and the others ignore
    // them). mediumIndex[i] = index in s.media of desc.media[i], -1 if not made.
    std::vector<int> mediumIndex(desc.media.size(), -1);
    {
        const std::string& in = s.integrator.name;
        bool mediaIntegrator = in == "volpath" || in == "bdpt" || in == "mlt";
        // Media are made (and their errors reported) whatever the integrator.
        for (size_t i = 0; i < desc.media.size(); ++i) {
            std::unique_ptr<Medium> m = createMedium(desc.media[i], diag);
            if (!m || !mediaIntegrator) continue;
            mediumIndex[i] = int(s.media.size());
            s.media.push_back(std::move(m));
        }
        if (!desc.media.empty() && !mediaIntegrator)
            diag.warning(desc.media[0].loc, "integrator \"" + in + "\" ignores participating "
                                            "media (as in pbrt-v3); use \"volpath\" to render them");
    }
    auto mediumByName = [&](const std::string& name) {
        if (name.empty()) return -1;
        for (size_t i = 0; i < desc.media.size(); ++i)
            if (desc.media[i].name == name) return mediumIndex[i];
        return -1;
    };
    s.cameraMedium = mediumByName(desc.cameraMedium);

    // --- Textures, in definition order (each sees the textures defined before it).
    MipMapCache mipCache;
    std::vector<std::shared_ptr<FloatTexture>> floatTex(desc.textures.size());
    std::vector<std::shared_ptr<SpectrumTexture>> specTex(desc.textures.size());
    DescTextures resolver(floatTex, specTex, diag);
    for (size_t i = 0; i < desc.textures.size(); ++i) {
        const TextureEntity& t = desc.textures[i];
        resolver.setScope(t.textures.get());
        err.clear();
        if (t.isFloat)
            floatTex[i] = createFloatTexture(t.type, t.params, t.worldFromTexture, resolver, &err,
                                             &mipCache);
        else
            specTex[i] = createSpectrumTexture(t.type, t.params, t.worldFromTexture, resolver,
                                               &err, &mipCache);
        if (!floatTex[i] && !specTex[i])
            diag.error(t.loc, "texture \"" + t.name + "\": " + err);
        else
            t.params.reportUnused("texture \"" + t.name + "\"");
    }
    s.stats.textures = desc.textures.size();

    // --- Materials, in definition order. runtime[i] = index in s.materials or -1.
    std::vector<int> runtimeMaterial(desc.materials.size(), -1);
    std::vector<const Material*> madeSoFar;
    std::vector<std::string> namesSoFar;
    for (size_t i = 0; i < desc.materials.size(); ++i) {
        const MaterialEntity& m = desc.materials[i];
        resolver.setScope(m.textures.get());
        bool ok = true;
        std::unique_ptr<Material> mat = createMaterial(m, resolver, madeSoFar, namesSoFar, diag, &ok);
        madeSoFar.push_back(mat.get());
        namesSoFar.push_back(m.name);
        if (mat) {
            runtimeMaterial[i] = int(s.materials.size());
            s.materials.push_back(std::move(mat));
        }
    }
    s.stats.materials = desc.materials.size();

    // --- Geometry.
    SceneAssembler as(s, diag);
    as.makeDevice();
    s.groups_.resize(1 + desc.objects.size());
    std::vector<int> emitterOf;  // per light: its area-light shape, -1 for a LightSource
    int emitters = 0;
    auto addPrim = [&](int shapeIndex, PrimitiveGroup& group, bool allowLights) {
        const ShapeEntity& e = desc.shapes[size_t(shapeIndex)];
        Primitive prim;
        if (!createShape(e, diag, &prim.shape)) return;
        prim.material = materialIndexFor(desc, e.material, runtimeMaterial);
        prim.mediumInside = mediumByName(e.insideMedium);
        prim.mediumOutside = mediumByName(e.outsideMedium);
        if (allowLights && e.areaLight >= 0 && prim.shape.curve) {
            diag.warning(e.loc, "an area light on a curve is not supported (pbrt-v3 cannot "
                                "sample curves either); the curve does not emit");
        } else if (allowLights && e.areaLight >= 0) {
            const Entity& al = desc.areaLights[size_t(e.areaLight)];
            std::vector<std::unique_ptr<Light>> made;
            if (createAreaLights(al.type, al.params, prim.shape, al.loc, diag, &made) &&
                !made.empty()) {
                prim.lightBase = int(s.lights.size());
                s.stats.areaLights += made.size();
                for (auto& l : made) s.lights.push_back(std::move(l));
                emitterOf.resize(s.lights.size(), emitters++);
            }
        }
        s.stats.shapes++;
        if (prim.shape.mesh) s.stats.triangles += prim.shape.mesh->triangleCount();
        else if (prim.shape.curve) s.stats.curves += prim.shape.curve->segments.size();
        else s.stats.quadrics++;
        group.prims.push_back(std::move(prim));
    };
    for (int idx : desc.worldShapes) addPrim(idx, s.groups_[0], true);
    for (size_t o = 0; o < desc.objects.size(); ++o)
        for (int idx : desc.objects[o].shapes) addPrim(idx, s.groups_[1 + o], false);
    for (const auto& al : desc.areaLights) al.params.reportUnused("AreaLightSource \"" + al.type + "\"");

    // Object scenes.
    std::vector<size_t> objectTriangles(desc.objects.size(), 0);
    for (size_t o = 0; o < desc.objects.size(); ++o) {
        PrimitiveGroup& g = s.groups_[1 + o];
        g.rtcScene = rtcNewScene(s.device_);
        for (size_t i = 0; i < g.prims.size(); ++i) {
            as.attach(g.rtcScene, g.prims[i], unsigned(i));
            objectTriangles[o] += g.prims[i].shape.triangleCount();
        }
        rtcCommitScene(g.rtcScene);
    }
    // Top scene: world primitives first (geomID = index), then instances.
    s.top_ = rtcNewScene(s.device_);
    s.groups_[0].rtcScene = s.top_;
    for (size_t i = 0; i < s.groups_[0].prims.size(); ++i)
        as.attach(s.top_, s.groups_[0].prims[i], unsigned(i));
    unsigned nextID = unsigned(s.groups_[0].prims.size());
    for (const InstanceEntity& ie : desc.instances) {
        const PrimitiveGroup& g = s.groups_[1 + size_t(ie.object)];
        if (g.prims.empty()) continue;
        Instance inst;
        inst.group = 1 + ie.object;
        inst.worldFromInstance = ie.worldFromInstance;
        inst.instanceFromWorld = glm::inverse(ie.worldFromInstance);
        if (!isFinite(Vec3(inst.instanceFromWorld[0])) || glm::determinant(ie.worldFromInstance) == 0.f) {
            diag.warning(ie.loc, "object instance with a singular transform is skipped");
            continue;
        }
        RTCGeometry gi = rtcNewGeometry(s.device_, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(gi, g.rtcScene);
        rtcSetGeometryTransform(gi, 0, RTC_FORMAT_FLOAT4X4_COLUMN_MAJOR, &inst.worldFromInstance[0][0]);
        rtcCommitGeometry(gi);
        rtcAttachGeometryByID(s.top_, gi, nextID++);
        rtcReleaseGeometry(gi);
        s.instances_.push_back(inst);
        s.stats.instances++;
        s.stats.instancedTriangles += objectTriangles[size_t(ie.object)];
    }
    rtcCommitScene(s.top_);
    RTCBounds b;
    rtcGetSceneBounds(s.top_, &b);
    s.bMin_ = Vec3(b.lower_x, b.lower_y, b.lower_z);
    s.bMax_ = Vec3(b.upper_x, b.upper_y, b.upper_z);
    if (!(s.bMin_.x <= s.bMax_.x)) s.bMin_ = s.bMax_ = Vec3(0.f);

    // --- Light sources.
    for (const LightEntity& le : desc.lights) {
        std::unique_ptr<Light> l = createLight(le.type, le.params, le.worldFromLight, le.loc, diag);
        if (!l) continue;
        if (l->kind() == LightKind::Infinite) s.infiniteLights.push_back(int(s.lights.size()));
        s.lights.push_back(std::move(l));
    }
    Vec3 center = 0.5f * (s.bMin_ + s.bMax_);
    float radius = 0.5f * glm::length(s.bMax_ - s.bMin_);
    for (auto& l : s.lights) l->preprocess(center, radius);
    emitterOf.resize(s.lights.size(), -1);
    s.lightGroups = LightGroups(s.lights, emitterOf);
    s.stats.lights = s.lights.size();
    if (s.lights.empty())
        diag.warning(FileLoc{}, "the scene has no lights: the image will be black");

    if (diag.errorCount() > errorsBefore) return nullptr;
    return scene;
}

}  // namespace rlpbrt
