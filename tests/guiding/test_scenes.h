// Small analytic scenes and random directions shared by the guiding backends' tests.
#pragma once

#include <cstring>
#include <map>
#include <memory>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "guiding/guiding.h"
#include "render/chi2.h"

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

// Calls feed(slot) for slots 0 .. slots - 1 in one of the orders the determinism tests
// compare: schedule 0 = slot order, 1 = reverse order, n >= 2 = in parallel on n threads.
template <class Feed>
void feedSlots(int slots, int schedule, Feed&& feed) {
    if (schedule == 0) {
        for (int s = 0; s < slots; ++s) feed(s);
    } else if (schedule == 1) {
        for (int s = slots - 1; s >= 0; --s) feed(s);
    } else {
        tbb::task_arena arena(schedule);
        arena.execute([&] { tbb::parallel_for(0, slots, 1, feed); });
    }
}

// Expects b's learned tables (Q, visits, CDFs) to equal a's bit for bit.
template <class Field>
void expectSameTables(const Field& a, const Field& b) {
    ASSERT_EQ(a.qTable().size(), b.qTable().size());
    EXPECT_EQ(0, std::memcmp(a.qTable().data(), b.qTable().data(),
                             a.qTable().size() * sizeof(double)));
    ASSERT_EQ(a.visitTable().size(), b.visitTable().size());
    EXPECT_EQ(0, std::memcmp(a.visitTable().data(), b.visitTable().data(),
                             a.visitTable().size() * sizeof(uint64_t)));
    ASSERT_EQ(a.cdfTable().size(), b.cdfTable().size());
    EXPECT_EQ(0, std::memcmp(a.cdfTable().data(), b.cdfTable().data(),
                             a.cdfTable().size() * sizeof(float)));
}

inline chi2::SphereOptions sphereOptions(uint64_t seed, long long samples, int thetaRes,
                                        int phiRes, int numTests = 1) {
    chi2::SphereOptions opt;
    opt.sampleCount = samples;
    opt.thetaRes = thetaRes;
    opt.phiRes = phiRes;
    opt.seed = seed;
    opt.numTests = numTests;
    return opt;
}

// World-grid chi-square of a region's sample() against the quadrature of its pdf()
// (render/chi2.h), 12 x 24 cells; numTests: the tests the 1% family-wise level is shared by.
// The adaptive quadrature loses ~1e-5 of the mass of sharply peaked pdfs at discontinuities,
// so peaked fields use 1e5 samples (bias ~1 count, below the ~sqrt(count) noise).
inline chi2::SphereResult sphereTest(const GuidingField& f, int region, uint64_t seed,
                                     long long samples = 400000, int numTests = 1) {
    return chi2::testSphere(
        [&](const glm::vec3& u) {
            chi2::SphereSample s;
            s.dir = f.sample(region, glm::vec2(u.x, u.y), u.z, &s.pdf);
            return s;
        },
        [&](const glm::vec3& w) { return f.pdf(region, w); },
        sphereOptions(seed, samples, 12, 24, numTests));
}

// The same at a place x of the region, through sampleAt() and pdfAt() (hemi's spot lobes aim
// from x), on a finer 24 x 48 grid for narrow lobes.
inline chi2::SphereResult sphereTestAt(const GuidingField& f, int region, const glm::vec3& x,
                                       uint64_t seed, long long samples = 200000) {
    return chi2::testSphere(
        [&](const glm::vec3& u) {
            chi2::SphereSample s;
            s.dir = f.sampleAt(region, x, glm::vec2(u.x, u.y), u.z, &s.pdf);
            return s;
        },
        [&](const glm::vec3& w) { return f.pdfAt(region, x, w); },
        sphereOptions(seed, samples, 24, 48));
}

}  // namespace rlpbrt::guiding::test
