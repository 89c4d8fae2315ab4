// NURBS evaluation and pbrt-v3's tessellation (render/nurbs.*) against surfaces known in
// closed form: a bilinear patch, a cubic Bezier patch (Bernstein polynomials), a rational
// quadratic quarter cylinder (exactly on the circle), and a spline with interior knots
// (partition of unity, derivatives against finite differences).
#include <gtest/gtest.h>

#include <random>

#include "render/nurbs.h"

namespace rlpbrt {
namespace {

void expectNear(const Vec3& a, const Vec3& b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

NurbsPatch bilinear() {
    NurbsPatch s;
    s.nu = s.nv = 2;
    s.uOrder = s.vOrder = 2;
    s.uKnots = s.vKnots = {0, 0, 1, 1};
    s.cp = {{0, 0, 0, 1}, {2, 0, 1, 1}, {0, 3, 0, 1}, {2, 3, 5, 1}};
    return s;
}

TEST(Nurbs, BilinearPatchIsBilinearInterpolation) {
    NurbsPatch s = bilinear();
    ASSERT_TRUE(validateNurbs(s, nullptr));
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> U(0.f, 1.f);
    for (int k = 0; k < 100; ++k) {
        float u = U(rng), v = U(rng);
        Vec3 dpdu, dpdv;
        Vec3 p = evaluateNurbs(s, u, v, &dpdu, &dpdv);
        // P(u, v) = (2u, 3v, u + 4uv).
        Vec3 want((1 - u) * (1 - v) * Vec3(0, 0, 0) + u * (1 - v) * Vec3(2, 0, 1) +
                  (1 - u) * v * Vec3(0, 3, 0) + u * v * Vec3(2, 3, 5));
        expectNear(p, want, 1e-5f);
        expectNear(dpdu, Vec3(2, 0, (1 - v) * 1 + v * 5), 1e-4f);
        expectNear(dpdv, Vec3(0, 3, u * 5 - u * 1), 1e-4f);
    }
}

float bernstein3(int i, float t) {
    const float c[4] = {1, 3, 3, 1};
    return c[i] * std::pow(t, float(i)) * std::pow(1.f - t, float(3 - i));
}

TEST(Nurbs, ClampedCubicIsBezierPatch) {
    NurbsPatch s;
    s.nu = s.nv = 4;
    s.uOrder = s.vOrder = 4;
    s.uKnots = s.vKnots = {0, 0, 0, 0, 1, 1, 1, 1};
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> U(-2.f, 2.f);
    for (int i = 0; i < 16; ++i) s.cp.emplace_back(U(rng), U(rng), U(rng), 1.f);
    ASSERT_TRUE(validateNurbs(s, nullptr));
    for (float u : {0.f, 0.2f, 0.5f, 0.93f, 1.f})
        for (float v : {0.f, 0.37f, 0.8f, 1.f}) {
            Vec3 want(0.f);
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i)
                    want += bernstein3(i, u) * bernstein3(j, v) * Vec3(s.cp[size_t(j * 4 + i)]);
            expectNear(evaluateNurbs(s, u, v), want, 1e-5f);
        }
}

// A quadratic rational arc with weights 1, sqrt(2)/2, 1 is exactly a quarter circle; extruded
// linearly along z it is a quarter cylinder of radius 1. Pw holds (w x, w y, w z, w).
NurbsPatch quarterCylinder() {
    NurbsPatch s;
    s.nu = 3;
    s.nv = 2;
    s.uOrder = 3;
    s.vOrder = 2;
    s.uKnots = {0, 0, 0, 1, 1, 1};
    s.vKnots = {0, 0, 1, 1};
    const float w = std::sqrt(0.5f);
    for (float z : {0.f, 2.f}) {
        s.cp.emplace_back(1, 0, z, 1);
        s.cp.emplace_back(w, w, w * z, w);
        s.cp.emplace_back(0, 1, z, 1);
    }
    return s;
}

TEST(Nurbs, RationalQuarterCylinderLiesOnTheCircle) {
    NurbsPatch s = quarterCylinder();
    ASSERT_TRUE(validateNurbs(s, nullptr));
    std::vector<Vec3> p, n;
    std::vector<Vec2> uv;
    std::vector<uint32_t> idx;
    tessellateNurbs(s, &p, &n, &uv, &idx);
    ASSERT_EQ(p.size(), size_t(kNurbsDice * kNurbsDice));
    for (size_t i = 0; i < p.size(); ++i) {
        EXPECT_NEAR(std::hypot(p[i].x, p[i].y), 1.f, 1e-5f);
        EXPECT_GE(p[i].x, -1e-6f);
        EXPECT_GE(p[i].y, -1e-6f);
        EXPECT_NEAR(p[i].z, 2.f * uv[i].y, 1e-5f);  // linear in v
        // The normal is radial: dP/du (along the arc) x dP/dv (+z) points outwards.
        expectNear(n[i], Vec3(p[i].x, p[i].y, 0.f), 1e-4f);
    }
    // The arc's ends and its middle (u = 1/2 is at 45 degrees by symmetry).
    expectNear(evaluateNurbs(s, 0.f, 0.f), Vec3(1, 0, 0), 1e-6f);
    expectNear(evaluateNurbs(s, 1.f, 1.f), Vec3(0, 1, 2), 1e-6f);
    expectNear(evaluateNurbs(s, 0.5f, 0.5f), Vec3(std::sqrt(0.5f), std::sqrt(0.5f), 1), 1e-6f);
}

// Interior knots (a non-uniform cubic in u, quadratic in v): the basis is a partition of unity
// (equal control points give that point and zero derivatives), and the derivatives of a
// rational surface agree with central differences.
TEST(Nurbs, InteriorKnotsPartitionOfUnityAndDerivatives) {
    NurbsPatch s;
    s.nu = 6;
    s.nv = 4;
    s.uOrder = 4;
    s.vOrder = 3;
    s.uKnots = {0, 0, 0, 0, 0.3f, 0.7f, 1, 1, 1, 1};
    s.vKnots = {0, 0, 0, 0.5f, 2, 2, 2};
    s.cp.assign(24, glm::vec4(1.5f, -2.f, 0.25f, 1.f));
    ASSERT_TRUE(validateNurbs(s, nullptr));
    Vec3 du, dv;
    expectNear(evaluateNurbs(s, 0.45f, 1.3f, &du, &dv), Vec3(1.5f, -2.f, 0.25f), 1e-5f);
    expectNear(du, Vec3(0.f), 1e-4f);
    expectNear(dv, Vec3(0.f), 1e-4f);

    std::mt19937 rng(3);
    std::uniform_real_distribution<float> U(-1.f, 1.f), W(0.5f, 2.f);
    for (auto& c : s.cp) {
        float w = W(rng);
        c = glm::vec4(w * U(rng), w * U(rng), w * U(rng), w);
    }
    const double h = 1e-3;
    for (float u : {0.1f, 0.3f, 0.5f, 0.85f})
        for (float v : {0.2f, 0.5f, 1.4f}) {
            evaluateNurbs(s, u, v, &du, &dv);
            Vec3 fu = (evaluateNurbs(s, u + float(h), v) - evaluateNurbs(s, u - float(h), v)) /
                      float(2 * h);
            Vec3 fv = (evaluateNurbs(s, u, v + float(h)) - evaluateNurbs(s, u, v - float(h))) /
                      float(2 * h);
            // u = 0.3 is a knot (C2 for a cubic: the central difference still holds).
            expectNear(du, fu, 2e-2f);
            expectNear(dv, fv, 2e-2f);
        }
}

TEST(Nurbs, TessellationIsPbrtV3sGrid) {
    NurbsPatch s = bilinear();
    s.u0 = 0.25f;
    s.u1 = 0.75f;
    s.v0 = 0.f;
    s.v1 = 0.5f;
    std::vector<Vec3> p, n;
    std::vector<Vec2> uv;
    std::vector<uint32_t> idx;
    tessellateNurbs(s, &p, &n, &uv, &idx);
    const int d = kNurbsDice;
    ASSERT_EQ(d, 30);
    ASSERT_EQ(p.size(), size_t(d * d));
    ASSERT_EQ(idx.size(), size_t(6 * (d - 1) * (d - 1)));
    EXPECT_EQ(uv.front(), Vec2(0.25f, 0.f));
    EXPECT_EQ(uv.back(), Vec2(0.75f, 0.5f));
    EXPECT_NEAR(uv[1].x, 0.25f + 0.5f / 29.f, 1e-6f);
    // First cell: (u, v), (u+1, v), (u+1, v+1) and (u, v), (u+1, v+1), (u, v+1).
    EXPECT_EQ(std::vector<uint32_t>(idx.begin(), idx.begin() + 6),
              (std::vector<uint32_t>{0, 1, 31, 0, 31, 30}));
    for (const Vec3& v : n) EXPECT_NEAR(glm::length(v), 1.f, 1e-5f);
    // The geometric normal of the first triangle agrees with the shading normals' side.
    Vec3 ng = glm::cross(p[1] - p[0], p[31] - p[0]);
    EXPECT_GT(glm::dot(ng, n[0]), 0.f);
}

TEST(Nurbs, ValidationNamesTheProblem) {
    std::string err;
    NurbsPatch s = bilinear();
    s.uKnots.pop_back();
    EXPECT_FALSE(validateNurbs(s, &err));
    EXPECT_NE(err.find("u knot vector"), std::string::npos) << err;
    s = bilinear();
    s.cp.pop_back();
    EXPECT_FALSE(validateNurbs(s, &err));
    EXPECT_NE(err.find("control points"), std::string::npos) << err;
    s = bilinear();
    s.vKnots = {0, 1, 0.5f, 1};
    EXPECT_FALSE(validateNurbs(s, &err));
    EXPECT_NE(err.find("decrease"), std::string::npos) << err;
    s = bilinear();
    s.u1 = 2.f;
    EXPECT_FALSE(validateNurbs(s, &err));
    s = bilinear();
    s.uOrder = 1;
    EXPECT_FALSE(validateNurbs(s, &err));
}

}  // namespace
}  // namespace rlpbrt
