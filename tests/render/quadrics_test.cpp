// Tests of the analytic quadrics: known ray answers, clipping, parametrisation, areas and the
// uniformity / normalisation of their sampling routines.
#include "render/quadrics.h"
#include "render/sampling.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace rlpbrt {
namespace {

constexpr float kEps = 1e-5f;

void expectVecNear(const Vec3& a, const Vec3& b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

// pbrt-v3's parametrisation p(u, v) of each shape, written independently of the library.
Vec3 pointFromUv(const Quadric& q, double u, double v) {
    double phi = u * q.phiMax, c = std::cos(phi), s = std::sin(phi), r = q.radius;
    switch (q.kind) {
    case Quadric::Kind::Sphere: {
        double theta = q.thetaZMin + v * (double(q.thetaZMax) - q.thetaZMin);
        return Vec3(float(r * std::sin(theta) * c), float(r * std::sin(theta) * s),
                    float(r * std::cos(theta)));
    }
    case Quadric::Kind::Disk: {
        double rho = (1 - v) * r + v * q.innerRadius;
        return Vec3(float(rho * c), float(rho * s), q.height);
    }
    case Quadric::Kind::Cylinder:
        return Vec3(float(r * c), float(r * s), float(q.zMin + v * (q.zMax - q.zMin)));
    case Quadric::Kind::Cone:
        return Vec3(float(r * (1 - v) * c), float(r * (1 - v) * s), float(v * q.height));
    case Quadric::Kind::Paraboloid: {
        double z = q.zMin + v * (q.zMax - q.zMin);
        double rho = r * std::sqrt(z / q.zMax);
        return Vec3(float(rho * c), float(rho * s), float(z));
    }
    case Quadric::Kind::Hyperboloid: {
        glm::dvec3 l = (1 - v) * glm::dvec3(q.p1) + v * glm::dvec3(q.p2);
        return Vec3(float(l.x * c - l.y * s), float(l.x * s + l.y * c), float(l.z));
    }
    }
    return Vec3(0.f);
}

std::vector<Quadric> allShapes() {
    return {makeSphere(1.5f),
            makeSphere(2.f, -1.f, 1.5f, 270.f),
            makeDisk(0.5f, 2.f, 0.f, 360.f),
            makeDisk(-0.25f, 1.f, 0.4f, 200.f),
            makeCylinder(1.2f, -0.5f, 1.f, 360.f),
            makeCylinder(1.f, -1.f, 1.f, 120.f),
            makeCone(2.f, 1.f, 360.f),
            makeCone(1.f, 0.7f, 300.f),
            makeParaboloid(1.f, 0.f, 1.f, 360.f),
            makeParaboloid(0.8f, 0.3f, 1.5f, 250.f),
            makeHyperboloid(Vec3(1, -1, -1), Vec3(1, 1, 1), 360.f),
            makeHyperboloid(Vec3(0.5f, 0, 0), Vec3(0.2f, 1, 2), 300.f)};
}

const char* kindName(const Quadric& q) {
    static const char* names[] = {"sphere", "disk", "cylinder", "cone", "paraboloid",
                                  "hyperboloid"};
    return names[int(q.kind)];
}

TEST(Quadrics, SphereKnownHits) {
    Quadric s = makeSphere(1.f);
    QuadricHit h;
    ASSERT_TRUE(intersect(s, Vec3(-5, 0, 0), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_NEAR(h.t, 4.f, kEps);
    expectVecNear(h.p, Vec3(-1, 0, 0), kEps);
    expectVecNear(h.n, Vec3(-1, 0, 0), kEps);
    EXPECT_NEAR(h.uv.x, 0.5f, kEps);  // phi = pi
    EXPECT_NEAR(h.uv.y, 0.5f, kEps);  // theta = pi/2 between thetaZMin = pi and thetaZMax = 0
    // Unnormalised direction: t is in units of |d|.
    ASSERT_TRUE(intersect(s, Vec3(-5, 0, 0), Vec3(2, 0, 0), 0.f, Infinity, &h));
    EXPECT_NEAR(h.t, 2.f, kEps);
    // From inside: the far side, normal still outward.
    ASSERT_TRUE(intersect(s, Vec3(0, 0, 0), Vec3(0, 1, 0), 0.f, Infinity, &h));
    EXPECT_NEAR(h.t, 1.f, kEps);
    expectVecNear(h.n, Vec3(0, 1, 0), kEps);
    EXPECT_FALSE(intersect(s, Vec3(-5, 1.01f, 0), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_FALSE(intersect(s, Vec3(-5, 0, 0), Vec3(1, 0, 0), 0.f, 3.9f, &h));
    EXPECT_FALSE(intersect(s, Vec3(-5, 0, 0), Vec3(-1, 0, 0), 0.f, Infinity, nullptr));
    // tMin skips the near hit.
    ASSERT_TRUE(intersect(s, Vec3(-5, 0, 0), Vec3(1, 0, 0), 4.5f, Infinity, &h));
    EXPECT_NEAR(h.t, 6.f, kEps);
    // Pole: finite normal and derivatives.
    ASSERT_TRUE(intersect(s, Vec3(0, 0, 5), Vec3(0, 0, -1), 0.f, Infinity, &h));
    EXPECT_TRUE(isFinite(h.n) && isFinite(h.dpdu) && isFinite(h.dpdv));
    EXPECT_GT(h.n.z, 0.999f);
}

TEST(Quadrics, SphereFarAwayIsPrecise) {
    // Double precision and refinement keep the hit on the surface despite a large t.
    Quadric s = makeSphere(0.01f);
    QuadricHit h;
    ASSERT_TRUE(intersect(s, Vec3(-1e4f, 0.003f, 0.002f), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_NEAR(glm::length(h.p), 0.01f, 1e-8f);
    EXPECT_LT(h.p.x, 0.f);
}

TEST(Quadrics, PartialSphereClipping) {
    Quadric s = makeSphere(1.f, -1.f, 1.f, 90.f);
    QuadricHit h;
    // Near hit at phi ~ pi is clipped; the far one at phi ~ 0.1 is kept.
    ASSERT_TRUE(intersect(s, Vec3(-5, 0.1f, 0), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_GT(h.p.x, 0.9f);
    EXPECT_NEAR(h.uv.x, std::atan2(0.1, std::sqrt(0.99)) / PiOver2, 1e-5);
    // Both hits clipped by phi.
    EXPECT_FALSE(intersect(s, Vec3(-5, -0.1f, 0), Vec3(1, 0, 0), 0.f, Infinity, &h));
    // z range.
    Quadric band = makeSphere(1.f, 0.5f, -0.5f, 360.f);  // swapped limits are sorted
    EXPECT_EQ(band.zMin, -0.5f);
    EXPECT_FALSE(intersect(band, Vec3(0.3f, 0, -5), Vec3(0, 0, 1), 0.f, Infinity, &h));
    ASSERT_TRUE(intersect(band, Vec3(-5, 0, 0.2f), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_LT(h.p.x, 0.f);
    ASSERT_TRUE(intersect(band, Vec3(-5, 0, 0.6f), Vec3(1, 0, 0), 0.f, Infinity, &h) == false);
    // v spans [0,1] over [zMin, zMax].
    ASSERT_TRUE(intersect(band, Vec3(0, -5, 0.5f - 1e-4f), Vec3(0, 1, 0), 0.f, Infinity, &h));
    EXPECT_NEAR(h.uv.y, 1.f, 1e-3f);
}

TEST(Quadrics, DiskAnnulusAndPhi) {
    Quadric d = makeDisk(0.5f, 1.f, 0.5f, 360.f);
    QuadricHit h;
    EXPECT_FALSE(intersect(d, Vec3(0.3f, 0, 2), Vec3(0, 0, -1), 0.f, Infinity, &h));
    EXPECT_FALSE(intersect(d, Vec3(1.1f, 0, 2), Vec3(0, 0, -1), 0.f, Infinity, &h));
    ASSERT_TRUE(intersect(d, Vec3(0.75f, 0, 2), Vec3(0, 0, -1), 0.f, Infinity, &h));
    EXPECT_NEAR(h.t, 1.5f, kEps);
    expectVecNear(h.n, Vec3(0, 0, 1), kEps);
    EXPECT_NEAR(h.uv.y, 0.5f, kEps);  // v = (radius - r) / (radius - innerRadius)
    EXPECT_FALSE(intersect(d, Vec3(0.75f, 0, 2), Vec3(1, 0, 0), 0.f, Infinity, &h));  // parallel
    EXPECT_FALSE(intersect(d, Vec3(0.75f, 0, 2), Vec3(0, 0, 1), 0.f, Infinity, &h));   // away
    Quadric half = makeDisk(0.f, 1.f, 0.f, 180.f);
    EXPECT_TRUE(intersect(half, Vec3(0.2f, 0.5f, 1), Vec3(0, 0, -1), 0.f, Infinity, &h));
    EXPECT_NEAR(h.uv.x, std::atan2(0.5, 0.2) / Pi, 1e-5);
    EXPECT_FALSE(intersect(half, Vec3(0.2f, -0.5f, 1), Vec3(0, 0, -1), 0.f, Infinity, &h));
    // Centre of a full disk: finite frame.
    Quadric full = makeDisk();
    ASSERT_TRUE(intersect(full, Vec3(0, 0, 1), Vec3(0, 0, -1), 0.f, Infinity, &h));
    EXPECT_TRUE(isFinite(h.dpdv));
    expectVecNear(h.n, Vec3(0, 0, 1), kEps);
}

TEST(Quadrics, CylinderConeParaboloidHyperboloidKnownHits) {
    QuadricHit h;
    Quadric cyl = makeCylinder(1.f, -1.f, 1.f, 360.f);
    ASSERT_TRUE(intersect(cyl, Vec3(-5, 0, 0.5f), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_NEAR(h.t, 4.f, kEps);
    expectVecNear(h.n, Vec3(-1, 0, 0), kEps);
    EXPECT_NEAR(h.uv.y, 0.75f, kEps);
    EXPECT_FALSE(intersect(cyl, Vec3(0.5f, 0, -5), Vec3(0, 0, 1), 0.f, Infinity, &h));
    EXPECT_FALSE(intersect(cyl, Vec3(-5, 0, 1.5f), Vec3(1, 0, 0), 0.f, Infinity, &h));
    // Oblique ray entering through the (open) top hits the inside wall.
    ASSERT_TRUE(intersect(cyl, Vec3(0, 0, 2), Vec3(1, 0, -1.5f), 0.f, Infinity, &h));
    EXPECT_NEAR(h.p.x, 1.f, kEps);
    EXPECT_NEAR(h.p.z, 0.5f, kEps);

    Quadric cone = makeCone(1.f, 1.f, 360.f);
    ASSERT_TRUE(intersect(cone, Vec3(-5, 0, 0.5f), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_NEAR(h.t, 4.5f, kEps);
    expectVecNear(h.n, glm::normalize(Vec3(-1, 0, 1)), kEps);
    EXPECT_NEAR(h.uv.y, 0.5f, kEps);
    EXPECT_FALSE(intersect(cone, Vec3(-5, 0, 1.5f), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_FALSE(intersect(cone, Vec3(-5, 0, -0.5f), Vec3(1, 0, 0), 0.f, Infinity, &h));

    Quadric par = makeParaboloid(1.f, 0.f, 1.f, 360.f);  // z = x^2 + y^2
    ASSERT_TRUE(intersect(par, Vec3(-5, 0, 0.25f), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_NEAR(h.t, 4.5f, kEps);
    expectVecNear(h.n, glm::normalize(Vec3(-1, 0, -1)), kEps);  // outside of the bowl
    ASSERT_TRUE(intersect(par, Vec3(0.5f, 0, 3), Vec3(0, 0, -1), 0.f, Infinity, &h));
    EXPECT_NEAR(h.p.z, 0.25f, kEps);  // a single (linear) root
    EXPECT_FALSE(intersect(par, Vec3(-5, 0, 1.2f), Vec3(1, 0, 0), 0.f, Infinity, &h));

    // A segment parallel to z sweeps a cylinder.
    Quadric hcyl = makeHyperboloid(Vec3(1, 0, -1), Vec3(1, 0, 1), 360.f);
    ASSERT_TRUE(intersect(hcyl, Vec3(-5, 0, 0.5f), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_NEAR(h.t, 4.f, kEps);
    EXPECT_NEAR(area(hcyl), 4 * Pi, 1e-4f);
    // x^2 + y^2 - z^2 = 1.
    Quadric hyp = makeHyperboloid(Vec3(1, -1, -1), Vec3(1, 1, 1), 360.f);
    ASSERT_TRUE(intersect(hyp, Vec3(-5, 0, 1), Vec3(1, 0, 0), 0.f, Infinity, &h));
    EXPECT_NEAR(h.t, 5 - std::sqrt(2.f), kEps);
    ASSERT_TRUE(intersect(hyp, Vec3(-5, 0, 0), Vec3(1, 0, 0), 0.f, Infinity, &h));
    expectVecNear(h.n, Vec3(-1, 0, 0), 1e-4f);
    EXPECT_FALSE(intersect(hyp, Vec3(-5, 0, 1.1f), Vec3(1, 0, 0), 0.f, Infinity, &h));
    Quadric flat = makeHyperboloid(Vec3(1, 0, 0), Vec3(2, 0, 0), 360.f);
    EXPECT_FALSE(intersect(flat, Vec3(1.5f, 0, 1), Vec3(0, 0, -1), 0.f, Infinity, &h));
}

TEST(Quadrics, HyperboloidAreaMatchesSurfaceOfRevolution) {
    // Area of x^2 + y^2 - z^2 = 1, |z| <= 1: 2 pi int sqrt(1 + 2 z^2) dz (midpoint rule).
    double sum = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        double z = -1 + 2 * (i + 0.5) / n;
        sum += std::sqrt(1 + 2 * z * z) * 2.0 / n;
    }
    EXPECT_NEAR(area(makeHyperboloid(Vec3(1, -1, -1), Vec3(1, 1, 1), 360.f)), 2 * Pi * sum,
                1e-4);
    EXPECT_NEAR(area(makeHyperboloid(Vec3(1, -1, -1), Vec3(1, 1, 1), 90.f)), Pi / 2 * sum,
                1e-4);
}

TEST(Quadrics, ClosedFormAreas) {
    EXPECT_NEAR(area(makeSphere(2.f)), 16 * Pi, 1e-4);
    EXPECT_NEAR(area(makeSphere(1.f, 0.f, 1.f, 180.f)), Pi, 1e-5);
    EXPECT_NEAR(area(makeDisk(0.f, 1.f, 0.5f, 360.f)), Pi * 0.75f, 1e-5);
    EXPECT_NEAR(area(makeCylinder(2.f, 0.f, 3.f, 360.f)), 12 * Pi, 1e-4);
    EXPECT_NEAR(area(makeCone(1.f, 1.f, 360.f)), Pi * std::sqrt(2.f), 1e-5);
}

// Random rays aimed at points near each shape: every hit satisfies pbrt-v3's parametrisation,
// unit normal = normalize(dpdu x dpdv), uv in [0,1], derivatives match finite differences,
// the hit lies on the ray and within the bounds, and no closer hit exists along the ray.
TEST(Quadrics, RandomRaysConsistentWithParametrisation) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> U(0.f, 1.f);
    for (const Quadric& q : allShapes()) {
        Vec3 lo, hi;
        bounds(q, &lo, &hi);
        int hits = 0;
        for (int i = 0; i < 2000; ++i) {
            Vec3 target = lo + Vec3(U(rng), U(rng), U(rng)) * (hi - lo);
            Vec3 o = 6.f * sampleUniformSphere(Vec2(U(rng), U(rng)));
            Vec3 d = target - o;
            QuadricHit h;
            const bool found = intersect(q, o, d, 0.f, Infinity, &h);
            // The occlusion query (no hit record; a full sphere skips the parametrisation)
            // answers as the full one.
            ASSERT_EQ(intersect(q, o, d, 0.f, Infinity, nullptr), found) << kindName(q);
            if (!found) continue;
            ++hits;
            SCOPED_TRACE(kindName(q));
            ASSERT_GE(h.uv.x, 0.f);
            ASSERT_LE(h.uv.x, 1.f);
            ASSERT_GE(h.uv.y, 0.f);
            ASSERT_LE(h.uv.y, 1.f);
            expectVecNear(h.p, o + h.t * d, 2e-4f);
            expectVecNear(h.p, pointFromUv(q, h.uv.x, h.uv.y), 2e-4f);
            for (int k = 0; k < 3; ++k) {
                EXPECT_GE(h.p[k], lo[k] - 1e-4f);
                EXPECT_LE(h.p[k], hi[k] + 1e-4f);
            }
            EXPECT_NEAR(glm::length(h.n), 1.f, 1e-5f);
            Vec3 nc = glm::normalize(glm::cross(h.dpdu, h.dpdv));
            expectVecNear(h.n, nc, 1e-4f);
            // Finite differences away from the parameter-domain boundary and the cone apex.
            double du = 1e-4, dv = 1e-4;
            if (h.uv.x > 0.01f && h.uv.x < 0.99f && h.uv.y > 0.01f && h.uv.y < 0.99f) {
                Vec3 fu = (pointFromUv(q, h.uv.x + du, h.uv.y) -
                           pointFromUv(q, h.uv.x - du, h.uv.y)) / float(2 * du);
                Vec3 fv = (pointFromUv(q, h.uv.x, h.uv.y + dv) -
                           pointFromUv(q, h.uv.x, h.uv.y - dv)) / float(2 * dv);
                float su = std::max(1.f, glm::length(fu)), sv = std::max(1.f, glm::length(fv));
                expectVecNear(h.dpdu / su, fu / su, 3e-2f);
                expectVecNear(h.dpdv / sv, fv / sv, 3e-2f);
            }
            // Nothing closer: a ray stopped just before the hit misses.
            EXPECT_FALSE(intersect(q, o, d, 0.f, h.t * 0.999f, nullptr));
        }
        EXPECT_GT(hits, 100) << kindName(q);
    }
}

// Reference area of a uv cell by integrating |dp/du x dp/dv| of pointFromUv numerically.
double cellArea(const Quadric& q, double u0, double u1, double v0, double v1) {
    const int m = 6;
    double sum = 0, hu = (u1 - u0) / m, hv = (v1 - v0) / m, e = 1e-5;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            double u = u0 + (i + 0.5) * hu, v = v0 + (j + 0.5) * hv;
            Vec3 fu = (pointFromUv(q, u + e, v) - pointFromUv(q, u - e, v)) / float(2 * e);
            Vec3 fv = (pointFromUv(q, u, v + e) - pointFromUv(q, u, v - e)) / float(2 * e);
            sum += glm::length(glm::cross(fu, fv)) * hu * hv;
        }
    return sum;
}

// Area sampling is uniform: chi-square of sample counts over an 8x8 grid of uv cells against
// counts proportional to the cells' (independently integrated) areas; sampled normals agree
// with intersect(). Chi-square with 63 dof has mean 63 and sd sqrt(126) ~ 11.2; the bound
// 63 + 5 sd = 119 fails a correct sampler with probability < 1e-5 (fixed seed anyway).
TEST(Quadrics, AreaSamplingIsUniform) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> U(0.f, 1.f);
    const int g = 8, n = 40000;
    for (const Quadric& q : allShapes()) {
        SCOPED_TRACE(kindName(q));
        std::vector<double> expected(g * g);
        double total = 0;
        for (int i = 0; i < g; ++i)
            for (int j = 0; j < g; ++j)
                total += expected[i * g + j] =
                    cellArea(q, double(i) / g, double(i + 1) / g, double(j) / g,
                             double(j + 1) / g);
        EXPECT_NEAR(total, area(q), 2e-3 * area(q));
        QuadricSample s;
        if (q.kind == Quadric::Kind::Hyperboloid) {
            EXPECT_FALSE(sampleArea(q, Vec2(0.5f), &s));
            continue;
        }
        std::vector<int> counts(g * g, 0);
        for (int k = 0; k < n; ++k) {
            ASSERT_TRUE(sampleArea(q, Vec2(U(rng), U(rng)), &s));
            ASSERT_NEAR(s.pdf, 1 / area(q), 1e-6f / area(q));
            // Find uv by shooting a short ray at the sample along -n.
            QuadricHit h;
            ASSERT_TRUE(intersect(q, s.p + 1e-3f * s.n, -s.n, 0.f, 2e-3f, &h));
            expectVecNear(h.p, s.p, 1e-4f);
            expectVecNear(h.n, s.n, 1e-3f);
            int i = std::min(g - 1, int(h.uv.x * g)), j = std::min(g - 1, int(h.uv.y * g));
            ++counts[i * g + j];
        }
        double chi2 = 0;
        for (int c = 0; c < g * g; ++c) {
            double e = n * expected[c] / total;
            chi2 += (counts[c] - e) * (counts[c] - e) / e;
        }
        EXPECT_LT(chi2, 119.0);
    }
}

// Mean and standard error of a sample.
void meanAndError(const std::vector<double>& x, double* mean, double* err) {
    double s = 0, s2 = 0;
    for (double v : x) {
        s += v;
        s2 += v * v;
    }
    *mean = s / x.size();
    double var = std::max(0.0, s2 / x.size() - *mean * *mean);
    *err = std::sqrt(var / x.size());
}

TEST(Quadrics, SphereConeSampling) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> U(0.f, 1.f);
    Quadric s = makeSphere(1.f);
    Vec3 ref(0.5f, -1.f, 2.5f);
    float dc = glm::length(ref);
    double cosMax = std::sqrt(1.0 - 1.0 / (dc * dc));
    double omega = 2 * Pi * (1 - cosMax);
    const int n = 20000, bins = 10;
    std::vector<int> counts(bins, 0);
    Vec3 axis = -ref / dc;
    for (int k = 0; k < n; ++k) {
        QuadricSample qs;
        ASSERT_TRUE(sampleSolidAngle(s, ref, Vec2(U(rng), U(rng)), &qs));
        EXPECT_NEAR(glm::length(qs.p), 1.f, 1e-5f);
        expectVecNear(qs.n, qs.p, 1e-5f);
        Vec3 wi = glm::normalize(qs.p - ref);
        EXPECT_LE(glm::dot(qs.n, wi), 1e-4f);  // visible side
        EXPECT_NEAR(qs.pdf, 1 / omega, 1e-4 / omega);  // constant, E[1/pdf] = omega
        EXPECT_NEAR(pdfSolidAngle(s, ref, qs.p - ref), qs.pdf, 1e-4 / omega);
        // The sampled point is the first hit along wi.
        QuadricHit h;
        ASSERT_TRUE(intersect(s, ref, wi, 0.f, Infinity, &h));
        expectVecNear(h.p, qs.p, 2e-3f);
        // cos(theta) about the axis is uniform on [cosMax, 1].
        double c = glm::dot(wi, axis);
        int b = std::min(bins - 1, std::max(0, int((c - cosMax) / (1 - cosMax) * bins)));
        ++counts[b];
    }
    // Chi-square with 9 dof: mean 9, sd sqrt(18) ~ 4.2; bound 9 + 6 sd.
    double chi2 = 0, e = double(n) / bins;
    for (int c : counts) chi2 += (c - e) * (c - e) / e;
    EXPECT_LT(chi2, 35.0);
    EXPECT_EQ(pdfSolidAngle(s, ref, -ref + Vec3(0, 3, 0)), 0.f);
}

// The solid-angle pdf integrates to one over the sphere of directions: E[4 pi pdf(w)] = 1
// for uniform w, within 5 standard errors estimated from the samples. Checked for a sphere
// seen from outside and inside and for area-sampled shapes (converted to solid angle); also
// E[1/pdf] over sampled directions = subtended solid angle (4 pi from inside the sphere).
TEST(Quadrics, SolidAnglePdfsIntegrateToOne) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> U(0.f, 1.f);
    struct Case { Quadric q; Vec3 ref; };
    std::vector<Case> cases = {{makeSphere(1.f), Vec3(0, 0, 3)},
                               {makeSphere(1.f), Vec3(0.2f, 0.3f, -0.4f)},
                               {makeDisk(0.f, 1.f, 0.3f, 270.f), Vec3(0.2f, 0.1f, 0.8f)},
                               {makeCylinder(1.f, 0.f, 1.f, 360.f), Vec3(0, 0, 0.5f)}};
    const int n = 200000;
    for (const Case& c : cases) {
        SCOPED_TRACE(kindName(c.q));
        std::vector<double> x(n);
        for (int k = 0; k < n; ++k)
            x[k] = 4 * Pi * pdfSolidAngle(c.q, c.ref, sampleUniformSphere(Vec2(U(rng), U(rng))));
        double mean, err;
        meanAndError(x, &mean, &err);
        EXPECT_NEAR(mean, 1.0, 5 * err + 1e-6);
        EXPECT_GT(err, 0.0);
    }
    // Inside the sphere: E[1/pdf] = 4 pi.
    std::vector<double> inv(n);
    Quadric s = makeSphere(1.f);
    for (int k = 0; k < n; ++k) {
        QuadricSample qs;
        ASSERT_TRUE(sampleSolidAngle(s, Vec3(0.2f, 0.3f, -0.4f), Vec2(U(rng), U(rng)), &qs));
        inv[k] = 1 / qs.pdf;
    }
    double mean, err;
    meanAndError(inv, &mean, &err);
    EXPECT_NEAR(mean, 4 * Pi, 5 * err);
}

TEST(Quadrics, BoundsContainShapes) {
    Vec3 lo, hi;
    bounds(makeSphere(2.f, -1.f, 1.5f, 90.f), &lo, &hi);
    expectVecNear(lo, Vec3(-2, -2, -1), 0.f);
    expectVecNear(hi, Vec3(2, 2, 1.5f), 0.f);
    bounds(makeDisk(0.5f, 2.f, 0.f, 360.f), &lo, &hi);
    EXPECT_EQ(lo.z, 0.5f);
    EXPECT_EQ(hi.z, 0.5f);
    bounds(makeCone(2.f, 1.f, 360.f), &lo, &hi);
    expectVecNear(hi, Vec3(1, 1, 2), 0.f);
    bounds(makeHyperboloid(Vec3(1, -1, -1), Vec3(1, 1, 1), 360.f), &lo, &hi);
    EXPECT_NEAR(hi.x, std::sqrt(2.f), 1e-6f);
}

}  // namespace
}  // namespace rlpbrt
