// No lost work: `--checkpoint SECONDS` writes the image so far during the render (atomically,
// with its real spp in the metadata), and the final image replaces it at the end; the restart
// state OUTFILE.resume is written with it (tests/render/resume_test.cpp).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <sys/stat.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

#include <gtest/gtest.h>

#include "render/exr_header.h"
#include "render/image_io.h"

namespace {

bool exists(const std::string& p) {
    struct stat st;
    return stat(p.c_str(), &st) == 0;
}

int sppOf(const std::string& exr) {
    auto attrs = rlpbrt::test::exrStringAttributes(exr);
    auto it = attrs.find("rlpbrt:spp");
    return it == attrs.end() ? -1 : std::stoi(it->second);
}

TEST(Checkpoint, ImageSoFarIsWrittenDuringTheRender) {
    char tmpl[] = "/tmp/rlpbrt-checkpoint-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    std::string dir = tmpl, out = dir + "/out.exr", stats = dir + "/stats.json";
    std::string scene = std::string(RLPBRT_SOURCE_DIR) + "/scenes/demo/demo.pbrt";
    pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        freopen("/dev/null", "w", stderr);
#if defined(__SANITIZE_ADDRESS__)
        const char* budget = "20";  // a pass takes seconds under the sanitizers: >= 2 passes
#else
        const char* budget = "6";
#endif
        execl(RLPBRT_BINARY, RLPBRT_BINARY, scene.c_str(), "--time", budget, "--checkpoint", "0.2",
              "--nthreads", "1", "-o", out.c_str(), "--stats", stats.c_str(), "--quiet",
              (char*)nullptr);
        _exit(127);
    }
    // Wait for the first checkpoint (parse + build + 0.2 s of passes).
    auto start = std::chrono::steady_clock::now();
    while (!exists(out) && std::chrono::steady_clock::now() - start < std::chrono::seconds(15))
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    int status = 0;
    ASSERT_TRUE(exists(out)) << "no checkpoint within 15 s";
    ASSERT_EQ(waitpid(pid, &status, WNOHANG), 0) << "the render ended before its checkpoint";
    // Mid-render: a complete, valid image (written by rename, never partial).
    rlpbrt::Image mid;
    std::string err;
    ASSERT_TRUE(rlpbrt::readImage(out, &mid, &err)) << err;
    EXPECT_EQ(mid.width, 320);
    EXPECT_EQ(mid.height, 240);
    int midSpp = sppOf(out);
    EXPECT_GE(midSpp, 1);
    // No temporary files are left next to it at the end.
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_EQ(WEXITSTATUS(status), 0);
    int finalSpp = sppOf(out);
    EXPECT_GT(finalSpp, midSpp);
    rlpbrt::Image fin;
    ASSERT_TRUE(rlpbrt::readImage(out, &fin, &err)) << err;
    EXPECT_EQ(fin.width, 320);
    for (float v : fin.pixels) ASSERT_TRUE(std::isfinite(v));
    FILE* f = std::fopen(stats.c_str(), "r");
    ASSERT_NE(f, nullptr);
    char buf[4096] = {};
    std::fread(buf, 1, sizeof buf - 1, f);
    std::fclose(f);
    std::string json = buf;
    EXPECT_NE(json.find("\"spp\": " + std::to_string(finalSpp)), std::string::npos) << json;
    auto c = json.find("\"checkpoints\": ");
    ASSERT_NE(c, std::string::npos) << json;
    EXPECT_GE(std::stoi(json.substr(c + 15)), 2) << json;
    // With each checkpoint, the restart state (docs/DISTRIBUTED.md, "Resume").
    EXPECT_TRUE(exists(out + ".resume"));
    std::remove(out.c_str());
    std::remove((out + ".resume").c_str());
    std::remove(stats.c_str());
    EXPECT_EQ(rmdir(dir.c_str()), 0) << "files left in " << dir;
}

TEST(Checkpoint, NegativeIntervalIsRejected) {
    std::string cmd = std::string(RLPBRT_BINARY) + " --checkpoint -1 /nonexistent.pbrt >/dev/null 2>&1";
    int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status));
    EXPECT_NE(WEXITSTATUS(status), 0);
}

}  // namespace
