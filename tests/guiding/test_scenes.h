// Small analytic scenes and random directions shared by the guiding backends' tests.
#pragma once

#include <random>

#include "guiding/guiding.h"

namespace rlpbrt::guiding::test {

// Unit square [0,1]^2 at z = 0 with normal +z.
inline SceneInfo planeScene() {
    SceneInfo s;
    s.boundsMin = glm::vec3(0.f);
    s.boundsMax = glm::vec3(1.f, 1.f, 0.f);
    s.totalArea = 1.0;
    s.samplePoint = [](const glm::vec3& u, glm::vec3* p, glm::vec3* n) {
        *p = glm::vec3(u.x, u.y, 0.f);
        *n = glm::vec3(0.f, 0.f, 1.f);
        return true;
    };
    return s;
}

// A floor (z = 0, normal +z) and a wall (x = 0, normal +x), both unit squares.
inline SceneInfo cornerScene() {
    SceneInfo s;
    s.boundsMin = glm::vec3(0.f);
    s.boundsMax = glm::vec3(1.f);
    s.totalArea = 2.0;
    s.samplePoint = [](const glm::vec3& u, glm::vec3* p, glm::vec3* n) {
        if (u.x < 0.5f) {
            *p = glm::vec3(2.f * u.x, u.y, 0.f);
            *n = glm::vec3(0.f, 0.f, 1.f);
        } else {
            *p = glm::vec3(0.f, u.y, 2.f * u.x - 1.f);
            *n = glm::vec3(1.f, 0.f, 0.f);
        }
        return true;
    };
    return s;
}

// A uniformly distributed unit direction.
inline glm::vec3 gaussianDirection(std::mt19937_64& rng) {
    std::normal_distribution<float> g;
    glm::vec3 v;
    do {
        v = glm::vec3(g(rng), g(rng), g(rng));
    } while (glm::length(v) < 1e-6f);
    return glm::normalize(v);
}

}  // namespace rlpbrt::guiding::test
