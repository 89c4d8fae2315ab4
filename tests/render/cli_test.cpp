// The command line's own options: --version names the version and the commit (or "unknown"
// outside a git checkout), and --help lists the options in groups.
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "cli_run.h"

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
}

}  // namespace
