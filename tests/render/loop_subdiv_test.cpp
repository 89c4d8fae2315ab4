// Tests of Loop subdivision: face counts, closedness, normal orientation, planarity,
// boundary behaviour, pbrt-v3's limit masks, input errors and the killeroo scene mesh.
#include "render/loop_subdiv.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include "shared_data.h"

namespace rlpbrt {
namespace {

struct Result {
    std::vector<Vec3> p, n;
    std::vector<int> idx;
};

Result subdivide(int levels, const std::vector<int>& idx, const std::vector<Vec3>& p) {
    Result r;
    std::string err;
    EXPECT_TRUE(loopSubdivide(levels, idx, p, &r.p, &r.n, &r.idx, &err)) << err;
    return r;
}

std::string failure(int levels, const std::vector<int>& idx, const std::vector<Vec3>& p) {
    Result r;
    std::string err;
    EXPECT_FALSE(loopSubdivide(levels, idx, p, &r.p, &r.n, &r.idx, &err));
    return err;
}

// Every directed edge occurs once and its reverse occurs once: closed, oriented 2-manifold.
void expectClosed(const std::vector<int>& idx) {
    std::map<std::pair<int, int>, int> count;
    for (size_t f = 0; f < idx.size(); f += 3)
        for (int k = 0; k < 3; ++k) ++count[{idx[f + k], idx[f + (k + 1) % 3]}];
    for (const auto& [e, c] : count) {
        EXPECT_EQ(c, 1);
        auto it = count.find({e.second, e.first});
        ASSERT_TRUE(it != count.end()) << "open edge " << e.first << "-" << e.second;
        EXPECT_EQ(it->second, 1);
    }
}

Vec3 faceNormal(const Result& r, size_t f) {
    const Vec3& a = r.p[size_t(r.idx[f])];
    return glm::cross(r.p[size_t(r.idx[f + 1])] - a, r.p[size_t(r.idx[f + 2])] - a);
}

// Vertex normals are unit and agree with the winding of every incident face.
void expectNormalsFollowWinding(const Result& r) {
    ASSERT_EQ(r.n.size(), r.p.size());
    for (const Vec3& n : r.n) EXPECT_NEAR(glm::length(n), 1.f, 1e-5f);
    for (size_t f = 0; f < r.idx.size(); f += 3) {
        Vec3 fn = glm::normalize(faceNormal(r, f));
        for (int k = 0; k < 3; ++k) EXPECT_GT(glm::dot(fn, r.n[size_t(r.idx[f + k])]), 0.2f);
    }
}

const std::vector<Vec3> kTetP = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
const std::vector<int> kTetIdx = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};  // outward (CCW)

const std::vector<Vec3> kOctP = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                 {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
const std::vector<int> kOctIdx = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4,
                                  2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};

TEST(LoopSubdiv, ClosedTetrahedronAndOctahedron) {
    for (int levels = 0; levels <= 3; ++levels) {
        for (auto* mesh : {&kTetIdx, &kOctIdx}) {
            const auto& P = mesh == &kTetIdx ? kTetP : kOctP;
            Result r = subdivide(levels, *mesh, P);
            size_t faces = mesh->size() / 3 * (size_t(1) << (2 * levels));
            ASSERT_EQ(r.idx.size(), 3 * faces);
            // Euler characteristic 2: V = F/2 + 2 for a closed triangle mesh of genus 0.
            EXPECT_EQ(r.p.size(), faces / 2 + 2);
            expectClosed(r.idx);
            expectNormalsFollowWinding(r);
            for (size_t v = 0; v < r.p.size(); ++v) {
                EXPECT_GT(glm::dot(r.n[v], r.p[v]), 0.f);  // outward (centred at the origin)
                EXPECT_LT(glm::length(r.p[v]), glm::length(P[0]) + 1e-5f);  // shrinks
            }
            double vol = 0;
            for (size_t f = 0; f < r.idx.size(); f += 3)
                vol += glm::dot(r.p[size_t(r.idx[f])], faceNormal(r, f)) / 6;
            EXPECT_GT(vol, 0.0);
        }
    }
}

TEST(LoopSubdiv, OctahedronSymmetryAndLimitMask) {
    // nlevels 0: only the limit mask. Valence 4: gamma = 1 / (4 + 3/(8 * 3/32)) = 1/8;
    // p = (1 - 4/8) * (1,0,0) + 1/8 * (sum of the 4 ring vertices = 0) = (1/2, 0, 0).
    Result r0 = subdivide(0, kOctIdx, kOctP);
    ASSERT_EQ(r0.p.size(), 6u);
    EXPECT_NEAR(r0.p[0].x, 0.5f, 1e-6f);
    EXPECT_NEAR(r0.n[0].x, 1.f, 1e-6f);
    // Tetrahedron, valence 3: beta = 3/16, gamma = 1 / (3 + 3/(8 * 3/16)) = 1/5;
    // p = (1 - 3/5) * (1,1,1) + 1/5 * (-1,-1,-1) = (0.2, 0.2, 0.2).
    Result t0 = subdivide(0, kTetIdx, kTetP);
    EXPECT_NEAR(glm::length(t0.p[0] - Vec3(0.2f)), 0.f, 1e-6f);
    // Interior limit masks are exact, so the original vertices' limit points do not depend
    // on the number of levels (checks the even and odd rules against the limit mask).
    for (int levels = 1; levels <= 3; ++levels) {
        Result rl = subdivide(levels, kOctIdx, kOctP);
        Result tl = subdivide(levels, kTetIdx, kTetP);
        for (size_t v = 0; v < 6; ++v)
            EXPECT_NEAR(glm::length(rl.p[v] - r0.p[v]), 0.f, 1e-6f) << levels;
        for (size_t v = 0; v < 4; ++v)
            EXPECT_NEAR(glm::length(tl.p[v] - t0.p[v]), 0.f, 1e-6f) << levels;
    }
    // After 3 levels the original vertices stay on their axes.
    Result r = subdivide(3, kOctIdx, kOctP);
    for (int v = 0; v < 6; ++v) {
        int axis = v / 2;
        for (int k = 0; k < 3; ++k)
            if (k != axis) {
                EXPECT_NEAR(r.p[size_t(v)][k], 0.f, 1e-6f);
            }
        EXPECT_NEAR(std::abs(r.n[size_t(v)][axis]), 1.f, 1e-5f);
    }
    // All limit points lie between the inscribed sphere of the octahedron and the vertices.
    for (const Vec3& p : r.p) {
        EXPECT_GT(glm::length(p), 0.4f);
        EXPECT_LT(glm::length(p), 1.f);
    }
}

// An n x n grid of quads in z = 0, split into triangles wound counter-clockwise.
void makeGrid(int n, std::vector<Vec3>* P, std::vector<int>* idx) {
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) P->push_back(Vec3(float(i), float(j), 0.f));
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            int a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
            idx->insert(idx->end(), {a, b, c, a, c, d});
        }
}

