// Reads the string attributes of an OpenEXR file's header (e.g. rlpbrt's "rlpbrt:spp"
// metadata) without OpenEXR: magic, version, then (name\0 type\0 int32 size, value)...
// up to an empty name. Returns an empty map if the file is not an EXR file.
#pragma once

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

namespace rlpbrt {
namespace test {

inline std::map<std::string, std::string> exrStringAttributes(const std::string& path) {
    std::map<std::string, std::string> out;
    std::ifstream in(path, std::ios::binary);
    std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (data.size() < 8 || std::memcmp(data.data(), "\x76\x2f\x31\x01", 4) != 0) return out;
    std::size_t pos = 8;
    auto cstr = [&](std::string* s) {
        std::size_t end = data.find('\0', pos);
        if (end == std::string::npos) return false;
        *s = data.substr(pos, end - pos);
        pos = end + 1;
        return true;
    };
    while (pos < data.size()) {
        std::string name, type;
        if (!cstr(&name) || name.empty() || !cstr(&type) || pos + 4 > data.size()) break;
        uint32_t size;
        std::memcpy(&size, data.data() + pos, 4);  // little-endian, as on the test machines
        pos += 4;
        if (size > data.size() - pos) break;
        if (type == "string") out[name] = data.substr(pos, size);
        pos += size;
    }
    return out;
}

}  // namespace test
}  // namespace rlpbrt
