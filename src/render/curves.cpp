#include "render/curves.h"

#include "render/transform.h"

namespace rlpbrt {

namespace {

Vec3 mix3(float t, const Vec3& a, const Vec3& b) { return (1.f - t) * a + t * b; }

// The point of the cubic with control points p whose blossom arguments are (a, b, c): the
// control points of the piece over [u0, u1] are blossom(u0,u0,u0), (u0,u0,u1), (u0,u1,u1),
// (u1,u1,u1).
Vec3 blossom(const Vec3 p[4], float a, float b, float c) {
    Vec3 q0 = mix3(a, p[0], p[1]), q1 = mix3(a, p[1], p[2]), q2 = mix3(a, p[2], p[3]);
    Vec3 r0 = mix3(b, q0, q1), r1 = mix3(b, q1, q2);
    return mix3(c, r0, r1);
}

void pieceControlPoints(const Vec3 p[4], float u0, float u1, Vec3 out[4]) {
    out[0] = blossom(p, u0, u0, u0);
    out[1] = blossom(p, u0, u0, u1);
    out[2] = blossom(p, u0, u1, u1);
    out[3] = blossom(p, u1, u1, u1);
}

// de Casteljau at 1/2: the halves are out[0..3] and out[3..6].
void splitInHalf(const Vec3 p[4], Vec3 out[7]) {
    Vec3 a = 0.5f * (p[0] + p[1]), b = 0.5f * (p[1] + p[2]), c = 0.5f * (p[2] + p[3]);
    Vec3 ab = 0.5f * (a + b), bc = 0.5f * (b + c);
    out[0] = p[0];
    out[1] = a;
    out[2] = ab;
    out[3] = 0.5f * (ab + bc);
    out[4] = bc;
    out[5] = c;
    out[6] = p[3];
}

// The cubic's point at u and its derivative (the chord p[3] - p[0] where the derivative
// vanishes, as pbrt-v3 does, so that a normal exists everywhere).
Vec3 bezier(const Vec3 p[4], float u, Vec3* deriv) {
    Vec3 q0 = mix3(u, p[0], p[1]), q1 = mix3(u, p[1], p[2]), q2 = mix3(u, p[2], p[3]);
    Vec3 r0 = mix3(u, q0, q1), r1 = mix3(u, q1, q2);
    if (deriv) {
        Vec3 dr = r1 - r0;
        *deriv = glm::dot(dr, dr) > 0.f ? 3.f * dr : p[3] - p[0];
    }
    return mix3(u, r0, r1);
}

float widthAt(const CurveSegment& s, float u) { return lerp(u, s.width[0], s.width[1]); }

// The ribbon normal at u: the end normals slerped (their angle clamped to [0, 90] degrees,
// as pbrt-v3).
Vec3 ribbonNormal(const CurveSegment& s, float u) {
    if (s.normalAngle < 1e-4f) return s.n[0];
    float a = std::sin((1.f - u) * s.normalAngle) * s.invSinNormalAngle;
    float b = std::sin(u * s.normalAngle) * s.invSinNormalAngle;
    return a * s.n[0] + b * s.n[1];
}

// An orthonormal frame with the ray along +z from its origin and the curve's chord (its
// part across the ray) along +x; right-handed.
struct RayFrame {
    Vec3 o, ex, ey, ez;
    RayFrame(const Vec3& origin, const Vec3& d, const Vec3& chord) : o(origin) {
        ez = glm::normalize(d);
        Vec3 x = chord - ez * glm::dot(chord, ez);
        float len2 = glm::dot(x, x);
        if (len2 > 0.f && std::isfinite(len2)) {
            ex = x / std::sqrt(len2);
            ey = glm::cross(ez, ex);
        } else {
            Frame f = Frame::fromZ(ez);
            ex = f.s;
            ey = f.t;
        }
    }
    Vec3 point(const Vec3& p) const {
        Vec3 q = p - o;
        return Vec3(glm::dot(q, ex), glm::dot(q, ey), glm::dot(q, ez));
    }
    Vec3 vector(const Vec3& v) const {
        return Vec3(glm::dot(v, ex), glm::dot(v, ey), glm::dot(v, ez));
    }
    Vec3 toObject(const Vec3& v) const { return v.x * ex + v.y * ey + v.z * ez; }
};

// Does the box of p[0..3], grown by r, overlap the ray's segment from 0 to zMax along z?
bool boxOverlapsRay(const Vec3 p[4], float r, float zMax) {
    Vec3 lo = glm::min(glm::min(p[0], p[1]), glm::min(p[2], p[3])) - Vec3(r);
    Vec3 hi = glm::max(glm::max(p[0], p[1]), glm::max(p[2], p[3])) + Vec3(r);
    return lo.y <= 0.f && hi.y >= 0.f && lo.x <= 0.f && hi.x >= 0.f && hi.z >= 0.f &&
           lo.z <= zMax;
}

struct LeafHit {
    float z = 0.f, u = 0.f, v = 0.f, width = 0.f;
    Vec3 nRibbon{0.f};
};

// The search of one primitive in ray space: the ray is the +z axis from the origin.
struct CurveSearch {
    const CurveSegment* seg;
    CurveType type;
    Vec3 dObj;         // the object-space ray direction (ribbons' foreshortening)
    float invDLen;     // 1 / |dObj|
    float zMax;        // nearest hit so far (ray-space distance)
    bool anyHit;       // stop at the first hit
    bool found = false;
    LeafHit best;

