// libFuzzer target: the .spd spectral data reader (through a temporary file: it reads paths).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <unistd.h>
#include <vector>

#include "parser/spd.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    static const std::string path = "/tmp/rlpbrt-fuzz-spd-" + std::to_string(getpid()) + ".spd";
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return 0;
    std::fwrite(data, 1, size, f);
    std::fclose(f);
    std::vector<double> pairs;
    std::string error;
    bool ok = rlpbrt::readSpdFile(path, &pairs, &error);
    if (ok) {
        if (pairs.empty() || pairs.size() % 2 != 0) __builtin_trap();
        for (double v : pairs)
            if (!std::isfinite(v)) __builtin_trap();  // NaN/Inf must be rejected
    } else if (error.empty()) {
        __builtin_trap();
    }
    return 0;
}