TEST(LoopSubdiv, FlatGridStaysPlanar) {
    std::vector<Vec3> P;
    std::vector<int> idx;
    makeGrid(4, &P, &idx);
    Result r = subdivide(2, idx, P);
    EXPECT_EQ(r.idx.size(), idx.size() * 16);
    for (size_t v = 0; v < r.p.size(); ++v) {
        EXPECT_EQ(r.p[v].z, 0.f);
        EXPECT_NEAR(r.n[v].z, 1.f, 1e-6f) << v;
        EXPECT_GE(r.p[v].x, 0.f);
        EXPECT_LE(r.p[v].x, 4.f);
    }
    // Interior vertices of a regular flat grid subdivide affinely: the original centre
    // vertex (2,2) stays put.
    EXPECT_NEAR(r.p[12].x, 2.f, 1e-6f);
    EXPECT_NEAR(r.p[12].y, 2.f, 1e-6f);
    expectNormalsFollowWinding(r);
}

// A hexagonal "hat": boundary ring on the unit circle at z = 0 and an apex at z = 1.
TEST(LoopSubdiv, OpenMeshBoundaryStaysOnBoundaryCurve) {
    std::vector<Vec3> P = {Vec3(0, 0, 1)};
    std::vector<int> idx;
    for (int k = 0; k < 6; ++k) {
        float a = 2 * Pi * k / 6;
        P.push_back(Vec3(std::cos(a), std::sin(a), 0.f));
        idx.insert(idx.end(), {0, 1 + k, 1 + (k + 1) % 6});
    }
    // nlevels 0: pbrt-v3's limit masks. Boundary: 0.6 v + 0.2 (neighbours);
    // interior valence 6: gamma = 1 / (6 + 3/(8/16)) = 1/12, so the apex goes to
    // (1 - 6/12) * 1 = 1/2.
    Result r0 = subdivide(0, idx, P);
    EXPECT_NEAR(r0.p[0].z, 0.5f, 1e-6f);
    Vec3 expect = 0.6f * P[1] + 0.2f * (P[2] + P[6]);
    EXPECT_NEAR(glm::length(r0.p[1] - expect), 0.f, 1e-6f);
    EXPECT_NEAR(r0.n[0].z, 1.f, 1e-6f);

    // Level 1, original boundary vertex: even rule v' = 3/4 v + 1/8 (n1 + n2), boundary
    // neighbours are the midpoints (v + n)/2, then the limit mask 0.6 / 0.2.
    Result r1 = subdivide(1, idx, P);
    Vec3 even = 0.75f * P[1] + 0.125f * (P[2] + P[6]);
    Vec3 lim1 = 0.6f * even + 0.1f * (P[1] + P[2]) + 0.1f * (P[1] + P[6]);
    EXPECT_NEAR(glm::length(r1.p[1] - lim1), 0.f, 1e-6f);
    // Interior limit masks are exact: the apex's limit point does not depend on the level.
    for (int levels = 1; levels <= 3; ++levels)
        EXPECT_NEAR(glm::length(subdivide(levels, idx, P).p[0] - r0.p[0]), 0.f, 1e-6f);

    Result r = subdivide(3, idx, P);
    EXPECT_EQ(r.idx.size(), idx.size() * 64);
    expectNormalsFollowWinding(r);
    // Boundary vertices: those on an edge used by a single face.
    std::map<std::pair<int, int>, int> count;
    for (size_t f = 0; f < r.idx.size(); f += 3)
        for (int k = 0; k < 3; ++k) {
            int a = r.idx[f + k], b = r.idx[f + (k + 1) % 3];
            ++count[{std::min(a, b), std::max(a, b)}];
        }
    std::vector<char> onBoundary(r.p.size(), 0);
    int boundaryEdges = 0;
    for (const auto& [e, c] : count)
        if (c == 1) {
            onBoundary[size_t(e.first)] = onBoundary[size_t(e.second)] = 1;
            ++boundaryEdges;
        }
    EXPECT_EQ(boundaryEdges, 6 * 8);
    float apothem = std::cos(Pi / 6);
    for (size_t v = 0; v < r.p.size(); ++v) {
        if (onBoundary[v]) {
            // The boundary curve depends only on the planar boundary polygon: it stays in
            // z = 0, inside the hexagon and outside a circle well inside it.
            EXPECT_NEAR(r.p[v].z, 0.f, 1e-6f);
            float rad = std::hypot(r.p[v].x, r.p[v].y);
            EXPECT_LE(rad, 1.f);
            EXPECT_GT(rad, 0.75f * apothem);
            // Boundary normals tilt outward from the apex.
            EXPECT_GT(glm::dot(r.n[v], Vec3(r.p[v].x, r.p[v].y, 0.f)), 0.f);
        } else {
            EXPECT_GT(r.p[v].z, 0.f);
        }
    }
}

