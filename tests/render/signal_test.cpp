// No lost work: SIGINT or SIGTERM during a render writes the image so far (its real spp in
// the statistics and the EXR metadata) and exits with 130.
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "render/exr_header.h"
#include "render/image_io.h"

namespace {

std::string tempDir() {
    char tmpl[] = "/tmp/rlpbrt-signal-XXXXXX";
    const char* d = mkdtemp(tmpl);
    return d ? d : "/tmp";
}

void interruptedRender(int sig) {
    std::string dir = tempDir();
    std::string out = dir + "/out.exr", stats = dir + "/stats.json";
    std::string scene = std::string(RLPBRT_SOURCE_DIR) + "/scenes/demo/demo.pbrt";
    pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        freopen("/dev/null", "w", stderr);
        execl(RLPBRT_BINARY, RLPBRT_BINARY, scene.c_str(), "--spp", "1000000", "--nthreads", "1",
              "-o", out.c_str(), "--stats", stats.c_str(), "--quiet", (char*)nullptr);
        _exit(127);
    }
    // Long enough to parse, build and finish a few passes of 320x240 at 1 spp each.
    sleep(2);
    kill(pid, sig);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 130);
    rlpbrt::Image img;
    std::string err;
    ASSERT_TRUE(rlpbrt::readImage(out, &img, &err)) << err;
    EXPECT_EQ(img.width, 320);
    EXPECT_EQ(img.height, 240);
    std::ifstream f(stats);
    std::stringstream ss;
    ss << f.rdbuf();
    std::string json = ss.str();
    EXPECT_NE(json.find("\"cancelled\": true"), std::string::npos) << json;
    auto pos = json.find("\"spp\": ");
    ASSERT_NE(pos, std::string::npos);
    int spp = std::stoi(json.substr(pos + 7));
    EXPECT_GE(spp, 1);
    EXPECT_LT(spp, 1000000);
    // The image's metadata carries the same real spp.
    auto attrs = rlpbrt::test::exrStringAttributes(out);
    ASSERT_EQ(attrs.count("rlpbrt:spp"), 1u);
    EXPECT_EQ(attrs["rlpbrt:spp"], std::to_string(spp));
    std::remove(out.c_str());
    std::remove(stats.c_str());
    rmdir(dir.c_str());
}

TEST(Signals, SigintWritesTheImageSoFar) { interruptedRender(SIGINT); }
TEST(Signals, SigtermWritesTheImageSoFar) { interruptedRender(SIGTERM); }

}  // namespace
