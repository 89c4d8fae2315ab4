#include "guiding/field_io.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace rlpbrt::guiding::fieldio {

bool writeFile(const std::string& path, const std::string& data, std::string* error) {
    const std::string tmp = path + ".tmp";
    {
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) {
            *error = "cannot open '" + tmp + "' for writing";
            return false;
        }
        f.write(data.data(), std::streamsize(data.size()));
        f.flush();
        if (!f) {
            *error = "cannot write '" + tmp + "'";
            std::remove(tmp.c_str());
            return false;
        }
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        *error = "cannot rename '" + tmp + "' to '" + path + "'";
        std::remove(tmp.c_str());
        return false;
    }
    return true;
}

bool readFile(const std::string& path, std::string* data, std::string* error) {
    std::ifstream f(path, std::ios::binary);
    if (!f) {
        *error = "cannot open '" + path + "'";
        return false;
    }
    std::ostringstream ss;
    ss << f.rdbuf();
    *data = ss.str();
    return true;
}

std::string fileKind(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    char head[64] = {};
    f.read(head, sizeof(head));
    const size_t n = size_t(f.gcount());
    // OpenVDB files start with the int32 magic 0x56444220 ("VDB ") in little-endian order.
    if (n >= 4 && head[0] == ' ' && head[1] == 'B' && head[2] == 'D' && head[3] == 'V')
        return "vdb";
    if (n >= 16 && std::memcmp(head, kMagic, 8) == 0) {
        std::string rest(head, n);
        Reader r(rest);
        r.skip(12);  // magic, version
        uint32_t len = r.u32();
        if (len > 0 && len <= 32 && 16 + len <= n) return rest.substr(16, len);
    }
    return "";
}

std::string packDoubles(const std::vector<double>& v) {
    Writer w;
    w.data.reserve(v.size() * 8);
    for (double d : v) w.f64(d);
    return std::move(w.data);
}

std::string packU64(const std::vector<uint64_t>& v) {
    Writer w;
    w.data.reserve(v.size() * 8);
    for (uint64_t u : v) w.u64(u);
    return std::move(w.data);
}

bool unpackDoubles(const std::string& s, size_t count, std::vector<double>* out) {
    if (s.size() != count * 8) return false;
    Reader r(s);
    out->resize(count);
    for (size_t i = 0; i < count; ++i) (*out)[i] = r.f64();
    return r.ok();
}

bool unpackU64(const std::string& s, size_t count, std::vector<uint64_t>* out) {
    if (s.size() != count * 8) return false;
    Reader r(s);
    out->resize(count);
    for (size_t i = 0; i < count; ++i) (*out)[i] = r.u64();
    return r.ok();
}

bool sameScene(const glm::vec3& savedMin, const glm::vec3& savedMax, double savedArea,
               const glm::vec3& bmin, const glm::vec3& bmax, double area, std::string* why) {
    char buf[512];
    if (savedMin != bmin || savedMax != bmax) {
        std::snprintf(buf, sizeof(buf),
                      "made for another scene: bounds (%g %g %g)-(%g %g %g), this scene has "
                      "(%g %g %g)-(%g %g %g)",
                      savedMin.x, savedMin.y, savedMin.z, savedMax.x, savedMax.y, savedMax.z,
                      bmin.x, bmin.y, bmin.z, bmax.x, bmax.y, bmax.z);
        *why = buf;
        return false;
    }
    if (!(std::abs(savedArea - area) <= 1e-9 * std::max(std::abs(area), 1e-30))) {
        std::snprintf(buf, sizeof(buf),
                      "made for another scene: surface area %.17g, this scene has %.17g",
                      savedArea, area);
        *why = buf;
        return false;
    }
    return true;
}

}  // namespace rlpbrt::guiding::fieldio
