// --curve FILE.csv --ref REF.exr: an error-over-time curve written when the render ends.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

#include <gtest/gtest.h>

namespace {

std::string tempDir() {
    char tmpl[] = "/tmp/rlpbrt-curve-XXXXXX";
    const char* d = mkdtemp(tmpl);
    return d ? d : "/tmp";
}

int run(const std::string& args) {
    std::string cmd = "timeout -k 5 300 '" + std::string(RLPBRT_BINARY) + "' '" +
                      std::string(RLPBRT_SOURCE_DIR) + "/scenes/demo/demo.pbrt' --quiet " + args +
                      " 2>/dev/null";
    int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool exists(const std::string& path) {
    struct stat st;
    return stat(path.c_str(), &st) == 0;
}

}  // namespace

// Rows: header, then spp increasing to the final spp, seconds non-decreasing, relMSE finite;
// against a 32-spp reference the error at 8 spp is below half the error at 1 spp (the expected
// ratio is 1/8 + 1/32 over 1 + 1/32 = 0.15 for an unbiased estimator; 0.5 leaves room for the
// trimming and the noise of the error estimate itself).
TEST(Curve, RowsPerPassAgainstReference) {
    const std::string dir = tempDir(), ref = dir + "/ref.exr", out = dir + "/out.exr",
                      csv = dir + "/curve.csv";
    ASSERT_EQ(run("--spp 32 --seed 7 -o " + ref), 0);
    ASSERT_EQ(run("--spp 8 --seed 1 -o " + out + " --ref " + ref + " --curve " + csv), 0);
    std::ifstream f(csv);
    std::string line;
    ASSERT_TRUE(std::getline(f, line));
    EXPECT_EQ(line, "seconds,spp,relmse");
    std::vector<double> secs, errs;
    std::vector<int> spps;
    while (std::getline(f, line)) {
        double s = 0, e = 0;
        int n = 0;
        ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%d,%lf", &s, &n, &e), 3) << line;
        secs.push_back(s);
        spps.push_back(n);
        errs.push_back(e);
    }
    ASSERT_GE(spps.size(), 2u);
    EXPECT_EQ(spps.front(), 1);
    EXPECT_EQ(spps.back(), 8);
    for (size_t i = 1; i < spps.size(); ++i) {
        EXPECT_GT(spps[i], spps[i - 1]);
        EXPECT_GE(secs[i], secs[i - 1]);
    }
    for (double e : errs) EXPECT_TRUE(std::isfinite(e) && e >= 0.0);
    EXPECT_LT(errs.back(), 0.5 * errs.front());
    for (const auto& p : {ref, out, csv}) std::remove(p.c_str());
    rmdir(dir.c_str());
}

// A reference of the wrong size is an error before rendering: no image, no curve.
TEST(Curve, MismatchedReferenceIsAnError) {
    const std::string dir = tempDir(), ref = dir + "/ref.exr", out = dir + "/out.exr",
                      csv = dir + "/curve.csv";
    // The demo scene renders at 320x240; a cropped render gives a smaller reference.
    ASSERT_EQ(run("--spp 1 -o " + ref), 0);
    const std::string small = dir + "/small.pbrt";
    {
        std::ofstream s(small);
        s << "Film \"image\" \"integer xresolution\" 8 \"integer yresolution\" 8\n"
             "WorldBegin\nWorldEnd\n";
    }
    std::string cmd = "'" + std::string(RLPBRT_BINARY) + "' '" + small + "' --quiet -o " + out +
                      " --ref " + ref + " --curve " + csv + " 2>/dev/null";
    int status = std::system(cmd.c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) != 0);
    EXPECT_FALSE(exists(out));
    EXPECT_FALSE(exists(csv));
    // --curve without --ref is refused by the command line parser.
    EXPECT_NE(run("--spp 1 -o " + out + " --curve " + csv), 0);
    EXPECT_FALSE(exists(csv));
    for (const auto& p : {ref, out, csv, small}) std::remove(p.c_str());
    rmdir(dir.c_str());
}
