// Loop subdivision on an index-based triangle mesh: per level, a manifold topology (face
// neighbours across edges, ordered one-rings) is built and Loop's even/odd rules applied;
// finally vertices move to the limit surface and normals come from the limit tangents.
#include "render/loop_subdiv.h"

#include <array>
#include <cstdint>

namespace rlpbrt {
namespace {

using DVec3 = glm::dvec3;
using Tri = std::array<int, 3>;

inline int next3(int i) { return i == 2 ? 0 : i + 1; }
inline int prev3(int i) { return i == 0 ? 2 : i - 1; }

// pbrt-v3's Loop weight for an interior vertex of the given valence.
inline double loopBeta(int valence) {
    return valence == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * valence);
}
// Weight of the one-ring in the interior limit-position mask.
inline double loopGamma(int valence) {
    return 1.0 / (valence + 3.0 / (8.0 * loopBeta(valence)));
}

struct Mesh {
    std::vector<DVec3> p;
    std::vector<Tri> f;
};

// Adjacency of a manifold, consistently oriented triangle mesh.
struct Topology {
    std::vector<Tri> nbr;    // face across edge k = (v[k], v[k+1]) or -1 on the boundary
    std::vector<Tri> edge;   // id of edge k of each face
    std::vector<std::array<int, 2>> edgeVerts;  // endpoints as seen by the first face
    std::vector<std::array<int, 2>> edgeFaces;  // first face, second face or -1
    std::vector<char> boundary;                 // per vertex
    std::vector<int> ringStart;                 // per vertex offsets into ring (size nv + 1)
    std::vector<int> ring;  // one-rings in pbrt-v3's order (see buildTopology)

