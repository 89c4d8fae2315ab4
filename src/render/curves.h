// The "curve" shape (pbrt-v3's semantics): cubic Bezier segments swept as flat, cylinder or
// ribbon curves, with the intersection test pbrt-v3 defines. No Embree here: scene.cpp makes
// each curve shape one Embree user geometry whose primitives are the sub-segments below.
//
// Why not Embree's native curves: its flat curves are chains of ray-facing quads (4 per
// segment by default, "subpixel size" assumed), its normal-oriented curves interpolate one
// normal per control point with the curve's basis, and its round curves are true swept tubes.
// pbrt-v3's curves are none of these: a ray-facing band found by recursive subdivision down
// to a flatness of width/20, a ribbon whose width is foreshortened by the cosine of a normal
// slerped between the two end normals, and a "cylinder" that is the flat band shaded with a
// normal rotated across it. So every type uses our own test (curves.cpp).
#pragma once

#include <string>
#include <vector>

#include "parser/diagnostics.h"
#include "render/math.h"
#include "render/scene_desc.h"

namespace rlpbrt {

enum class CurveType { Flat, Cylinder, Ribbon };

// One cubic Bezier segment in object space (pbrt-v3's CurveCommon): u runs over [0, 1] along
// the segment; widths are at u = 0 and u = 1.
struct CurveSegment {
    Vec3 cp[4];
    float width[2] = {1.f, 1.f};
    Vec3 n[2]{Vec3(0.f), Vec3(0.f)};  // ribbons: unit normals at the two ends
    float normalAngle = 0.f, invSinNormalAngle = 0.f;
};

// The geometry of one "curve" Shape directive: its segments, each split into 2^splitDepth
// primitives of equal u range (pbrt-v3's "splitdepth": separate bounding boxes for the
// acceleration structure, so thin curves are not one loose box each).
struct CurveShape {
    CurveType type = CurveType::Flat;
    std::vector<CurveSegment> segments;
    int splitDepth = 3;
    Mat4 worldFromObject{1.f}, objectFromWorld{1.f};
    bool flipNormals = false;  // ReverseOrientation xor handedness swap

    size_t primitiveCount() const { return segments.size() << splitDepth; }
    // The segment and u range of primitive `prim`.
    const CurveSegment& primitive(unsigned prim, float* u0, float* u1) const;
};

// A ray's hit on a curve primitive, in object space (t is the ray parameter, unchanged by
// the transform).
struct CurveHit {
    float t = 0.f;
    Vec2 uv{0.f};      // u along the segment, v across (0.5 on the centre line)
    Vec3 dpdu{0.f}, dpdv{0.f};
    Vec3 n{0.f};       // unit normal: normalize(cross(dpdu, dpdv)), flipped by flipNormals
    float width = 0.f; // the curve's width at the hit
};

// Object-space bounds of primitive `prim`, including its half width.
void curveBounds(const CurveShape& c, unsigned prim, Vec3* lo, Vec3* hi);

// Intersects the object-space ray o + t d (d need not be unit) with primitive `prim` for t in
// (0, tMax); the nearest hit. A ray whose origin lies on the curve (within its half width of
// the centre line, as rays leaving a curve hit do) does not hit the piece it starts on (see
// curves.cpp). hit may be null (any hit).
bool intersectCurve(const CurveShape& c, unsigned prim, const Vec3& o, const Vec3& d,
                    float tMax, CurveHit* hit);

// pbrt-v3's approximate area of the curve in object space: per primitive, the control
// polygon's length times the mean width.
float curveArea(const CurveShape& c, unsigned prim);

// The point and tangent of segment `seg` at u (object space).
Vec3 evalCurve(const CurveSegment& seg, float u, Vec3* tangent = nullptr);

// Reads a "curve" Shape entity (P, width/width0/width1, type, N, splitdepth, basis, degree).
// Errors are reported at the entity's location; returns false for no geometry.
bool makeCurveShape(const ShapeEntity& e, Diagnostics& diag, CurveShape* out);

}  // namespace rlpbrt