    void search(const Vec3 cp[4], float u0, float u1, int depth) {
        if (depth > 0) {
            Vec3 half[7];
            splitInHalf(cp, half);
            float um = 0.5f * (u0 + u1);
            float us[3] = {u0, um, u1};
            for (int i = 0; i < 2; ++i) {
                float r = 0.5f * std::max(widthAt(*seg, us[i]), widthAt(*seg, us[i + 1]));
                if (!boxOverlapsRay(&half[3 * i], r, zMax)) continue;
                search(&half[3 * i], us[i], us[i + 1], depth - 1);
                if (found && anyHit) return;
            }
            return;
        }
        leaf(cp, u0, u1);
    }

    // The piece is nearly straight here: the ray's nearest point on the chord (in the plane
    // across the ray) gives u; the curve's point there must lie within half the width.
    void leaf(const Vec3 cp[4], float u0, float u1) {
        Vec2 o0(-cp[0].x, -cp[0].y), o3(-cp[3].x, -cp[3].y);
        // Beyond the perpendiculars to the end tangents: another piece's business.
        if (glm::dot(Vec2(cp[1] - cp[0]), o0) < 0.f) return;
        if (glm::dot(Vec2(cp[2] - cp[3]), o3) < 0.f) return;
        Vec2 chord(cp[3] - cp[0]);
        float denom = glm::dot(chord, chord);
        if (!(denom > 0.f)) return;
        float w = glm::dot(o0, chord) / denom;
        float u = clamp(lerp(w, u0, u1), u0, u1);
        float width = widthAt(*seg, u), hitWidth = width;
        Vec3 nr(0.f);
        if (type == CurveType::Ribbon) {
            nr = ribbonNormal(*seg, u);
            hitWidth *= std::abs(glm::dot(nr, dObj)) * invDLen;
        }
        Vec3 tangent;
        Vec3 pc = bezier(cp, clamp(w, 0.f, 1.f), &tangent);
        float dist2 = pc.x * pc.x + pc.y * pc.y;
        if (dist2 > 0.25f * hitWidth * hitWidth) return;
        if (!(pc.z > 0.f) || !(pc.z < zMax)) return;
        float dist = std::sqrt(dist2);
        float side = tangent.x * -pc.y + pc.x * tangent.y;
        float dv = hitWidth > 0.f ? dist / hitWidth : 0.f;
        best.z = pc.z;
        best.u = u;
        best.v = side > 0.f ? 0.5f + dv : 0.5f - dv;
        best.width = hitWidth;
        best.nRibbon = nr;
        zMax = pc.z;
        found = true;
    }
};

}  // namespace

const CurveSegment& CurveShape::primitive(unsigned prim, float* u0, float* u1) const {
    unsigned n = 1u << unsigned(splitDepth);
    unsigned k = prim & (n - 1);
    *u0 = float(k) / float(n);
    *u1 = float(k + 1) / float(n);
    return segments[prim >> unsigned(splitDepth)];
}

Vec3 evalCurve(const CurveSegment& seg, float u, Vec3* tangent) {
    return bezier(seg.cp, u, tangent);
}

void curveBounds(const CurveShape& c, unsigned prim, Vec3* lo, Vec3* hi) {
    float u0, u1;
    const CurveSegment& s = c.primitive(prim, &u0, &u1);
    Vec3 p[4];
    pieceControlPoints(s.cp, u0, u1, p);
    float r = 0.5f * std::max(widthAt(s, u0), widthAt(s, u1));
    *lo = glm::min(glm::min(p[0], p[1]), glm::min(p[2], p[3])) - Vec3(r);
    *hi = glm::max(glm::max(p[0], p[1]), glm::max(p[2], p[3])) + Vec3(r);
}

float curveArea(const CurveShape& c, unsigned prim) {
    float u0, u1;
    const CurveSegment& s = c.primitive(prim, &u0, &u1);
    Vec3 p[4];
    pieceControlPoints(s.cp, u0, u1, p);
    float len = glm::length(p[1] - p[0]) + glm::length(p[2] - p[1]) + glm::length(p[3] - p[2]);
    return len * 0.5f * (widthAt(s, u0) + widthAt(s, u1));
}

namespace {

// The parameter of the point of s's centre line nearest to p, with its squared distance: the
// best of 17 samples, refined by golden-section search around it.
float nearestOnSegment(const CurveSegment& s, const Vec3& p, float* dist2) {
    auto d2 = [&](float u) {
        Vec3 q = bezier(s.cp, u, nullptr) - p;
        return glm::dot(q, q);
    };
    constexpr int kSamples = 16;
    float bestU = 0.f, best = d2(0.f);
    for (int i = 1; i <= kSamples; ++i) {
        float u = float(i) / float(kSamples), v = d2(u);
        if (v < best) best = v, bestU = u;
    }
    float a = std::max(0.f, bestU - 1.f / kSamples), b = std::min(1.f, bestU + 1.f / kSamples);
    constexpr float kGolden = 0.618034f;
    float x1 = b - kGolden * (b - a), x2 = a + kGolden * (b - a);
    float f1 = d2(x1), f2 = d2(x2);
    for (int it = 0; it < 16; ++it) {
        if (f1 < f2) {
            b = x2, x2 = x1, f2 = f1;
            x1 = b - kGolden * (b - a);
            f1 = d2(x1);
        } else {
            a = x1, x1 = x2, f1 = f2;
            x2 = a + kGolden * (b - a);
            f2 = d2(x2);
        }
    }
    float u = f1 < f2 ? x1 : x2, v = std::min(f1, f2);
    if (v < best) best = v, bestU = u;
    *dist2 = best;
    return bestU;
}

// The search of one primitive along the ray o + t d, up to zMax (distance along the ray).
struct PrimitiveSearch {
    RayFrame frame;
    CurveSearch search;
    PrimitiveSearch(const CurveShape& c, const CurveSegment& s, const Vec3 pObj[4],
                    const Vec3& o, const Vec3& d, float invDLen, float zMax, bool anyHit)
        : frame(o, d, pObj[3] - pObj[0]),
          search{&s, c.type, d, invDLen, zMax, anyHit, false, LeafHit()} {}