    int valence(int v) const { return ringStart[size_t(v) + 1] - ringStart[size_t(v)]; }
    const int* ringOf(int v) const { return ring.data() + ringStart[size_t(v)]; }
};

inline int slot(const Tri& t, int v) { return t[0] == v ? 0 : (t[1] == v ? 1 : 2); }

// Builds face adjacency and one-rings. Interior rings list, starting anywhere, the vertex
// after v in each face while stepping to the face across edge (v, next); boundary rings run
// from one boundary neighbour across the fan to the other (pbrt-v3's SDVertex::oneRing).
bool buildTopology(const Mesh& m, Topology* t, std::string* error) {
    const size_t nf = m.f.size(), nv = m.p.size();
    t->nbr.assign(nf, Tri{-1, -1, -1});
    t->edge.assign(nf, Tri{-1, -1, -1});
    t->edgeVerts.clear();
    t->edgeFaces.clear();
    t->edgeVerts.reserve(nf * 3 / 2 + 3);
    t->edgeFaces.reserve(nf * 3 / 2 + 3);
    // Edges keyed by their smaller endpoint: per-vertex slots (CSR) holding (other end, id),
    // filled in face order so that edge ids follow pbrt-v3's creation order.
    std::vector<int> slotStart(nv + 1, 0), slotFill;
    for (const Tri& tri : m.f)
        for (int k = 0; k < 3; ++k) ++slotStart[size_t(std::min(tri[k], tri[next3(k)])) + 1];
    for (size_t v = 0; v < nv; ++v) slotStart[v + 1] += slotStart[v];
    slotFill.assign(slotStart.begin(), slotStart.end() - 1);
    std::vector<std::array<int, 2>> slots(static_cast<size_t>(slotStart[nv]));
    std::vector<int> incident(nv, 0), startFace(nv, -1);
    for (size_t fi = 0; fi < nf; ++fi) {
        const Tri& tri = m.f[fi];
        for (int k = 0; k < 3; ++k) {
            ++incident[size_t(tri[k])];
            startFace[size_t(tri[k])] = int(fi);
            int a = tri[k], b = tri[next3(k)];
            size_t lo = size_t(std::min(a, b));
            int hi = std::max(a, b), e = -1;
            for (int i = slotStart[lo]; i < slotFill[lo]; ++i)
                if (slots[size_t(i)][0] == hi) {
                    e = slots[size_t(i)][1];
                    break;
                }
            if (e < 0) {
                e = int(t->edgeVerts.size());
                slots[size_t(slotFill[lo]++)] = {hi, e};
                t->edgeVerts.push_back({a, b});
                t->edgeFaces.push_back({int(fi), -1});
            } else {
                auto& ef = t->edgeFaces[size_t(e)];
                if (ef[1] >= 0) {
                    *error = "edge (" + std::to_string(a) + ", " + std::to_string(b) +
                             ") is shared by more than two faces";
                    return false;
                }
                if (t->edgeVerts[size_t(e)][0] == a) {
                    *error = "faces " + std::to_string(ef[0]) + " and " + std::to_string(fi) +
                             " have inconsistent orientation";
                    return false;
                }
                ef[1] = int(fi);
                int f0 = ef[0];
                t->nbr[fi][size_t(k)] = f0;
                const Tri& t0 = m.f[size_t(f0)];
                t->nbr[size_t(f0)][size_t(slot(t0, b))] = int(fi);  // edge (b, a) of f0
            }
            t->edge[fi][size_t(k)] = e;
        }
    }
    // One-rings.
    t->boundary.assign(nv, 0);
    t->ringStart.assign(nv + 1, 0);
    t->ring.clear();
    t->ring.reserve(nf * 3 + nv);
    for (size_t v = 0; v < nv; ++v) {
        t->ringStart[v] = int(t->ring.size());
        int vi = int(v);
        int start = startFace[v];
        if (start < 0) continue;  // unused (cannot happen after compaction)
        int f = start, count = 0;
        bool closed = false;
        // Walk across (v, next) edges until we return to start or reach the boundary.
        int last = f;
        while (true) {
            ++count;
            last = f;
            int g = t->nbr[size_t(f)][size_t(slot(m.f[size_t(f)], vi))];
            if (g == start) { closed = true; break; }
            if (g < 0 || count > incident[v]) break;
            f = g;
        }
        if (closed) {
            if (count != incident[v]) {
                *error = "non-manifold vertex " + std::to_string(v);
                return false;
            }
            f = start;
            do {
                const Tri& tri = m.f[size_t(f)];
                t->ring.push_back(tri[size_t(next3(slot(tri, vi)))]);
                f = t->nbr[size_t(f)][size_t(slot(tri, vi))];
            } while (f != start);
        } else {
            if (count > incident[v]) {
                *error = "non-manifold vertex " + std::to_string(v);
                return false;
            }
            t->boundary[v] = 1;
            f = last;
            const Tri& lt = m.f[size_t(f)];
            t->ring.push_back(lt[size_t(next3(slot(lt, vi)))]);
            int faces = 0;
            while (f >= 0 && faces <= incident[v]) {
                const Tri& tri = m.f[size_t(f)];
                int s = slot(tri, vi);
                t->ring.push_back(tri[size_t(prev3(s))]);
                ++faces;
                f = t->nbr[size_t(f)][size_t(prev3(s))];
            }
            if (faces != incident[v]) {
                *error = "non-manifold vertex " + std::to_string(v) +
                         " (faces around it form more than one fan)";
                return false;
            }
        }
    }
    t->ringStart[nv] = int(t->ring.size());
    return true;
}

int oppositeVertex(const Tri& t, int a, int b) {
    for (int v : t)
        if (v != a && v != b) return v;
    return t[0];
}

// One Loop refinement step of `m` with topology `t`.
Mesh refine(const Mesh& m, const Topology& t) {
    const size_t nv = m.p.size(), ne = t.edgeVerts.size();
    Mesh out;
    out.p.resize(nv + ne);
    // Even vertices.
    for (size_t v = 0; v < nv; ++v) {
        int n = t.valence(int(v));
        const int* r = t.ringOf(int(v));
        if (t.boundary[v]) {
            out.p[v] = 0.75 * m.p[v] + 0.125 * (m.p[size_t(r[0])] + m.p[size_t(r[n - 1])]);
        } else {
            double b = loopBeta(n);
            DVec3 sum(0.0);
            for (int k = 0; k < n; ++k) sum += m.p[size_t(r[k])];
            out.p[v] = (1 - n * b) * m.p[v] + b * sum;
        }
    }
    // Odd (edge) vertices.
    for (size_t e = 0; e < ne; ++e) {
        int a = t.edgeVerts[e][0], b = t.edgeVerts[e][1];
        int f0 = t.edgeFaces[e][0], f1 = t.edgeFaces[e][1];
        DVec3 pa = m.p[size_t(a)], pb = m.p[size_t(b)];
        if (f1 < 0) {
            out.p[nv + e] = 0.5 * (pa + pb);
        } else {
            DVec3 c = m.p[size_t(oppositeVertex(m.f[size_t(f0)], a, b))];
            DVec3 d = m.p[size_t(oppositeVertex(m.f[size_t(f1)], a, b))];
            out.p[nv + e] = 0.375 * (pa + pb) + 0.125 * (c + d);
        }
    }
    // Four children per face, in pbrt-v3's order and vertex slots.
    out.f.resize(m.f.size() * 4);
    for (size_t fi = 0; fi < m.f.size(); ++fi) {
        const Tri& v = m.f[fi];
        int e01 = int(nv) + t.edge[fi][0], e12 = int(nv) + t.edge[fi][1];
        int e20 = int(nv) + t.edge[fi][2];
        out.f[4 * fi + 0] = {v[0], e01, e20};
        out.f[4 * fi + 1] = {e01, v[1], e12};
        out.f[4 * fi + 2] = {e20, e12, v[2]};
        out.f[4 * fi + 3] = {e01, e12, e20};
    }
    return out;
}

}  // namespace

