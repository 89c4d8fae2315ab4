// Small analytic scenes and random directions shared by the guiding backends' tests.
#pragma once

#include <map>
#include <memory>
#include <random>
#include <string>

#include <gtest/gtest.h>

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

// A field of backend Field made through the factory (as the integrator does); a test failure
// and nullptr if the factory refuses or makes another type.
template <class Field>
std::unique_ptr<Field> makeField(const char* backend, const SceneInfo& scene,
                                 std::map<std::string, std::string> params = {}) {
    GuideConfig cfg;
    cfg.backend = backend;
    cfg.params = std::move(params);
    std::string error;
    std::unique_ptr<GuidingField> f = createGuidingField(cfg, scene, &error);
    EXPECT_TRUE(f) << error;
    EXPECT_TRUE(error.empty()) << error;
    auto* typed = dynamic_cast<Field*>(f.get());
    EXPECT_TRUE(typed);
    if (!typed) return nullptr;
    f.release();
    return std::unique_ptr<Field>(typed);
}

// Trains a region for a few passes of 20000 uniform directions: target 100 within the cone
// dot(w, bright) > 0.9, 0.05 elsewhere (directions outside the region's strata are rejected).
inline void trainBright(GuidingField& f, int region, const glm::vec3& bright, int passes,
                        uint64_t seed) {
    std::mt19937_64 rng(seed);
    for (int p = 0; p < passes; ++p) {
        f.beginPass(1);
        for (int i = 0; i < 20000; ++i) {
            glm::vec3 w = gaussianDirection(rng);
            f.record(0, region, w, glm::dot(w, bright) > 0.9f ? 100.f : 0.05f);
        }
        f.endPass();
    }
}

}  // namespace rlpbrt::guiding::test
