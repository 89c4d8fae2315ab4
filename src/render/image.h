// An in-memory image of float channels, row-major, top row first.
#pragma once

#include <string>
#include <vector>

namespace rlpbrt {

struct Image {
    int width = 0, height = 0, channels = 0;
    std::vector<float> pixels;  // width * height * channels
    float& at(int x, int y, int c) { return pixels[(size_t(y) * width + x) * channels + c]; }
    float at(int x, int y, int c) const { return pixels[(size_t(y) * width + x) * channels + c]; }
    bool empty() const { return pixels.empty(); }
};

}  // namespace rlpbrt