TEST(LoopSubdiv, UnusedVerticesDropped) {
    std::vector<Vec3> P = kTetP;
    P.push_back(Vec3(100, 100, 100));
    std::vector<int> idx = kTetIdx;
    Result a = subdivide(1, idx, P), b = subdivide(1, kTetIdx, kTetP);
    EXPECT_EQ(a.p.size(), b.p.size());
    for (const Vec3& p : a.p) EXPECT_LT(glm::length(p), 2.f);
}

TEST(LoopSubdiv, BadInputFails) {
    EXPECT_NE(failure(1, {0, 1, 7}, kTetP).find("out of range"), std::string::npos);
    EXPECT_NE(failure(1, {0, 1, -1}, kTetP).find("out of range"), std::string::npos);
    EXPECT_NE(failure(1, {0, 1}, kTetP).find("multiple of 3"), std::string::npos);
    EXPECT_NE(failure(1, {}, kTetP).find("multiple of 3"), std::string::npos);
    EXPECT_NE(failure(1, {0, 1, 1}, kTetP).find("repeats"), std::string::npos);
    EXPECT_NE(failure(-1, kTetIdx, kTetP).find("negative"), std::string::npos);
    EXPECT_NE(failure(20, kTetIdx, kTetP).find("exceeds"), std::string::npos);
    // Three faces on edge 0-1.
    std::vector<Vec3> P = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
    EXPECT_NE(failure(1, {0, 1, 2, 1, 0, 3, 0, 1, 4}, P).find("more than two"),
              std::string::npos);
    // Two faces traversing edge 0-1 in the same direction.
    EXPECT_NE(failure(1, {0, 1, 2, 0, 1, 3}, P).find("orientation"), std::string::npos);
    // Bow tie: two triangles sharing only vertex 0.
    std::vector<Vec3> B = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
    EXPECT_NE(failure(1, {0, 1, 2, 0, 3, 4}, B).find("non-manifold"), std::string::npos);
    std::vector<Vec3> N = kTetP;
    N[2].y = NAN;
    EXPECT_NE(failure(1, kTetIdx, N).find("non-finite"), std::string::npos);
}

