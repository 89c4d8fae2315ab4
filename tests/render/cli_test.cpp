// The command line's own options: --version names the version and the commit (or "unknown"
// outside a git checkout), and --help lists the options in groups. The demo scene
// (scripts/demo.sh) builds, and its reference has the film's size.
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "cli_run.h"
#include "render/image_io.h"

namespace {

using rlpbrt::test::runCli;

TEST(Cli, VersionNamesVersionAndCommit) {
    auto r = runCli("--version");
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(std::regex_search(
        r.output, std::regex(R"(^rlpbrt [0-9]+\.[0-9]+\.[0-9]+ \(commit ([0-9a-f]{7,}(-dirty)?|unknown)\)\n$)")))
        << r.output;
    EXPECT_NE(r.output.find(RLPBRT_VERSION), std::string::npos) << r.output;
}

TEST(Cli, HelpGroupsTheOptions) {
    auto r = runCli("--help");
    EXPECT_EQ(r.status, 0) << r.output;
    // Each group's heading, in this order, and one option of each under it.
    size_t at = 0;
    for (const char* heading : {"\nRender:\n", "--spp", "\nGuiding:\n", "--guide-param",
                                "\nOutput:\n", "--outfile", "\nDiagnostics:\n", "--curve"}) {
        size_t next = r.output.find(heading, at);
        ASSERT_NE(next, std::string::npos) << heading << " missing or out of order:\n" << r.output;
        at = next;
    }
    // Every option has a group: the ungrouped "Options:" list holds only --help and --version.
    const size_t options = r.output.find("\nOptions:\n"), render = r.output.find("\nRender:\n");
    ASSERT_NE(options, std::string::npos) << r.output;
    std::string ungrouped = r.output.substr(options, render - options);
    for (const char* known : {"--help", "--version"}) {
        const size_t k = ungrouped.find(known);
        ASSERT_NE(k, std::string::npos) << ungrouped;
        ungrouped.erase(k, 2);
    }
    EXPECT_EQ(ungrouped.find("--"), std::string::npos) << "an option without a group:\n"
                                                       << ungrouped;
}

TEST(Cli, DemoSceneAndItsReferenceAgree) {
    const std::string dir = std::string(RLPBRT_SOURCE_DIR) + "/scenes/demo/";
    auto r = runCli("--parse-only " + dir + "door.pbrt");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("lights: 2 (2 area lights"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("film 256x192"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("ignored features: 0"), std::string::npos) << r.output;
    rlpbrt::Image ref;
    std::string err;
    ASSERT_TRUE(rlpbrt::readImage(dir + "door-ref.exr", &ref, &err)) << err;
    EXPECT_EQ(ref.width, 256);
    EXPECT_EQ(ref.height, 192);
}

}  // namespace
