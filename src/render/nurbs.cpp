#include "render/nurbs.h"

#include <cmath>

namespace rlpbrt {

namespace {

constexpr int kMaxOrder = 16;

// The knot span of t: the first index k >= order - 1 with t <= knots[k + 1] (pbrt-v3's choice
// at interior knots), at most n - 1.
int findSpan(const std::vector<float>& knots, int order, int n, float t) {
    int k = order - 1;
    while (k < n - 1 && t > knots[size_t(k) + 1]) ++k;
    return k;
}

// The order nonzero B-spline basis functions of degree order - 1 at t in span `span`
// (functions span - order + 1 .. span) in N, their derivatives in dN. Cox-de Boor recursion
// over increasing degree; a zero-length knot interval contributes 0.
void basisFunctions(const std::vector<float>& knots, int order, int span, float t, float* N,
                    float* dN) {
    const int p = order - 1;
    float prev[kMaxOrder] = {1.f};  // degree d - 1, functions span - (d - 1) .. span
    float cur[kMaxOrder];
    auto ratio = [](float num, float den) { return den != 0.f ? num / den : 0.f; };
    for (int d = 1; d <= p; ++d) {
        for (int k = 0; k <= d; ++k) {
            int i = span - d + k;  // function index
            float left = k > 0 ? prev[k - 1] : 0.f;  // N_{i, d-1}
            float right = k < d ? prev[k] : 0.f;     // N_{i+1, d-1}
            float a = ratio(t - knots[i], knots[i + d] - knots[i]);
            float b = ratio(knots[i + d + 1] - t, knots[i + d + 1] - knots[i + 1]);
            cur[k] = a * left + b * right;
        }
        if (d == p) {
            // N'_{i,p} = p N_{i,p-1} / (u_{i+p} - u_i) - p N_{i+1,p-1} / (u_{i+p+1} - u_{i+1})
            for (int k = 0; k <= p; ++k) {
                int i = span - p + k;
                float left = k > 0 ? prev[k - 1] : 0.f;
                float right = k < p ? prev[k] : 0.f;
                dN[k] = p * (ratio(left, knots[i + p] - knots[i]) -
                             ratio(right, knots[i + p + 1] - knots[i + 1]));
            }
        }
        for (int k = 0; k <= d; ++k) prev[k] = cur[k];
    }
    if (p == 0) dN[0] = 0.f;
    for (int k = 0; k <= p; ++k) N[k] = prev[k];
}

}  // namespace

bool validateNurbs(const NurbsPatch& s, std::string* error) {
    auto fail = [&](const std::string& m) {
        if (error) *error = m;
        return false;
    };
    if (s.uOrder < 2 || s.vOrder < 2 || s.uOrder > kMaxOrder || s.vOrder > kMaxOrder)
        return fail("\"uorder\" and \"vorder\" must be in 2.." + std::to_string(kMaxOrder));
    if (s.nu < s.uOrder || s.nv < s.vOrder)
        return fail("\"nu\" and \"nv\" must be at least the order in their direction");
    if (s.uKnots.size() != size_t(s.nu + s.uOrder))
        return fail("the u knot vector has " + std::to_string(s.uKnots.size()) +
                    " values; nu + uorder = " + std::to_string(s.nu + s.uOrder));
    if (s.vKnots.size() != size_t(s.nv + s.vOrder))
        return fail("the v knot vector has " + std::to_string(s.vKnots.size()) +
                    " values; nv + vorder = " + std::to_string(s.nv + s.vOrder));
    for (const auto* k : {&s.uKnots, &s.vKnots})
        for (size_t i = 0; i < k->size(); ++i) {
            if (!std::isfinite((*k)[i])) return fail("a knot value is not finite");
            if (i > 0 && (*k)[i] < (*k)[i - 1]) return fail("knot vectors must not decrease");
        }
    if (s.cp.size() != size_t(s.nu) * size_t(s.nv))
        return fail("expected " + std::to_string(s.nu) + "x" + std::to_string(s.nv) + "=" +
                    std::to_string(s.nu * s.nv) + " control points, got " +
                    std::to_string(s.cp.size()));
    auto inRange = [](float a, float b, float lo, float hi) {
        return std::isfinite(a) && std::isfinite(b) && a >= lo && b <= hi && a < b;
    };
    if (!inRange(s.u0, s.u1, s.uKnots[size_t(s.uOrder) - 1], s.uKnots[size_t(s.nu)]) ||
        !inRange(s.v0, s.v1, s.vKnots[size_t(s.vOrder) - 1], s.vKnots[size_t(s.nv)]))
        return fail("u0 < u1 and v0 < v1 must lie in the knot vectors' valid range");
    return true;
}

Vec3 evaluateNurbs(const NurbsPatch& s, float u, float v, Vec3* dpdu, Vec3* dpdv) {
    float Nu[kMaxOrder], dNu[kMaxOrder], Nv[kMaxOrder], dNv[kMaxOrder];
    int su = findSpan(s.uKnots, s.uOrder, s.nu, u), sv = findSpan(s.vKnots, s.vOrder, s.nv, v);
    basisFunctions(s.uKnots, s.uOrder, su, u, Nu, dNu);
    basisFunctions(s.vKnots, s.vOrder, sv, v, Nv, dNv);
    glm::vec4 S(0.f), Su(0.f), Sv(0.f);  // homogeneous value and derivatives
    for (int j = 0; j < s.vOrder; ++j) {
        int row = sv - s.vOrder + 1 + j;
        for (int i = 0; i < s.uOrder; ++i) {
            const glm::vec4& c = s.cp[size_t(row) * s.nu + size_t(su - s.uOrder + 1 + i)];
            S += Nu[i] * Nv[j] * c;
            Su += dNu[i] * Nv[j] * c;
            Sv += Nu[i] * dNv[j] * c;
        }
    }
    Vec3 P = Vec3(S) / S.w;
    // d(x / w) = (dx - P dw) / w
    if (dpdu) *dpdu = (Vec3(Su) - P * Su.w) / S.w;
    if (dpdv) *dpdv = (Vec3(Sv) - P * Sv.w) / S.w;
    return P;
}

void tessellateNurbs(const NurbsPatch& s, std::vector<Vec3>* p, std::vector<Vec3>* n,
                     std::vector<Vec2>* uv, std::vector<uint32_t>* indices) {
    const int d = kNurbsDice;
    p->clear();
    n->clear();
    uv->clear();
    indices->clear();
    for (int j = 0; j < d; ++j) {
        float t = float(j) / float(d - 1);
        float v = (1.f - t) * s.v0 + t * s.v1;
        for (int i = 0; i < d; ++i) {
            float r = float(i) / float(d - 1);
            float u = (1.f - r) * s.u0 + r * s.u1;
            Vec3 dpdu, dpdv;
            p->push_back(evaluateNurbs(s, u, v, &dpdu, &dpdv));
            Vec3 c = glm::cross(dpdu, dpdv);
            float len = glm::length(c);
            n->push_back(len > 0.f && std::isfinite(len) ? c / len : Vec3(0.f));
            uv->emplace_back(u, v);
        }
    }
    for (int j = 0; j + 1 < d; ++j)
        for (int i = 0; i + 1 < d; ++i) {
            uint32_t a = uint32_t(j * d + i), b = a + 1, c = a + uint32_t(d) + 1,
                     e = a + uint32_t(d);
            indices->insert(indices->end(), {a, b, c, a, c, e});
        }
}

}  // namespace rlpbrt