// Reads the bracketed numbers after `name` in a pbrt file.
template <typename T>
std::vector<T> readArray(const std::string& text, const std::string& name) {
    std::vector<T> out;
    size_t at = text.find(name);
    if (at == std::string::npos) return out;
    size_t b = text.find('[', at), e = text.find(']', b);
    std::istringstream in(text.substr(b + 1, e - b - 1));
    T v;
    while (in >> v) out.push_back(v);
    return out;
}

TEST(LoopSubdiv, KillerooSceneMesh) {
    RLPBRT_REQUIRE_SHARED();
    std::string path =
        rlpbrt::test::sharedDir() + "/scenes/killeroo-simple/geometry/killeroo.pbrt";
    std::ifstream f(path);
    ASSERT_TRUE(f) << "cannot read " << path;
    std::stringstream ss;
    ss << f.rdbuf();
    std::string text = ss.str();
    std::vector<int> idx = readArray<int>(text, "\"integer indices\"");
    std::vector<float> pf = readArray<float>(text, "\"point P\"");
    ASSERT_GT(idx.size(), 0u);
    std::vector<Vec3> P;
    for (size_t i = 0; i + 2 < pf.size(); i += 3) P.push_back(Vec3(pf[i], pf[i + 1], pf[i + 2]));
    Result r = subdivide(1, idx, P);
    EXPECT_EQ(r.idx.size(), idx.size() * 4);
    for (const Vec3& n : r.n) EXPECT_NEAR(glm::length(n), 1.f, 1e-5f);
    // The control mesh is wound outward (positive volume); so is the result and its normals.
    double vol = 0;
    int agree = 0;
    for (size_t fi = 0; fi < r.idx.size(); fi += 3) {
        vol += glm::dot(r.p[size_t(r.idx[fi])], faceNormal(r, fi)) / 6;
        Vec3 fn = faceNormal(r, fi);
        for (int k = 0; k < 3; ++k) agree += glm::dot(fn, r.n[size_t(r.idx[fi + k])]) > 0;
    }
    EXPECT_GT(vol, 0.0);
    EXPECT_GT(agree, int(r.idx.size() * 99 / 100));
}

}  // namespace
}  // namespace rlpbrt
