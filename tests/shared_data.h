// Access to ../shared (scenes and pbrt-v3 references) from tests. Tests that need it fail when
// CI=true and it is missing, and skip otherwise.
#pragma once

#include <cstdlib>
#include <string>
#include <sys/stat.h>

#include <gtest/gtest.h>

namespace rlpbrt::test {

inline std::string sharedDir() { return std::string(RLPBRT_SOURCE_DIR) + "/../shared"; }

inline bool sharedAvailable() {
    struct stat st;
    return stat((sharedDir() + "/references/manifest.tsv").c_str(), &st) == 0;
}

inline bool inCI() {
    const char* ci = std::getenv("CI");
    return ci && std::string(ci) == "true";
}

}  // namespace rlpbrt::test

// Use at the start of a test body that needs ../shared.
#define RLPBRT_REQUIRE_SHARED()                                                           \
    do {                                                                                  \
        if (!::rlpbrt::test::sharedAvailable()) {                                         \
            if (::rlpbrt::test::inCI()) FAIL() << "../shared is missing (CI=true)";       \
            GTEST_SKIP() << "../shared is missing";                                       \
        }                                                                                 \
    } while (0)
