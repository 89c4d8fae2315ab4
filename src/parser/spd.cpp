#include "parser/spd.h"

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace rlpbrt {

namespace {

bool fail(std::string* error, const std::string& message) {
    if (error) *error = message;
    return false;
}

}  // namespace

bool readSpdFile(const std::string& path, std::vector<double>* pairs, std::string* error) {
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
            if (end == begin || *end != '\0' || errno == ERANGE) {
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
