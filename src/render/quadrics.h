// Analytic quadric shapes of pbrt-v3 (sphere, disk, cylinder, cone, paraboloid, hyperboloid)
// in object space: ray intersection, area, bounds, uniform area sampling and, for spheres,
// solid-angle (cone) sampling. The caller transforms rays and results and applies
// ReverseOrientation (flip n) itself.
#pragma once

#include "render/math.h"

namespace rlpbrt {

// Surface point found by intersect(). All vectors are in object space.
struct QuadricHit {
    float t = 0;      // ray parameter (in units of |d|)
    Vec3 p{0.f};      // hit point, refined onto the surface
    Vec3 n{0.f};      // unit geometric normal = normalize(cross(dpdu, dpdv)), as pbrt-v3
    Vec2 uv{0.f};     // pbrt-v3 parametrisation, both in [0,1]
    Vec3 dpdu{0.f}, dpdv{0.f};
    Vec3 pError{0.f}; // conservative absolute error bound of p (for ray-origin offsets)
};

// A quadric with pbrt-v3's parameters. Build it with the make*() functions, which apply
// pbrt-v3's clamping and precompute derived values; fields unused by a kind are ignored.
struct Quadric {
    enum class Kind { Sphere, Disk, Cylinder, Cone, Paraboloid, Hyperboloid };
    Kind kind = Kind::Sphere;
    float radius = 1;       // sphere, disk, cylinder, cone, paraboloid
    float zMin = -1, zMax = 1;  // sphere, cylinder, paraboloid (hyperboloid: from p1, p2)
    float phiMax = 2 * Pi;  // radians, in [0, 2pi]
    float innerRadius = 0;  // disk
    float height = 0;       // disk: plane z = height; cone: apex at z = height
    Vec3 p1{0.f}, p2{0.f};  // hyperboloid: the segment swept around the z axis

    // Derived (set by the make*() functions).
    float thetaZMin = Pi, thetaZMax = 0;  // sphere: polar angles of zMin and zMax
    // Hyperboloid: x^2 + y^2 = hypA z^2 + hypB z + hypC; rMax and numerically integrated area.
    double hypA = 0, hypB = 0, hypC = 0;
    float rMax = 0, hypArea = 0;
};

// pbrt-v3 "sphere": radius 1, zmin -radius, zmax radius, phimax 360 (degrees).
Quadric makeSphere(float radius, float zMin, float zMax, float phiMaxDeg);
// Full sphere of the given radius.
Quadric makeSphere(float radius = 1.f);
// pbrt-v3 "disk": height 0, radius 1, innerradius 0, phimax 360 (degrees).
Quadric makeDisk(float height = 0.f, float radius = 1.f, float innerRadius = 0.f,
                 float phiMaxDeg = 360.f);
// pbrt-v3 "cylinder": radius 1, zmin -1, zmax 1, phimax 360 (degrees).
Quadric makeCylinder(float radius = 1.f, float zMin = -1.f, float zMax = 1.f,
                     float phiMaxDeg = 360.f);
// pbrt-v3 "cone": height 1, radius 1, phimax 360 (degrees); base at z = 0, apex at z = height.
Quadric makeCone(float height = 1.f, float radius = 1.f, float phiMaxDeg = 360.f);
// pbrt-v3 "paraboloid": radius 1, zmin 0, zmax 1, phimax 360 (degrees); z = zMax (r/radius)^2.
Quadric makeParaboloid(float radius = 1.f, float zMin = 0.f, float zMax = 1.f,
                       float phiMaxDeg = 360.f);
// pbrt-v3 "hyperboloid": p1 (0,0,0), p2 (1,1,1), phimax 360 (degrees); the surface swept by
// the segment p1-p2 rotating about z. Degenerate (never hit, area 0) when p1.z == p2.z.
Quadric makeHyperboloid(const Vec3& p1 = Vec3(0.f), const Vec3& p2 = Vec3(1.f),
                        float phiMaxDeg = 360.f);

// Nearest intersection of the ray o + t d with t in (tMin, tMax); partial shapes (phiMax,
// z range, inner radius) are respected. `hit` may be null (occlusion test).
bool intersect(const Quadric& q, const Vec3& o, const Vec3& d, float tMin, float tMax,
               QuadricHit* hit);

// Surface area in object-space units squared.
float area(const Quadric& q);

// Object-space axis-aligned bounds (conservative; pbrt-v3's boxes).
void bounds(const Quadric& q, Vec3* pMin, Vec3* pMax);

// A sampled surface point with its unit normal (same orientation as intersect()) and pdf.
struct QuadricSample {
    Vec3 p{0.f};
    Vec3 n{0.f};
    float pdf = 0;  // per unit area (sampleArea) or per steradian (sampleSolidAngle)
};

// Uniform point on the (partial) surface from u in [0,1)^2; pdf = 1/area (area measure).
// Returns false when the shape cannot be sampled (hyperboloid, zero area).
bool sampleArea(const Quadric& q, Vec2 u, QuadricSample* s);

// True when sampleSolidAngle/pdfSolidAngle use cone sampling from `ref` (object space): a
// full sphere and ref outside it by more than a relative 1e-4 of the radius squared. Points on
// the sphere itself (a path vertex on an emitting sphere, e.g. seen from inside) get area
// sampling: pbrt-v3 offsets the reference point towards the centre for the same reason; cone
// sampling from a point on the surface degenerates (measured: -7% radiance inside a closed
// emitting sphere).
bool usesSphereCone(const Quadric& q, const Vec3& ref);

// Point on the shape sampled as seen from `ref`, pdf per steradian of the direction
// ref -> p. Full spheres seen from outside (usesSphereCone) use pbrt-v3's cone sampling (uniform within the
// cone subtended by the sphere); otherwise the area sample is converted to solid angle.
// Returns false (pdf 0) when no valid sample exists.
bool sampleSolidAngle(const Quadric& q, const Vec3& ref, Vec2 u, QuadricSample* s);

// Solid-angle pdf (per steradian) with which sampleSolidAngle() picks direction `wi` (need
// not be normalised) from `ref`; 0 when the direction misses the shape.
float pdfSolidAngle(const Quadric& q, const Vec3& ref, const Vec3& wi);

}  // namespace rlpbrt
