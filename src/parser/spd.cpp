#include "parser/spd.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <sys/stat.h>

namespace rlpbrt {

namespace {

constexpr long long kMaxSpdBytes = 64ll << 20;

bool fail(std::string* error, const std::string& message) {
    if (error) *error = message;
    return false;
}

}  // namespace

bool readSpdFile(const std::string& path, std::vector<double>* pairs, std::string* error) {
    // Only regular files of sane size: a device such as /dev/zero would be read forever.
    struct stat st;
    if (stat(path.c_str(), &st) != 0) return fail(error, path + ": cannot open spectral data file");
    if (!S_ISREG(st.st_mode)) return fail(error, path + ": not a regular file");
    if (st.st_size > kMaxSpdBytes)
        return fail(error, path + ": spectral data file larger than " +
                               std::to_string(kMaxSpdBytes >> 20) + " MiB");
    std::ifstream in(path);
    if (!in) return fail(error, path + ": cannot open spectral data file");

    std::vector<double> values;
    std::string line;
    int lineNo = 0;
    while (std::getline(in, line)) {
        ++lineNo;
        std::size_t hash = line.find('#');
        if (hash != std::string::npos) line.resize(hash);
        std::istringstream words(line);
        std::string word;
        while (words >> word) {
            const char* begin = word.c_str();
            char* end = nullptr;
            errno = 0;
            double v = std::strtod(begin, &end);
            if (end == begin || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
                return fail(error, path + ":" + std::to_string(lineNo) +
                                       ": expected a number, found \"" + word + "\"");
            }
            values.push_back(v);
        }
    }
    if (in.bad()) return fail(error, path + ": read error");
    if (values.empty()) return fail(error, path + ": no (wavelength, value) pairs");
    if (values.size() % 2 != 0) {
        return fail(error, path + ": odd number of values (" + std::to_string(values.size()) +
                               "); expected (wavelength, value) pairs");
    }
    pairs->insert(pairs->end(), values.begin(), values.end());
    return true;
}

}  // namespace rlpbrt