bool loopSubdivide(int nLevels, const std::vector<int>& indices, const std::vector<Vec3>& P,
                   std::vector<Vec3>* outP, std::vector<Vec3>* outN,
                   std::vector<int>* outIndices, std::string* error) {
    std::string dummy;
    if (!error) error = &dummy;
    if (nLevels < 0) {
        *error = "nlevels must not be negative (got " + std::to_string(nLevels) + ")";
        return false;
    }
    if (indices.empty() || indices.size() % 3 != 0) {
        *error = "\"indices\" must hold a positive multiple of 3 values (got " +
                 std::to_string(indices.size()) + ")";
        return false;
    }
    const size_t nf = indices.size() / 3;
    // Result size: nf * 4^nLevels faces; refuse absurd requests before allocating.
    const double maxFaces = double(1 << 24);
    if (double(nf) * std::pow(4.0, nLevels) > maxFaces) {
        *error = "subdividing " + std::to_string(nf) + " triangles " +
                 std::to_string(nLevels) + " times exceeds " +
                 std::to_string(int64_t(maxFaces)) + " triangles";
        return false;
    }
    // Validate, and compact away unreferenced vertices (keeping the order of the others).
    std::vector<int> remap(P.size(), -1);
    for (int idx : indices) {
        if (idx < 0 || size_t(idx) >= P.size()) {
            *error = "vertex index " + std::to_string(idx) + " out of range (" +
                     std::to_string(P.size()) + " vertices)";
            return false;
        }
        remap[size_t(idx)] = 0;
    }
    Mesh m;
    for (size_t v = 0; v < P.size(); ++v) {
        if (remap[v] < 0) continue;
        if (!isFinite(P[v])) {
            *error = "vertex " + std::to_string(v) + " has a non-finite position";
            return false;
        }
        remap[v] = int(m.p.size());
        m.p.push_back(DVec3(P[v]));
    }
    m.f.resize(nf);
    for (size_t i = 0; i < indices.size(); ++i) m.f[i / 3][i % 3] = remap[size_t(indices[i])];
    for (size_t fi = 0; fi < nf; ++fi) {
        const Tri& t = m.f[fi];
        if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
            *error = "triangle " + std::to_string(fi) + " repeats a vertex";
            return false;
        }
    }

    Topology topo;
    for (int level = 0; level < nLevels; ++level) {
        if (!buildTopology(m, &topo, error)) return false;
        m = refine(m, topo);
    }
    if (!buildTopology(m, &topo, error)) return false;

    // Push vertices to the limit surface.
    const size_t nv = m.p.size();
    std::vector<DVec3> limit(nv);
    for (size_t v = 0; v < nv; ++v) {
        int n = topo.valence(int(v));
        const int* r = topo.ringOf(int(v));
        if (topo.boundary[v]) {
            limit[v] = 0.6 * m.p[v] + 0.2 * (m.p[size_t(r[0])] + m.p[size_t(r[n - 1])]);
        } else {
            double g = loopGamma(n);
            DVec3 sum(0.0);
            for (int k = 0; k < n; ++k) sum += m.p[size_t(r[k])];
            limit[v] = (1 - n * g) * m.p[v] + g * sum;
        }
    }

    // Area-weighted face normals: fallback where the limit tangents degenerate.
    std::vector<DVec3> faceSum(nv, DVec3(0.0));
    for (const Tri& t : m.f) {
        DVec3 n = glm::cross(limit[size_t(t[1])] - limit[size_t(t[0])],
                             limit[size_t(t[2])] - limit[size_t(t[0])]);
        for (int v : t) faceSum[size_t(v)] += n;
    }

    // Normals from the limit tangents (pbrt-v3's masks). pbrt-v3's rings run clockwise
    // around the winding normal, so cross(S, T) points against it; we use cross(T, S).
    outN->resize(nv);
    std::vector<DVec3> ringP;
    for (size_t v = 0; v < nv; ++v) {
        int n = topo.valence(int(v));
        const int* r = topo.ringOf(int(v));
        ringP.resize(size_t(n));
        for (int k = 0; k < n; ++k) ringP[size_t(k)] = limit[size_t(r[k])];
        DVec3 S(0.0), T(0.0);
        const DVec3& p = limit[v];
        if (!topo.boundary[v]) {
            for (int k = 0; k < n; ++k) {
                double ang = 2 * double(Pi) * k / n;
                S += std::cos(ang) * ringP[size_t(k)];
                T += std::sin(ang) * ringP[size_t(k)];
            }
        } else {
            S = ringP[size_t(n - 1)] - ringP[0];
            if (n == 2) {
                T = ringP[0] + ringP[1] - 2.0 * p;
            } else if (n == 3) {
                T = ringP[1] - p;
            } else if (n == 4) {
                T = -ringP[0] + 2.0 * ringP[1] + 2.0 * ringP[2] - ringP[3] - 2.0 * p;
            } else {
                double theta = double(Pi) / (n - 1);
                T = std::sin(theta) * (ringP[0] + ringP[size_t(n - 1)]);
                for (int k = 1; k < n - 1; ++k)
                    T += (2 * std::cos(theta) - 2) * std::sin(k * theta) * ringP[size_t(k)];
                T = -T;
            }
        }
        DVec3 N = glm::cross(T, S);
        double len = glm::length(N);
        if (!(len > 0) || !std::isfinite(len)) {
            N = faceSum[v];
            len = glm::length(N);
        }
        (*outN)[v] = (len > 0 && std::isfinite(len)) ? Vec3(N / len) : Vec3(0, 0, 1);
    }

    outP->resize(nv);
    for (size_t v = 0; v < nv; ++v) (*outP)[v] = Vec3(limit[v]);
    outIndices->resize(m.f.size() * 3);
    for (size_t fi = 0; fi < m.f.size(); ++fi)
        for (int k = 0; k < 3; ++k) (*outIndices)[3 * fi + size_t(k)] = m.f[fi][size_t(k)];
    return true;
}

}  // namespace rlpbrt
