// Little-endian binary serialisation helpers for saved guiding fields (docs/GUIDE_FILES.md)
// and the detection of what a file holds, so that loading a file of another backend gives a
// clear message. Standard library and GLM only.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace rlpbrt::guiding::fieldio {

// First 8 bytes of an rlpbrt binary field file; followed by u32 version and the backend name.
constexpr char kMagic[8] = {'R', 'L', 'P', 'B', 'G', 'U', 'I', 'D'};
constexpr uint32_t kVersion = 1;

// Appends little-endian values to a byte string.
class Writer {
public:
    void u32(uint32_t v) { put(v, 4); }
    void u64(uint64_t v) { put(v, 8); }
    void f32(float v) {
        uint32_t b;
        std::memcpy(&b, &v, 4);
        u32(b);
    }
    void f64(double v) {
        uint64_t b;
        std::memcpy(&b, &v, 8);
        u64(b);
    }
    void vec3(const glm::vec3& v) { f32(v.x), f32(v.y), f32(v.z); }
    void str(const std::string& s) {
        u32(uint32_t(s.size()));
        data.append(s);
    }
    void raw(const char* p, size_t n) { data.append(p, n); }
    // A byte string of any length (u64 length, then the bytes).
    void blob(const std::string& s) {
        u64(uint64_t(s.size()));
        data.append(s);
    }
    std::string data;

private:
    void put(uint64_t v, int n) {
        for (int i = 0; i < n; ++i) data.push_back(char((v >> (8 * i)) & 0xff));
    }
};

// Reads little-endian values; after the first read past the end ok() is false and every
// later read returns 0.
class Reader {
public:
    explicit Reader(const std::string& d) : data_(d) {}
    uint32_t u32() { return uint32_t(get(4)); }
    uint64_t u64() { return get(8); }
    float f32() {
        uint32_t b = u32();
        float v;
        std::memcpy(&v, &b, 4);
        return v;
    }
    double f64() {
        uint64_t b = u64();
        double v;
        std::memcpy(&v, &b, 8);
        return v;
    }
    glm::vec3 vec3() {
        glm::vec3 v;
        v.x = f32(), v.y = f32(), v.z = f32();
        return v;
    }
    std::string str(size_t maxLen = 4096) {
        uint32_t n = u32();
        if (!ok_ || n > maxLen || remaining() < n) {
            ok_ = false;
            return {};
        }
        std::string s = data_.substr(pos_, n);
        pos_ += n;
        return s;
    }
    // Writer::blob's byte string (empty and !ok() if it runs past the end).
    std::string blob() {
        const uint64_t n = u64();
        if (!ok_ || remaining() < n) {
            ok_ = false;
            return {};
        }
        std::string s = data_.substr(pos_, size_t(n));
        pos_ += size_t(n);
        return s;
    }
    bool ok() const { return ok_; }
    size_t remaining() const { return data_.size() - pos_; }
    bool skip(size_t n) {
        if (remaining() < n) return ok_ = false;
        pos_ += n;
        return true;
    }

private:
    uint64_t get(int n) {
        if (!ok_ || remaining() < size_t(n)) {
            ok_ = false;
            return 0;
        }
        uint64_t v = 0;
        for (int i = 0; i < n; ++i) v |= uint64_t(uint8_t(data_[pos_ + size_t(i)])) << (8 * i);
        pos_ += size_t(n);
        return v;
    }
    const std::string& data_;
    size_t pos_ = 0;
    bool ok_ = true;
};

// Writes `data` to `path` atomically (temporary file, then rename).
bool writeFile(const std::string& path, const std::string& data, std::string* error);
// Reads a whole file.
bool readFile(const std::string& path, std::string* data, std::string* error);
// What a file holds, from its first bytes: the backend name of an rlpbrt binary field
// ("hemi"), "vdb" for an OpenVDB file, "" if neither or unreadable.
std::string fileKind(const std::string& path);

// Tables as raw little-endian bytes (for the vdb file's metadata blobs).
std::string packDoubles(const std::vector<double>& v);
std::string packU64(const std::vector<uint64_t>& v);
bool unpackDoubles(const std::string& s, size_t count, std::vector<double>* out);
bool unpackU64(const std::string& s, size_t count, std::vector<uint64_t>* out);

// "<file>: made for another scene (bounds ... vs ...)" style comparisons of the fingerprint.
bool sameScene(const glm::vec3& savedMin, const glm::vec3& savedMax, double savedArea,
               const glm::vec3& bmin, const glm::vec3& bmax, double area, std::string* why);

}  // namespace rlpbrt::guiding::fieldio
