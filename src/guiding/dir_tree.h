// An adaptive directional distribution for the guiding layer (issue 30: directions refined
// where the learned light concentrates, as the directional quadtrees of Mueller et al. 2017,
// "Practical Path Guiding"): a quadtree over the unit square whose leaves hold a non-negative
// mass. Sampling picks a leaf with probability proportional to its mass and a point uniformly
// inside it. Through the cylindrical equal-area maps below, area on the square is solid angle
// up to a constant, so a direction's density per steradian is the square's density divided
// by the domain's solid angle (2 pi for a hemisphere, 4 pi for the sphere).
// Between passes the owner sets the leaves' masses from what it learned and asks for the
// refined tree: a node whose share of the total mass exceeds a threshold is split into four,
// a subtree whose share does not is merged into one leaf, so fine leaves go where the light
// is concentrated and the leaf count stays about 4 / threshold at most. Standard library and
// GLM only; not thread-safe for writing, const methods are.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace rlpbrt::guiding {

class DirTree {
public:
    // A node: its four children are nodes child .. child + 3 (0: a leaf), child k covering
    // the quarter (k & 1) in x and (k >> 1) in y of the node's square; mass is the leaf's (for
    // a leaf) or the sum of its children's.
    struct Node {
        uint32_t child = 0;
        float mass = 0.f;
        bool leaf() const { return child == 0; }
    };
    // Where a node of a refined tree takes its data from: the node `from` of the tree it was
    // refined from, of which it covers `fraction` of the area (1: the same square, or a merge
    // of that node's subtree; 1/4, 1/16, ...: a piece of an old leaf).
    struct Source {
        uint32_t from = 0;
        float fraction = 1.f;
    };
    static constexpr int kMaxDepth = 16;

    // A single leaf of mass 1: the uniform distribution.
    DirTree();

    size_t size() const { return nodes_.size(); }
    size_t leaves() const { return (nodes_.size() - 1) / 4 * 3 + 1; }
    const Node& node(uint32_t i) const { return nodes_[i]; }
    float totalMass() const { return nodes_[0].mass; }
    // Bytes of the tree's nodes.
    size_t bytes() const { return nodes_.size() * sizeof(Node); }

    // The leaf whose square holds a (components clamped to [0, 1]; NaN goes to 0); its depth
    // (0: the root) in *depth if given.
    uint32_t leafOf(glm::vec2 a, int* depth = nullptr) const;
    // The square of node i: its lower corner and edge length (a walk over the nodes: for
    // one node; squares() gives all at once).
    void square(uint32_t i, glm::vec2* origin, float* edge) const;
    // Every node's square as (origin x, origin y, edge), in node order.
    std::vector<glm::vec3> squares() const;
    // Density over the unit square at a (integrates to 1 over it): the product over the path
    // from the root of 4 x the child's share of its parent's mass (a quarter each where the
    // parent's mass is 0). *leaf (if given) receives a's leaf.
    float density(glm::vec2 a, uint32_t* leaf = nullptr) const;
    // A point of the square drawn with density(), from u in [0,1)^2 (each level picks the
    // half in x by u.x, then the half in y within it by u.y, and rescales both). *density
    // receives density(result); *leaf (if given) its leaf. Never a leaf of zero mass.
    glm::vec2 sample(glm::vec2 u, float* density, uint32_t* leaf = nullptr) const;

    // Sets the mass of every leaf (mass[i] for leaf node i; inner entries are ignored; values
    // that are negative or not finite count as 0) and sums them up the tree. mass.size() must
    // be size().
    void setLeafMasses(const std::vector<float>& mass);
    // The refined tree: from the root, a node whose share of the total mass is above
    // splitShare (in (0, 1]) and whose depth is below maxDepth (at most kMaxDepth) gets four
    // children (an old leaf's mass split evenly among them, which may split again), any other
    // node becomes a leaf holding its subtree's mass. sources (if given) receives, per node of
    // the result, where its data come from. A tree without mass refines to the single leaf.
    DirTree refined(double splitShare, int maxDepth, std::vector<Source>* sources = nullptr) const;

    // The cylindrical equal-area maps between the unit square and directions in a local frame:
    // the upper hemisphere (cos(theta) = a.x, phi = 2 pi a.y; the layout of StrataLayout's
    // strata) and the sphere (cos(theta) = 2 a.x - 1).
    static glm::vec3 hemisphereDirection(glm::vec2 a);
    // The square point of a unit local direction; false if local.z <= 0 or NaN.
    static bool hemispherePoint(const glm::vec3& local, glm::vec2* a);
    static glm::vec3 sphereDirection(glm::vec2 a);
    // False for a NaN direction.
    static bool spherePoint(const glm::vec3& local, glm::vec2* a);

private:
    std::vector<Node> nodes_;
};

}  // namespace rlpbrt::guiding
