// Access to the shared test data (pbrt-v3 scenes and pbrt-v3's reference images: a folder
// with scenes/ and references/, README.md "Test scenes"). Its place: the environment
// variable RLPBRT_SHARED when set and not empty, else the CMake cache variable
// RLPBRT_SHARED_DIR (default: ../shared beside the source tree). Tests that need it fail when
// CI=true and it is missing, and skip otherwise, saying where they looked.
#pragma once

#include <cstdlib>
#include <string>
#include <sys/stat.h>

#include <gtest/gtest.h>

namespace rlpbrt::test {

inline std::string sharedDir() {
    const char* env = std::getenv("RLPBRT_SHARED");
    if (env && *env) return env;
    return RLPBRT_SHARED_DIR;
}

inline bool sharedAvailable() {
    struct stat st;
    return stat((sharedDir() + "/references/manifest.tsv").c_str(), &st) == 0;
}

inline bool inCI() {
    const char* ci = std::getenv("CI");
    return ci && std::string(ci) == "true";
}

}  // namespace rlpbrt::test

// Use at the start of a test body that needs the shared scenes and references. The skip
// message starts with "shared test data" (scripts/test.sh counts these skips).
#define RLPBRT_REQUIRE_SHARED()                                                           \
    do {                                                                                  \
        if (!::rlpbrt::test::sharedAvailable()) {                                         \
            if (::rlpbrt::test::inCI())                                                   \
                FAIL() << "shared test data missing at " << ::rlpbrt::test::sharedDir()   \
                       << " (CI=true)";                                                   \
            GTEST_SKIP() << "shared test data missing at " << ::rlpbrt::test::sharedDir() \
                         << " (set RLPBRT_SHARED; README.md, \"Test scenes\")";           \
        }                                                                                 \
    } while (0)
