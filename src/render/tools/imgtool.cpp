// rlpbrt-imgtool: image utilities for tests, benchmarks and the demo.
//   rlpbrt-imgtool compare TEST REF   prints relmse_trim, block_bias and nonfinite as JSON
//   rlpbrt-imgtool pair A B REF       two renders of one estimator (independent seeds): their
//                                     error without the reference's noise (pairRelMse), each
//                                     one's relmse_trim against REF, and the difference, an
//                                     estimate of REF's own error, as JSON
//   rlpbrt-imgtool convert IN OUT     converts between formats (tone: PNG is sRGB, clamped)
//   rlpbrt-imgtool side-by-side LEFT RIGHT OUT [CAPTION_LEFT CAPTION_RIGHT]
//                                     the two images (same size) next to each other, each
//                                     with its caption below ('|' or a newline starts a line)
#include <algorithm>
#include <cstdio>
#include <string>

#include "render/image_io.h"
#include "render/metrics.h"
#include "render/tools/caption.h"

using namespace rlpbrt;

namespace {

const char* kUsage =
    "usage: rlpbrt-imgtool compare TEST REF | pair A B REF | convert IN OUT |\n"
    "       side-by-side LEFT RIGHT OUT [CAPTION_LEFT CAPTION_RIGHT]\n";

bool read(const char* path, Image* img) {
    std::string err;
    if (readImage(path, img, &err)) return true;
    std::fprintf(stderr, "%s: error: %s\n", path, err.c_str());
    return false;
}

bool write(const char* path, const Image& img) {
    std::string err;
    if (writeImage(path, img, {}, &err)) return true;
    std::fprintf(stderr, "%s: error: %s\n", path, err.c_str());
    return false;
}

bool sameSize(const Image& a, const Image& b) {
    if (a.width == b.width && a.height == b.height) return true;
    std::fprintf(stderr, "error: image sizes differ: %dx%d vs %dx%d\n", a.width, a.height,
                 b.width, b.height);
    return false;
}

int compare(const char* testPath, const char* refPath) {
    Image a, b;
    if (!read(testPath, &a) || !read(refPath, &b)) return 1;
    if (!sameSize(a, b)) return 1;
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

int pair(const char* aPath, const char* bPath, const char* refPath) {
    Image a, b, ref;
    if (!read(aPath, &a) || !read(bPath, &b) || !read(refPath, &ref)) return 1;
    if (!sameSize(a, b) || !sameSize(a, ref)) return 1;
    const double pairError = pairRelMse(a, b, ref);
    const double ea = relMseTrimmed(a, ref), eb = relMseTrimmed(b, ref);
    std::printf("{\"pair_relmse\": %.9g, \"relmse_a\": %.9g, \"relmse_b\": %.9g, "
                "\"reference_error\": %.9g}\n",
                pairError, ea, eb, 0.5 * (ea + eb) - pairError);
    return 0;
}

// LEFT | gap | RIGHT on a black background, each caption in white on a strip below its
// image (font scale 2 for images at least 200 pixels wide, else 1).
int sideBySide(const char* leftPath, const char* rightPath, const char* outPath,
               std::string leftCaption, std::string rightCaption) {
    Image a, b;
    if (!read(leftPath, &a) || !read(rightPath, &b)) return 1;
    if (!sameSize(a, b)) return 1;
    for (std::string* c : {&leftCaption, &rightCaption})
        std::replace(c->begin(), c->end(), '|', '\n');
    const int gap = 4, pad = 6, scale = a.width >= 200 ? 2 : 1;
    const bool captions = !leftCaption.empty() || !rightCaption.empty();
    const int lines = std::max(captionLines(leftCaption), captionLines(rightCaption));
    const int strip = captions ? 2 * pad + (lines * CaptionLineHeight - 2) * scale : 0;
    Image out;
    out.width = 2 * a.width + gap;
    out.height = a.height + strip;
    out.channels = 3;
    out.pixels.assign(size_t(out.width) * out.height * 3, 0.f);
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            for (int c = 0; c < 3; ++c) {
                out.at(x, y, c) = a.at(x, y, c);
                out.at(a.width + gap + x, y, c) = b.at(x, y, c);
            }
    drawCaption(&out, pad, a.height + pad, leftCaption, scale, 1.f);
    drawCaption(&out, a.width + gap + pad, a.height + pad, rightCaption, scale, 1.f);
    for (const std::string* c : {&leftCaption, &rightCaption})
        if (captionWidth(*c, scale) > a.width - pad)
            std::fprintf(stderr, "warning: caption \"%s\" is wider than its image\n", c->c_str());
    return write(outPath, out) ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
    const std::string cmd = argc > 1 ? argv[1] : "";
    if (cmd == "compare" && argc == 4) return compare(argv[2], argv[3]);
    if (cmd == "pair" && argc == 5) return pair(argv[2], argv[3], argv[4]);
    if (cmd == "convert" && argc == 4) {
        Image a;
        return read(argv[2], &a) && write(argv[3], a) ? 0 : 1;
    }
    if (cmd == "side-by-side" && (argc == 5 || argc == 7))
        return sideBySide(argv[2], argv[3], argv[4], argc == 7 ? argv[5] : "",
                          argc == 7 ? argv[6] : "");
    std::fprintf(stderr, "%s", kUsage);
    return 2;
}