    bool run(const CurveSegment& s, const Vec3 pObj[4], float u0, float u1) {
        Vec3 cp[4];
        for (int i = 0; i < 4; ++i) cp[i] = frame.point(pObj[i]);
        float r = 0.5f * std::max(widthAt(s, u0), widthAt(s, u1));
        if (!boxOverlapsRay(cp, r, search.zMax)) return false;
        // Subdivision depth: enough halvings that each leaf's control points lie within
        // width / 20 of its chord (pbrt-v3's bound from the second differences).
        float l0 = 0.f;
        for (int i = 0; i < 2; ++i) {
            Vec3 dd = glm::abs(cp[i] - 2.f * cp[i + 1] + cp[i + 2]);
            l0 = std::max(l0, std::max(dd.x, std::max(dd.y, dd.z)));
        }
        float eps = 0.05f * std::max(s.width[0], s.width[1]);
        int depth = 0;
        if (eps > 0.f) {
            float x = 1.41421356f * 6.f * l0 / (8.f * eps);
            if (!std::isfinite(x)) depth = 10;
            else if (x >= 1.f) depth = clamp(int(std::lround(std::log2(x))) / 2, 0, 10);
        }
        search.search(cp, u0, u1, depth);
        return search.found;
    }
};

}  // namespace

bool intersectCurve(const CurveShape& c, unsigned prim, const Vec3& o, const Vec3& d,
                    float tMax, CurveHit* hit) {
    float u0, u1;
    const CurveSegment& s = c.primitive(prim, &u0, &u1);
    float dLen = glm::length(d);
    if (!(dLen > 0.f)) return false;
    Vec3 pObj[4];
    pieceControlPoints(s.cp, u0, u1, pObj);
    float zMax = tMax < Infinity ? tMax * dLen : Infinity;
    PrimitiveSearch ps(c, s, pObj, o, d, 1.f / dLen, zMax, hit == nullptr);
    if (!ps.run(s, pObj, u0, u1)) return false;
    float zShift = 0.f;
    // A ray that starts on this curve segment (a ray leaving a hit on it: the hit point lies
    // within half the width of the centre line) would find the curve's ray-facing band
    // again wherever it runs within half a width of the centre line. pbrt-v3 offsets such
    // rays' origins by about twice the width along the normal; here the origin moves twice
    // the width away from the centre line, across the curve in the ray's own direction, and
    // the primitive is searched again from there (straight curves are then left behind;
    // a curve that bends back is still found).
    {
        float wMax = std::max(s.width[0], s.width[1]);
        Vec3 lo = glm::min(glm::min(s.cp[0], s.cp[1]), glm::min(s.cp[2], s.cp[3])) - Vec3(wMax);
        Vec3 hi = glm::max(glm::max(s.cp[0], s.cp[1]), glm::max(s.cp[2], s.cp[3])) + Vec3(wMax);
        bool inBox = o.x >= lo.x && o.y >= lo.y && o.z >= lo.z && o.x <= hi.x && o.y <= hi.y &&
                     o.z <= hi.z;
        float dist2 = Infinity;
        float us = inBox ? nearestOnSegment(s, o, &dist2) : 0.f;
        float reach = 0.6f * widthAt(s, us);
        if (inBox && dist2 <= reach * reach) {
            Vec3 tangent;
            bezier(s.cp, us, &tangent);
            Vec3 dn = d / dLen, t = glm::normalize(tangent);
            Vec3 across = dn - t * glm::dot(dn, t);
            float len2 = glm::dot(across, across);
            across = len2 > 1e-12f ? across / std::sqrt(len2) : Frame::fromZ(t).s;
            Vec3 o2 = o + 2.f * widthAt(s, us) * across;
            zShift = glm::dot(o2 - o, dn);
            PrimitiveSearch again(c, s, pObj, o2, d, 1.f / dLen, zMax - zShift, hit == nullptr);
            if (!again.run(s, pObj, u0, u1)) return false;
            ps = again;
        }
    }
    if (!hit) return true;
    const RayFrame& frame = ps.frame;
    const CurveSearch& search = ps.search;
    const LeafHit& b = search.best;
    hit->t = (b.z + zShift) / dLen;
    hit->uv = Vec2(b.u, b.v);
    hit->width = b.width;
    Vec3 dpdu;
    bezier(s.cp, b.u, &dpdu);
    Vec3 dpdv;
    if (c.type == CurveType::Ribbon) {
        dpdv = glm::normalize(glm::cross(b.nRibbon, dpdu)) * b.width;
    } else {
        // Across the curve in the plane facing the ray; a cylinder turns it about the
        // tangent from -90 degrees (v = 0) to +90 degrees (v = 1), so that its normal sweeps
        // round the curve as a tube's would.
        Vec3 a = frame.vector(dpdu);
        Vec3 across = glm::normalize(Vec3(-a.y, a.x, 0.f));
        if (c.type == CurveType::Cylinder) {
            float theta = radians(lerp(b.v, -90.f, 90.f));
            Vec3 n0 = glm::normalize(glm::cross(a, across));
            across = across * std::cos(theta) - n0 * std::sin(theta);
        }
        dpdv = frame.toObject(across * b.width);
    }
    hit->dpdu = dpdu;
    hit->dpdv = dpdv;
    Vec3 n = glm::cross(dpdu, dpdv);
    float len = glm::length(n);
    n = len > 0.f && std::isfinite(len) ? n / len : -d / dLen;
    hit->n = c.flipNormals ? -n : n;
    return true;
}

// ------------------------------------------------------------------------------------------
// The Shape directive.

bool makeCurveShape(const ShapeEntity& e, Diagnostics& diag, CurveShape* out) {
    const ParamList& p = e.params;
    const std::string what = "shape \"curve\"";
    float width = p.getFloat("width", 1.f);
    float width0 = p.getFloat("width0", width), width1 = p.getFloat("width1", width);
    if (!(width0 >= 0.f) || !(width1 >= 0.f) || !std::isfinite(width0) ||
        !std::isfinite(width1)) {
        diag.error(e.loc, what + ": widths must be finite and not negative");
        return false;
    }
    int degree = p.getInt("degree", 3);
    if (degree != 2 && degree != 3) {
        diag.error(e.loc, what + ": degree " + std::to_string(degree) +
                              " is not supported (2 or 3)");
        return false;
    }
    std::string basis = p.getString("basis", "bezier");
    if (basis != "bezier" && basis != "bspline") {
        diag.error(e.loc, what + ": basis \"" + basis + "\" is not supported (\"bezier\" or "
                                 "\"bspline\")");
        return false;
    }
    std::vector<Float3> P = p.getPoint3s("P");
    int ncp = int(P.size());
    int nSegments = 0;
    if (basis == "bezier") {
        if (ncp < degree + 1 || (ncp - 1) % degree != 0) {
            diag.error(e.loc, what + ": " + std::to_string(ncp) + " control points \"P\"; a "
                                     "degree " + std::to_string(degree) + " Bezier curve needs " +
                                     std::to_string(degree + 1) + " + n * " +
                                     std::to_string(degree));
            return false;
        }
        nSegments = (ncp - 1) / degree;
    } else {
        if (ncp < degree + 1) {
            diag.error(e.loc, what + ": " + std::to_string(ncp) + " control points \"P\"; a "
                                     "degree " + std::to_string(degree) + " b-spline needs at "
                                     "least " + std::to_string(degree + 1));
            return false;
        }
        nSegments = ncp - degree;
    }
    for (const Float3& q : P)
        if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2])) {
            diag.error(e.loc, what + ": a control point is not finite");
            return false;
        }

    std::string type = p.getString("type", "flat");
    if (type == "flat") out->type = CurveType::Flat;
    else if (type == "ribbon") out->type = CurveType::Ribbon;
    else if (type == "cylinder") out->type = CurveType::Cylinder;
    else {
        diag.warning(e.loc, what + ": unknown curve type \"" + type + "\"; using \"cylinder\" "
                                   "(as pbrt-v3)");
        out->type = CurveType::Cylinder;
    }
    std::vector<Float3> N;
    if (p.has("N")) {
        N = p.getNormal3s("N");
        if (out->type != CurveType::Ribbon) {
            diag.warning(e.loc, what + ": normals \"N\" are only used by \"ribbon\" curves");
            N.clear();
        } else if (int(N.size()) != nSegments + 1) {
            diag.error(e.loc, what + ": " + std::to_string(N.size()) + " normals \"N\"; a "
                                     "ribbon of " + std::to_string(nSegments) +
                                     " segments needs " + std::to_string(nSegments + 1));
            return false;
        }
    }
    if (out->type == CurveType::Ribbon && N.empty()) {
        diag.error(e.loc, what + ": a \"ribbon\" curve needs normals \"N\" at its segments' ends");
        return false;
    }
    int splitDepth = 3;
    if (const Param* sd = p.find("splitdepth"))
        splitDepth = sd->type == ParamType::Integer ? p.getInt("splitdepth", 3)
                                                    : int(p.getFloat("splitdepth", 3.f));
    if (splitDepth < 0 || splitDepth > 10) {
        diag.warning(e.loc, what + ": splitdepth " + std::to_string(splitDepth) +
                                " is clamped to [0, 10]");
        splitDepth = clamp(splitDepth, 0, 10);
    }
    out->splitDepth = splitDepth;

    auto pt = [&](int i) { return Vec3(P[size_t(i)][0], P[size_t(i)][1], P[size_t(i)][2]); };
    out->segments.resize(size_t(nSegments));
    for (int seg = 0; seg < nSegments; ++seg) {
        CurveSegment& s = out->segments[size_t(seg)];
        // Every basis becomes cubic Bezier control points (pbrt-v3 does the same).
        if (basis == "bezier") {
            int b = seg * degree;
            if (degree == 3) {
                for (int i = 0; i < 4; ++i) s.cp[i] = pt(b + i);
            } else {  // degree elevation of a quadratic
                s.cp[0] = pt(b);
                s.cp[1] = mix3(2.f / 3.f, pt(b), pt(b + 1));
                s.cp[2] = mix3(1.f / 3.f, pt(b + 1), pt(b + 2));
                s.cp[3] = pt(b + 2);
            }
        } else if (degree == 3) {  // uniform cubic b-spline: blossoming to Bezier points
            Vec3 a = pt(seg), b = pt(seg + 1), c = pt(seg + 2), d = pt(seg + 3);
            Vec3 b1 = mix3(2.f / 3.f, a, b), b2 = mix3(1.f / 3.f, b, c);
            Vec3 b3 = mix3(2.f / 3.f, b, c), b4 = mix3(1.f / 3.f, c, d);
            s.cp[0] = 0.5f * (b1 + b2);
            s.cp[1] = b2;
            s.cp[2] = b3;
            s.cp[3] = 0.5f * (b3 + b4);
        } else {  // uniform quadratic b-spline, then degree elevation
            Vec3 a = pt(seg), b = pt(seg + 1), c = pt(seg + 2);
            Vec3 q0 = 0.5f * (a + b), q2 = 0.5f * (b + c);
            s.cp[0] = q0;
            s.cp[1] = mix3(2.f / 3.f, q0, b);
            s.cp[2] = mix3(1.f / 3.f, b, q2);
            s.cp[3] = q2;
        }
        s.width[0] = lerp(float(seg) / float(nSegments), width0, width1);
        s.width[1] = lerp(float(seg + 1) / float(nSegments), width0, width1);
        if (!N.empty()) {
            for (int i = 0; i < 2; ++i) {
                const Float3& q = N[size_t(seg + i)];
                Vec3 n(q[0], q[1], q[2]);
                float len = glm::length(n);
                if (!(len > 0.f) || !std::isfinite(len)) {
                    diag.error(e.loc, what + ": a normal \"N\" is zero or not finite");
                    return false;
                }
                s.n[i] = n / len;
            }
            s.normalAngle = std::acos(clamp(glm::dot(s.n[0], s.n[1]), 0.f, 1.f));
            float sn = std::sin(s.normalAngle);
            s.invSinNormalAngle = sn > 0.f ? 1.f / sn : 0.f;
        }
    }
    out->worldFromObject = e.worldFromObject;
    out->objectFromWorld = glm::inverse(e.worldFromObject);
    out->flipNormals = e.reverseOrientation != swapsHandedness(e.worldFromObject);
    return true;
}

}  // namespace rlpbrt
