#include "render/shapes.h"

#include <cmath>

#include "parser/ply.h"
#include "render/loop_subdiv.h"
#include "render/nurbs.h"
#include "render/transform.h"

namespace rlpbrt {

float TriangleMesh::triangleArea(size_t tri) const {
    const Vec3& a = p[indices[3 * tri]];
    const Vec3& b = p[indices[3 * tri + 1]];
    const Vec3& c = p[indices[3 * tri + 2]];
    return 0.5f * glm::length(glm::cross(b - a, c - a));
}

namespace {

std::string ctx(const ShapeEntity& e) { return "shape \"" + e.type + "\""; }

// Moves a mesh into world space with the entity's transform and checks its data.
bool finishMesh(const ShapeEntity& e, Diagnostics& diag, TriangleMesh* m) {
    const Mat4& w = e.worldFromObject;
    Mat4 inv = glm::inverse(w);
    bool identity = w == Mat4(1.f);
    for (auto& v : m->p) {
        if (!identity) v = transformPoint(w, v);
        if (!isFinite(v)) {
            diag.error(e.loc, ctx(e) + ": a vertex position is not finite");
            return false;
        }
    }
    for (auto& v : m->n) {
        if (!identity) v = transformNormal(inv, v);
        float len = glm::length(v);
        v = (len > 0.f && std::isfinite(len)) ? v / len : Vec3(0.f);
    }
    for (auto& v : m->s)
        if (!identity) v = transformVector(w, v);
    m->flipNormals = e.reverseOrientation != swapsHandedness(w);
    uint32_t nv = uint32_t(m->p.size());
    for (uint32_t i : m->indices)
        if (i >= nv) {
            diag.error(e.loc, ctx(e) + ": vertex index " + std::to_string(i) +
                                  " is out of range (the mesh has " + std::to_string(nv) +
                                  " vertices)");
            return false;
        }
    return true;
}

// Optional per-vertex arrays: dropped with a warning when their size does not match.
template <typename T>
void checkVertexArray(const ShapeEntity& e, Diagnostics& diag, std::vector<T>* v, size_t nv,
                      const char* what) {
    if (!v->empty() && v->size() != nv) {
        diag.warning(e.loc, ctx(e) + ": " + std::to_string(v->size()) + " " + what +
                                " values for " + std::to_string(nv) + " vertices; ignored");
        v->clear();
    }
}

std::vector<Vec3> toVec3(const std::vector<Float3>& a) {
    std::vector<Vec3> out(a.size());
    for (size_t i = 0; i < a.size(); ++i) out[i] = Vec3(a[i][0], a[i][1], a[i][2]);
    return out;
}

// The "uv" (or "st") parameter as float pairs or point2s.
std::vector<Vec2> readUV(const ParamList& params) {
    std::vector<Vec2> out;
    for (const char* name : {"uv", "st"}) {
        const Param* p = params.find(name);
        if (!p) continue;
        if (p->type == ParamType::Point2) {
            for (const auto& a : params.getPoint2s(name)) out.emplace_back(a[0], a[1]);
        } else {
            std::vector<float> f = params.getFloats(name);
            for (size_t i = 0; i + 1 < f.size(); i += 2) out.emplace_back(f[i], f[i + 1]);
        }
        break;
    }
    return out;
}

bool makeTriangleMesh(const ShapeEntity& e, Diagnostics& diag, TriangleMesh* m) {
    const ParamList& params = e.params;
    m->p = toVec3(params.getPoint3s("P"));
    std::vector<int> idx = params.getInts("indices");
    if (m->p.empty()) {
        diag.error(e.loc, ctx(e) + ": no \"point3 P\" vertex positions");
        return false;
    }
    if (idx.empty()) {
        if (m->p.size() == 3) {
            idx = {0, 1, 2};
        } else {
            diag.error(e.loc, ctx(e) + ": no \"integer indices\" (required unless P holds "
                                       "exactly three vertices)");
            return false;
        }
    }
    if (idx.size() % 3 != 0) {
        diag.error(e.loc, ctx(e) + ": " + std::to_string(idx.size()) +
                              " indices is not a multiple of three");
        return false;
    }
    m->indices.resize(idx.size());
    for (size_t i = 0; i < idx.size(); ++i) {
        if (idx[i] < 0) {
            diag.error(e.loc, ctx(e) + ": negative vertex index " + std::to_string(idx[i]));
            return false;
        }
        m->indices[i] = uint32_t(idx[i]);
    }
    m->n = toVec3(params.getNormal3s("N"));
    m->s = toVec3(params.getVector3s("S"));
    m->uv = readUV(params);
    size_t nv = m->p.size();
    checkVertexArray(e, diag, &m->n, nv, "N");
    checkVertexArray(e, diag, &m->s, nv, "S");
    checkVertexArray(e, diag, &m->uv, nv, "uv");
    return finishMesh(e, diag, m);
}

bool makePlyMesh(const ShapeEntity& e, Diagnostics& diag, TriangleMesh* m) {
    std::string file = e.params.getFilename("filename");
    if (file.empty()) {
        diag.error(e.loc, ctx(e) + ": no \"string filename\"");
        return false;
    }
    PlyMesh ply;
    std::string err;
    if (!readPly(file, &ply, &err)) {
        diag.error(e.loc, "cannot read PLY file \"" + file + "\": " + err);
        return false;
    }
    size_t nv = ply.vertexCount();
    m->p.resize(nv);
    for (size_t i = 0; i < nv; ++i)
        m->p[i] = Vec3(ply.positions[3 * i], ply.positions[3 * i + 1], ply.positions[3 * i + 2]);
    if (ply.normals.size() == 3 * nv) {
        m->n.resize(nv);
        for (size_t i = 0; i < nv; ++i)
            m->n[i] = Vec3(ply.normals[3 * i], ply.normals[3 * i + 1], ply.normals[3 * i + 2]);
    }
    if (ply.uvs.size() == 2 * nv) {
        m->uv.resize(nv);
        for (size_t i = 0; i < nv; ++i) m->uv[i] = Vec2(ply.uvs[2 * i], ply.uvs[2 * i + 1]);
    }
    m->indices = std::move(ply.indices);
    return finishMesh(e, diag, m);
}

bool makeLoopSubdiv(const ShapeEntity& e, Diagnostics& diag, TriangleMesh* m) {
    int levels = e.params.getInt("nlevels", e.params.getInt("levels", 3));
    if (levels < 0 || levels > 10) {
        diag.error(e.loc, ctx(e) + ": nlevels " + std::to_string(levels) +
                              " is outside the supported range 0..10");
        return false;
    }
    std::vector<int> idx = e.params.getInts("indices");
    std::vector<Vec3> P = toVec3(e.params.getPoint3s("P"));
    if (idx.empty() || P.empty()) {
        diag.error(e.loc, ctx(e) + ": needs \"integer indices\" and \"point3 P\"");
        return false;
    }
    // Each level splits every triangle in four: bound the result before allocating it.
    const double outTriangles = double(idx.size() / 3) * std::pow(4.0, levels);
    if (outTriangles > double(1 << 26)) {
        diag.error(e.loc, ctx(e) + ": " + std::to_string(idx.size() / 3) + " triangles at nlevels " +
                              std::to_string(levels) + " would make " +
                              std::to_string((long long)outTriangles) +
                              " triangles (at most 67108864)");
        return false;
    }
    std::vector<Vec3> outP, outN;
    std::vector<int> outIdx;
    std::string err;
    if (!loopSubdivide(levels, idx, P, &outP, &outN, &outIdx, &err)) {
        diag.error(e.loc, ctx(e) + ": " + err);
        return false;
    }
    m->p = std::move(outP);
    // pbrt-v3's limit normals point against the face winding (and its triangles then face
    // their geometric normals the same way); keep that orientation so that direction-
    // dependent BSDF terms (Fresnel) match pbrt-v3.
    for (auto& n : outN) n = -n;
    m->n = std::move(outN);
    m->indices.assign(outIdx.begin(), outIdx.end());
    return finishMesh(e, diag, m);
}

bool makeHeightField(const ShapeEntity& e, Diagnostics& diag, TriangleMesh* m) {
    int nu = e.params.getInt("nu", -1), nv = e.params.getInt("nv", -1);
    std::vector<float> z = e.params.getFloats("Pz");
    if (nu < 2 || nv < 2 || z.size() != size_t(nu) * size_t(nv)) {
        diag.error(e.loc, ctx(e) + ": needs nu, nv >= 2 and nu*nv \"float Pz\" values");
        return false;
    }
    for (int v = 0; v < nv; ++v)
        for (int u = 0; u < nu; ++u) {
            float fu = float(u) / float(nu - 1), fv = float(v) / float(nv - 1);
            m->p.emplace_back(fu, fv, z[size_t(v) * nu + u]);
            m->uv.emplace_back(fu, fv);
        }
    for (int v = 0; v < nv - 1; ++v)
        for (int u = 0; u < nu - 1; ++u) {
            uint32_t i0 = uint32_t(v * nu + u), i1 = i0 + 1, i2 = i0 + uint32_t(nu),
                     i3 = i2 + 1;
            m->indices.insert(m->indices.end(), {i0, i1, i3, i0, i3, i2});
        }
    return finishMesh(e, diag, m);
}

// pbrt-v3's "nurbs": nu, nv, uorder, vorder, uknots, vknots, u0, u1, v0, v1 (defaults: the
// knot vectors' valid range), "point3 P" or homogeneous "float Pw"; tessellated (nurbs.h).
bool makeNurbs(const ShapeEntity& e, Diagnostics& diag, TriangleMesh* m) {
    const ParamList& ps = e.params;
    NurbsPatch s;
    s.nu = ps.getInt("nu", -1);
    s.nv = ps.getInt("nv", -1);
    s.uOrder = ps.getInt("uorder", -1);
    s.vOrder = ps.getInt("vorder", -1);
    s.uKnots = ps.getFloats("uknots");
    s.vKnots = ps.getFloats("vknots");
    for (const char* name : {"nu", "nv", "uorder", "vorder", "uknots", "vknots"})
        if (!ps.has(name)) {
            diag.error(e.loc, ctx(e) + ": needs \"" + name + "\"");
            return false;
        }
    auto knot = [](const std::vector<float>& k, int i) {
        return i >= 0 && size_t(i) < k.size() ? k[size_t(i)] : 0.f;
    };
    s.u0 = ps.getFloat("u0", knot(s.uKnots, s.uOrder - 1));
    s.u1 = ps.getFloat("u1", knot(s.uKnots, s.nu));
    s.v0 = ps.getFloat("v0", knot(s.vKnots, s.vOrder - 1));
    s.v1 = ps.getFloat("v1", knot(s.vKnots, s.nv));
    if (ps.has("P")) {
        for (const Float3& a : ps.getPoint3s("P")) s.cp.emplace_back(a[0], a[1], a[2], 1.f);
    } else if (ps.has("Pw")) {
        std::vector<float> w = ps.getFloats("Pw");
        if (w.size() % 4 != 0) {
            diag.error(e.loc, ctx(e) + ": the number of \"Pw\" values must be a multiple of 4");
            return false;
        }
        for (size_t i = 0; i < w.size(); i += 4) s.cp.emplace_back(w[i], w[i + 1], w[i + 2], w[i + 3]);
    } else {
        diag.error(e.loc, ctx(e) + ": needs control points \"point3 P\" or \"float Pw\"");
        return false;
    }
    std::string err;
    if (!validateNurbs(s, &err)) {
        diag.error(e.loc, ctx(e) + ": " + err);
        return false;
    }
    tessellateNurbs(s, &m->p, &m->n, &m->uv, &m->indices);
    return finishMesh(e, diag, m);
}

bool makeQuadric(const ShapeEntity& e, Diagnostics& diag, QuadricShape* q) {
    const ParamList& p = e.params;
    Quadric& Q = q->quadric;
    float phimax = clamp(p.getFloat("phimax", 360.f), 0.f, 360.f);
    if (e.type == "sphere") {
        float r = p.getFloat("radius", 1.f);
        Q = makeSphere(r, p.getFloat("zmin", -r), p.getFloat("zmax", r), phimax);
    } else if (e.type == "disk") {
        Q = makeDisk(p.getFloat("height", 0.f), p.getFloat("radius", 1.f),
                     p.getFloat("innerradius", 0.f), phimax);
    } else if (e.type == "cylinder") {
        Q = makeCylinder(p.getFloat("radius", 1.f), p.getFloat("zmin", -1.f),
                         p.getFloat("zmax", 1.f), phimax);
    } else if (e.type == "cone") {
        Q = makeCone(p.getFloat("height", 1.f), p.getFloat("radius", 1.f), phimax);
    } else if (e.type == "paraboloid") {
        Q = makeParaboloid(p.getFloat("radius", 1.f), p.getFloat("zmin", 0.f),
                           p.getFloat("zmax", 1.f), phimax);
    } else {  // hyperboloid
        Float3 a = p.getPoint3("p1", {0.f, 0.f, 0.f}), b = p.getPoint3("p2", {1.f, 1.f, 1.f});
        Q = makeHyperboloid(Vec3(a[0], a[1], a[2]), Vec3(b[0], b[1], b[2]), phimax);
    }
    if (Q.kind != Quadric::Kind::Hyperboloid && (!(Q.radius > 0.f) || !std::isfinite(Q.radius))) {
        diag.error(e.loc, ctx(e) + ": radius must be positive and finite");
        return false;
    }
    if (!(area(Q) > 0.f) || !std::isfinite(area(Q))) {
        diag.warning(e.loc, ctx(e) + ": the shape has zero area; skipped");
        return false;
    }
    q->worldFromObject = e.worldFromObject;
    q->objectFromWorld = glm::inverse(e.worldFromObject);
    q->flipNormals = e.reverseOrientation != swapsHandedness(e.worldFromObject);
    return true;
}

}  // namespace

bool createShape(const ShapeEntity& e, Diagnostics& diag, ShapeData* out) {
    out->type = e.type;
    out->loc = e.loc;
    const Param* alpha = e.params.find("alpha");
    if (alpha && alpha->type == ParamType::Texture) {
        alpha->used = true;
        diag.ignored(e.loc, "alpha textures (cut-outs) are not supported yet; the shape is "
                            "rendered opaque");
    } else if (alpha) {
        float a = e.params.getFloat("alpha", 1.f);
        if (a == 0.f) return false;  // fully transparent: pbrt-v3 makes no geometry either
    }
    if (const Param* sa = e.params.find("shadowalpha")) {
        sa->used = true;
        diag.ignored(e.loc, "\"shadowalpha\" is not supported; shadows are opaque");
    }
    bool ok;
    if (e.type == "trianglemesh" || e.type == "plymesh" || e.type == "loopsubdiv" ||
        e.type == "heightfield" || e.type == "nurbs") {
        auto m = std::make_shared<TriangleMesh>();
        if (e.type == "trianglemesh") ok = makeTriangleMesh(e, diag, m.get());
        else if (e.type == "plymesh") ok = makePlyMesh(e, diag, m.get());
        else if (e.type == "loopsubdiv") ok = makeLoopSubdiv(e, diag, m.get());
        else if (e.type == "nurbs") ok = makeNurbs(e, diag, m.get());
        else ok = makeHeightField(e, diag, m.get());
        if (ok) out->mesh = std::move(m);
    } else if (e.type == "sphere" || e.type == "disk" || e.type == "cylinder" ||
               e.type == "cone" || e.type == "paraboloid" || e.type == "hyperboloid") {
        auto q = std::make_shared<QuadricShape>();
        ok = makeQuadric(e, diag, q.get());
        if (ok) out->quadric = std::move(q);
    } else if (e.type == "curve") {
        auto c = std::make_shared<CurveShape>();
        ok = makeCurveShape(e, diag, c.get());
        if (ok) out->curve = std::move(c);
    } else {
        diag.error(e.loc, "unknown shape type \"" + e.type + "\"");
        return false;
    }
    if (ok) e.params.reportUnused(ctx(e));
    return ok;
}

}  // namespace rlpbrt
