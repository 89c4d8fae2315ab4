// rlpbrt-imgtool: image utilities for tests and benchmarks.
//   rlpbrt-imgtool compare TEST REF   prints relmse_trim, block_bias and nonfinite as JSON
//   rlpbrt-imgtool convert IN OUT     converts between formats (tone: PNG is sRGB, clamped)
#include <cstdio>
#include <string>

#include "render/image_io.h"
#include "render/metrics.h"

using namespace rlpbrt;

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: rlpbrt-imgtool compare TEST REF | convert IN OUT\n");
        return 2;
    }
    std::string cmd = argv[1], err;
    Image a, b;
    if (!readImage(argv[2], &a, &err)) {
        std::fprintf(stderr, "%s: error: %s\n", argv[2], err.c_str());
        return 1;
    }
    if (cmd == "convert") {
        if (!writeImage(argv[3], a, {}, &err)) {
            std::fprintf(stderr, "%s: error: %s\n", argv[3], err.c_str());
            return 1;
        }
        return 0;
    }
    if (cmd != "compare") {
        std::fprintf(stderr, "unknown command \"%s\"\n", cmd.c_str());
        return 2;
    }
    if (!readImage(argv[3], &b, &err)) {
        std::fprintf(stderr, "%s: error: %s\n", argv[3], err.c_str());
        return 1;
    }
    if (a.width != b.width || a.height != b.height) {
        std::fprintf(stderr, "error: image sizes differ: %dx%d vs %dx%d\n", a.width, a.height,
                     b.width, b.height);
        return 1;
    }
    double mean = 0, refMean = 0;
    for (size_t i = 0; i < a.pixels.size(); ++i) {
        mean += a.pixels[i];
        refMean += b.pixels[i];
    }
    mean /= a.pixels.size();
    refMean /= b.pixels.size();
    std::printf("{\"relmse_trim\": %.9g, \"block_bias\": %.9g, \"nonfinite\": %s, "
                "\"mean\": %.9g, \"ref_mean\": %.9g}\n",
                relMseTrimmed(a, b), blockBias(a, b), hasNonFinite(a) ? "true" : "false", mean,
                refMean);
    return 0;
}
