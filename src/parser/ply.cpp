// PLY reader: header parsing, bounds checks against the file size before any allocation, and
// decoding of ascii / binary bodies into a triangle mesh.
#include "parser/ply.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <sys/stat.h>

namespace rlpbrt {
namespace {

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };
enum class Format { Ascii, BinaryLittleEndian, BinaryBigEndian };

int scalarSize(Scalar s) {
    switch (s) {
    case Scalar::Int8: case Scalar::UInt8: return 1;
    case Scalar::Int16: case Scalar::UInt16: return 2;
    case Scalar::Int32: case Scalar::UInt32: case Scalar::Float32: return 4;
    case Scalar::Float64: return 8;
    }
    return 1;
}

bool isIntegral(Scalar s) { return s != Scalar::Float32 && s != Scalar::Float64; }

bool parseScalar(const std::string& name, Scalar* out) {
    struct Entry { const char* name; Scalar type; };
    static const Entry table[] = {
        {"char", Scalar::Int8},     {"int8", Scalar::Int8},       {"uchar", Scalar::UInt8},
        {"uint8", Scalar::UInt8},   {"short", Scalar::Int16},     {"int16", Scalar::Int16},
        {"ushort", Scalar::UInt16}, {"uint16", Scalar::UInt16},   {"int", Scalar::Int32},
        {"int32", Scalar::Int32},   {"uint", Scalar::UInt32},     {"uint32", Scalar::UInt32},
        {"float", Scalar::Float32}, {"float32", Scalar::Float32}, {"double", Scalar::Float64},
        {"float64", Scalar::Float64}};
    for (const Entry& e : table)
        if (name == e.name) {
            *out = e.type;
            return true;
        }
    return false;
}

struct Property {
    std::string name;
    bool isList = false;
    Scalar type = Scalar::Float32;       // value type (list item type for lists)
    Scalar countType = Scalar::UInt8;    // lists only
};

struct Element {
    std::string name;
    uint64_t count = 0;
    std::vector<Property> props;
    int headerLine = 0;
};

struct Header {
    Format format = Format::Ascii;
    std::vector<Element> elements;
    size_t bodyOffset = 0;  // byte offset of the first body byte
    int bodyLine = 1;       // line number of the first body line (ascii)
};

std::string quoted(const std::string& s) {
    // Keep messages short even for absurd tokens.
    if (s.size() > 40) return "'" + s.substr(0, 40) + "...'";
    return "'" + s + "'";
}

std::string atLine(int line) { return " (PLY line " + std::to_string(line) + ")"; }

bool parseCount(const std::string& tok, uint64_t* out) {
    if (tok.empty() || tok.size() > 20) return false;
    auto r = std::from_chars(tok.data(), tok.data() + tok.size(), *out);
    return r.ec == std::errc() && r.ptr == tok.data() + tok.size();
}

// Parses the header of a PLY file in [data, data + size).
bool parseHeader(const char* data, size_t size, Header* h, std::string* error) {
    size_t pos = 0;
    int line = 0;
    bool haveFormat = false, done = false;
    std::vector<std::string> toks;
    while (!done) {
        if (size == 0) {
            *error = "not a PLY file (empty file)";
            return false;
        }
        if (pos >= size) {
            *error = "PLY header is not terminated by 'end_header'" + atLine(line);
            return false;
        }
        const char* nl = static_cast<const char*>(std::memchr(data + pos, '\n', size - pos));
        size_t end = nl ? size_t(nl - data) : size;
        ++line;
        // Tokenize [pos, end).
        toks.clear();
        size_t i = pos;
        while (i < end) {
            while (i < end && (data[i] == ' ' || data[i] == '\t' || data[i] == '\r')) ++i;
            size_t b = i;
            while (i < end && data[i] != ' ' && data[i] != '\t' && data[i] != '\r') ++i;
            if (i > b) {
                toks.emplace_back(data + b, i - b);
                if (toks[0] == "comment" || toks[0] == "obj_info") break;
            }
        }
        size_t next = nl ? end + 1 : size;
        if (line == 1) {
            if (toks.size() != 1 || toks[0] != "ply") {
                *error = "not a PLY file (first line must be 'ply')";
                return false;
            }
        } else if (toks.empty() || toks[0] == "comment" || toks[0] == "obj_info") {
            // Blank line or comment.
        } else if (toks[0] == "format") {
            if (haveFormat) {
                *error = "duplicate 'format' line" + atLine(line);
                return false;
            }
            if (toks.size() != 3) {
                *error = "malformed 'format' line" + atLine(line);
                return false;
            }
            if (toks[1] == "ascii") h->format = Format::Ascii;
            else if (toks[1] == "binary_little_endian") h->format = Format::BinaryLittleEndian;
            else if (toks[1] == "binary_big_endian") h->format = Format::BinaryBigEndian;
            else {
                *error = "unknown PLY format " + quoted(toks[1]) + atLine(line);
                return false;
            }
            if (toks[2] != "1.0" && toks[2] != "1") {
                *error = "unsupported PLY version " + quoted(toks[2]) + atLine(line);
                return false;
            }
            haveFormat = true;
        } else if (toks[0] == "element") {
            Element e;
            if (toks.size() != 3 || !parseCount(toks[2], &e.count)) {
                *error = "malformed 'element' line (expected 'element <name> <count>')" +
                         atLine(line);
                return false;
            }
            e.name = toks[1];
            e.headerLine = line;
            for (const Element& o : h->elements)
                if (o.name == e.name) {
                    *error = "duplicate element " + quoted(e.name) + atLine(line);
                    return false;
                }
            h->elements.push_back(std::move(e));
        } else if (toks[0] == "property") {
            if (h->elements.empty()) {
                *error = "'property' before any 'element'" + atLine(line);
                return false;
            }
            Property p;
            if (toks.size() == 5 && toks[1] == "list") {
                p.isList = true;
                if (!parseScalar(toks[2], &p.countType) || !parseScalar(toks[3], &p.type)) {
                    *error = "unknown property type in list property " + quoted(toks[4]) +
                             atLine(line);
                    return false;
                }
                if (!isIntegral(p.countType)) {
                    *error = "list count type of property " + quoted(toks[4]) +
                             " must be an integer type" + atLine(line);
                    return false;
                }
                p.name = toks[4];
            } else if (toks.size() == 3 && toks[1] != "list") {
                if (!parseScalar(toks[1], &p.type)) {
                    *error = "unknown property type " + quoted(toks[1]) + atLine(line);
                    return false;
                }
                p.name = toks[2];
            } else {
                *error = "malformed 'property' line" + atLine(line);
                return false;
            }
            for (const Property& o : h->elements.back().props)
                if (o.name == p.name) {
                    *error = "duplicate property " + quoted(p.name) + atLine(line);
                    return false;
                }
            h->elements.back().props.push_back(std::move(p));
        } else if (toks[0] == "end_header") {
            if (toks.size() != 1) {
                *error = "malformed 'end_header' line" + atLine(line);
                return false;
            }
            done = true;
        } else {
            *error = "unknown PLY header keyword " + quoted(toks[0]) + atLine(line);
            return false;
        }
        pos = next;
    }
    if (!haveFormat) {
        *error = "PLY header has no 'format' line";
        return false;
    }
    h->bodyOffset = pos;
    h->bodyLine = line + 1;
    return true;
}

// Byte-swaps `n` bytes in place.
inline void swapBytes(unsigned char* b, int n) {
    for (int i = 0; i < n / 2; ++i) std::swap(b[i], b[n - 1 - i]);
}

// Sequential reader of values from a binary or ascii body. Every read checks bounds; the
// first failure records a message and all later reads fail.
class BodyReader {
public:
    BodyReader(const char* data, size_t size, const Header& h)
        : data_(data), size_(size), pos_(h.bodyOffset), line_(h.bodyLine), format_(h.format) {
        unsigned one = 1;
        unsigned char first;
        std::memcpy(&first, &one, 1);
        bool hostLittle = first == 1;
        swap_ = (format_ == Format::BinaryLittleEndian && !hostLittle) ||
                (format_ == Format::BinaryBigEndian && hostLittle);
    }

    bool ascii() const { return format_ == Format::Ascii; }
    bool swapped() const { return swap_; }
    const char* cursor() const { return data_ + pos_; }
    size_t offset() const { return pos_; }
    void advance(size_t n) { pos_ += n; }
    size_t remaining() const { return size_ - pos_; }
    const std::string& error() const { return error_; }

    // Location suffix of the current read position.
    std::string where() const {
        if (ascii()) return atLine(line_);
        return " (byte offset " + std::to_string(pos_) + ")";
    }
    bool fail(const std::string& msg) {
        if (error_.empty()) error_ = msg + where();
        return false;
    }

    // Reads a value of type `t` as a double (ascii: any number; non-finite values allowed).
    bool readReal(Scalar t, double* out) {
        if (ascii()) {
            const char *b = nullptr, *e = nullptr;
            if (!token(&b, &e)) return false;
            if (isIntegral(t)) {
                int64_t v;
                if (!parseInt(b, e, &v)) return false;
                *out = double(v);
                return true;
            }
            if (*b == '+') ++b;
            auto r = std::from_chars(b, e, *out);
            if (r.ec == std::errc::result_out_of_range) {
                *out = std::strtod(std::string(b, e).c_str(), nullptr);  // +-HUGE_VAL or 0
                return true;
            }
            if (r.ec != std::errc() || r.ptr != e) return fail("invalid number " + tok(b, e));
            return true;
        }
        unsigned char buf[8];
        if (!raw(t, buf)) return false;
        switch (t) {
        case Scalar::Float32: { float f; std::memcpy(&f, buf, 4); *out = f; return true; }
        case Scalar::Float64: { std::memcpy(out, buf, 8); return true; }
        default: { int64_t v = decodeInt(t, buf); *out = double(v); return true; }
        }
    }

    // Reads an integer of integral type `t` (ascii: the token must be an integer).
    bool readInt(Scalar t, int64_t* out) {
        if (ascii()) {
            const char *b = nullptr, *e = nullptr;
            if (!token(&b, &e)) return false;
            return parseInt(b, e, out);
        }
        unsigned char buf[8];
        if (!raw(t, buf)) return false;
        *out = decodeInt(t, buf);
        return true;
    }

    // Skips `n` values of type `t` (bounds-checked before looping).
    bool skip(Scalar t, uint64_t n) {
        if (n == 0) return true;
        if (ascii()) {
            // Each value needs at least one character plus a separator (except the last).
            if (n - 1 > remaining() / 2) return fail("list longer than the rest of the file");
            const char *b = nullptr, *e = nullptr;
            for (uint64_t i = 0; i < n; ++i)
                if (!token(&b, &e)) return false;
            return true;
        }
        uint64_t sz = uint64_t(scalarSize(t));
        if (n > remaining() / sz) return fail("unexpected end of file in list");
        pos_ += size_t(n * sz);
        return true;
    }

    // Checks that a list of `n` values of type `t` can still fit in the file.
    bool listFits(Scalar t, uint64_t n) {
        if (n == 0) return true;
        uint64_t minBytes = ascii() ? 2 : uint64_t(scalarSize(t));
        if (ascii() ? (n - 1 > remaining() / minBytes) : (n > remaining() / minBytes))
            return fail("list of " + std::to_string(n) + " values is longer than the rest of "
                        "the file");
        return true;
    }

private:
    std::string tok(const char* b, const char* e) { return quoted(std::string(b, e)); }

    bool parseInt(const char* b, const char* e, int64_t* out) {
        const char* s = b;
        if (s < e && *s == '+') ++s;
        auto r = std::from_chars(s, e, *out);
        if (r.ec != std::errc() || r.ptr != e) return fail("invalid integer " + tok(b, e));
        return true;
    }

    // Next whitespace-separated token; tracks line numbers.
    bool token(const char** b, const char** e) {
        while (pos_ < size_) {
            char c = data_[pos_];
            if (c == '\n') ++line_;
            else if (c != ' ' && c != '\t' && c != '\r' && c != '\v' && c != '\f') break;
            ++pos_;
        }
        if (pos_ >= size_) return fail("unexpected end of file");
        size_t start = pos_;
        while (pos_ < size_) {
            char c = data_[pos_];
            if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f') break;
            ++pos_;
        }
        *b = data_ + start;
        *e = data_ + pos_;
        return true;
    }

    bool raw(Scalar t, unsigned char* buf) {
        int n = scalarSize(t);
        if (remaining() < size_t(n)) return fail("unexpected end of file");
        std::memcpy(buf, data_ + pos_, size_t(n));
        if (swap_) swapBytes(buf, n);
        pos_ += size_t(n);
        return true;
    }

    static int64_t decodeInt(Scalar t, const unsigned char* buf) {
        switch (t) {
        case Scalar::Int8: { int8_t v; std::memcpy(&v, buf, 1); return v; }
        case Scalar::UInt8: { uint8_t v; std::memcpy(&v, buf, 1); return v; }
        case Scalar::Int16: { int16_t v; std::memcpy(&v, buf, 2); return v; }
        case Scalar::UInt16: { uint16_t v; std::memcpy(&v, buf, 2); return v; }
        case Scalar::Int32: { int32_t v; std::memcpy(&v, buf, 4); return v; }
        case Scalar::UInt32: { uint32_t v; std::memcpy(&v, buf, 4); return v; }
        case Scalar::Float32: { float v; std::memcpy(&v, buf, 4); return int64_t(v); }
        case Scalar::Float64: { double v; std::memcpy(&v, buf, 8); return int64_t(v); }
        }
        return 0;
    }

    const char* data_;
    size_t size_;
    size_t pos_;
    int line_;
    Format format_;
    bool swap_ = false;
    std::string error_;
};

// Decodes a binary scalar of type `t` at `p` (byte-swapped if `swap`) as a double.
inline double decodeReal(Scalar t, const char* p, bool swap) {
    unsigned char b[8];
    int n = scalarSize(t);
    std::memcpy(b, p, size_t(n));
    if (swap) swapBytes(b, n);
    switch (t) {
    case Scalar::Int8: { int8_t v; std::memcpy(&v, b, 1); return v; }
    case Scalar::UInt8: return b[0];
    case Scalar::Int16: { int16_t v; std::memcpy(&v, b, 2); return v; }
    case Scalar::UInt16: { uint16_t v; std::memcpy(&v, b, 2); return v; }
    case Scalar::Int32: { int32_t v; std::memcpy(&v, b, 4); return v; }
    case Scalar::UInt32: { uint32_t v; std::memcpy(&v, b, 4); return v; }
    case Scalar::Float32: { float v; std::memcpy(&v, b, 4); return v; }
    case Scalar::Float64: { double v; std::memcpy(&v, b, 8); return v; }
    }
    return 0;
}

// Role of a vertex property.
enum class Role { None, X, Y, Z, NX, NY, NZ, U, V };

Role vertexRole(const std::string& n) {
    if (n == "x") return Role::X;
    if (n == "y") return Role::Y;
    if (n == "z") return Role::Z;
    if (n == "nx") return Role::NX;
    if (n == "ny") return Role::NY;
    if (n == "nz") return Role::NZ;
    if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s") return Role::U;
    if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t") return Role::V;
    return Role::None;
}

// Smallest number of body bytes one item of `e` can occupy.
uint64_t minItemBytes(const Element& e, Format f) {
    uint64_t n = 0;
    for (const Property& p : e.props) {
        if (f == Format::Ascii) n += 2;  // a digit and a separator
        else n += uint64_t(scalarSize(p.isList ? p.countType : p.type));
    }
    return n;
}

// Skips one item of an element (all its properties).
bool skipItem(BodyReader& r, const Element& e) {
    for (const Property& p : e.props) {
        if (p.isList) {
            int64_t n = 0;
            if (!r.readInt(p.countType, &n)) return false;
            if (n < 0) return r.fail("negative list count in element " + quoted(e.name));
            if (!r.skip(p.type, uint64_t(n))) return false;
        } else if (!r.skip(p.type, 1)) {
            return false;
        }
    }
    return true;
}

bool readVertices(BodyReader& r, const Element& e, PlyMesh* mesh) {
    std::vector<Role> roles(e.props.size(), Role::None);
    bool seen[9] = {};
    for (size_t i = 0; i < e.props.size(); ++i) {
        Role role = e.props[i].isList ? Role::None : vertexRole(e.props[i].name);
        if (role != Role::None && !seen[int(role)]) {
            roles[i] = role;
            seen[int(role)] = true;
        }
    }
    if (!seen[int(Role::X)] || !seen[int(Role::Y)] || !seen[int(Role::Z)])
        return r.fail("element 'vertex' lacks one of the properties x, y, z");
    bool hasN = seen[int(Role::NX)] && seen[int(Role::NY)] && seen[int(Role::NZ)];
    bool hasUV = seen[int(Role::U)] && seen[int(Role::V)];
    size_t n = size_t(e.count);
    if (n == 0) return true;  // (faces then fail: no index can be in range)
    mesh->positions.resize(3 * n);
    if (hasN) mesh->normals.resize(3 * n);
    if (hasUV) mesh->uvs.resize(2 * n);

    // Fast path: binary vertices without lists have a fixed stride.
    bool fixedStride = !r.ascii();
    size_t stride = 0;
    for (const Property& p : e.props) {
        fixedStride = fixedStride && !p.isList;
        stride += size_t(scalarSize(p.type));
    }
    if (fixedStride) {
        struct Field { size_t offset; Scalar type; float* dst; size_t dstStride; };
        std::vector<Field> fields;
        size_t off = 0;
        for (size_t i = 0; i < e.props.size(); ++i) {
            Role role = roles[i];
            float* dst = nullptr;
            size_t dstStride = 3;
            if (role >= Role::X && role <= Role::Z)
                dst = mesh->positions.data() + (int(role) - int(Role::X));
            else if (role >= Role::NX && role <= Role::NZ && hasN)
                dst = mesh->normals.data() + (int(role) - int(Role::NX));
            else if ((role == Role::U || role == Role::V) && hasUV) {
                dst = mesh->uvs.data() + (int(role) - int(Role::U));
                dstStride = 2;
            }
            if (dst) fields.push_back({off, e.props[i].type, dst, dstStride});
            off += size_t(scalarSize(e.props[i].type));
        }
        if (n > r.remaining() / stride) return r.fail("unexpected end of file in vertices");
        const char* base = r.cursor();
        bool swap = r.swapped();
        for (size_t v = 0; v < n; ++v) {
            const char* item = base + v * stride;
            for (const Field& f : fields) {
                float x;
                if (f.type == Scalar::Float32 && !swap) std::memcpy(&x, item + f.offset, 4);
                else x = float(decodeReal(f.type, item + f.offset, swap));
                if (!std::isfinite(x)) {
                    r.advance(size_t(item - base));
                    return r.fail("non-finite vertex value in vertex " + std::to_string(v));
                }
                f.dst[v * f.dstStride] = x;
            }
        }
        r.advance(n * stride);
        return true;
    }

    for (size_t v = 0; v < n; ++v) {
        for (size_t i = 0; i < e.props.size(); ++i) {
            const Property& p = e.props[i];
            if (p.isList) {
                int64_t c;
                if (!r.readInt(p.countType, &c)) return false;
                if (c < 0) return r.fail("negative list count in element 'vertex'");
                if (!r.skip(p.type, uint64_t(c))) return false;
                continue;
            }
            Role role = roles[i];
            if (role == Role::None || (role >= Role::NX && role <= Role::NZ && !hasN) ||
                ((role == Role::U || role == Role::V) && !hasUV)) {
                if (!r.skip(p.type, 1)) return false;
                continue;
            }
            double d;
            if (!r.readReal(p.type, &d)) return false;
            float f = float(d);
            if (!std::isfinite(f))
                return r.fail("non-finite value for vertex property " + quoted(p.name) +
                              " of vertex " + std::to_string(v));
            switch (role) {
            case Role::X: case Role::Y: case Role::Z:
                mesh->positions[3 * v + size_t(int(role) - int(Role::X))] = f; break;
            case Role::NX: case Role::NY: case Role::NZ:
                mesh->normals[3 * v + size_t(int(role) - int(Role::NX))] = f; break;
            case Role::U: case Role::V:
                mesh->uvs[2 * v + size_t(int(role) - int(Role::U))] = f; break;
            default: break;
            }
        }
    }
    return true;
}

// Appends the fan triangulation of polygon `poly` and counts quads / larger polygons.
inline void addPolygon(const uint32_t* poly, size_t n, PlyMesh* mesh) {
    if (n == 4) ++mesh->quadCount;
    else if (n > 4) ++mesh->polygonCount;
    for (size_t k = 1; k + 1 < n; ++k) {
        mesh->indices.push_back(poly[0]);
        mesh->indices.push_back(poly[k]);
        mesh->indices.push_back(poly[k + 1]);
    }
}

// Fast path for binary face elements whose only property is the index list.
bool readBinaryFaceList(BodyReader& r, const Property& p, uint64_t faceCount,
                        uint64_t vertexCount, PlyMesh* mesh) {
    const char* base = r.cursor();
    const char* cur = base;
    const char* end = base + r.remaining();
    size_t countSize = size_t(scalarSize(p.countType)), idxSize = size_t(scalarSize(p.type));
    bool swap = r.swapped();
    std::vector<uint32_t> poly;
    for (uint64_t f = 0; f < faceCount; ++f) {
        const char* faceStart = cur;
        auto failAt = [&](const std::string& msg) {
            r.advance(size_t(faceStart - base));
            return r.fail(msg);
        };
        if (size_t(end - cur) < countSize) return failAt("unexpected end of file in faces");
        double c = decodeReal(p.countType, cur, swap);
        cur += countSize;
        if (c < 3)
            return failAt("face " + std::to_string(f) + " has " + std::to_string(int64_t(c)) +
                          " vertices (at least 3 needed)");
        size_t n = size_t(c);
        if (n > size_t(end - cur) / idxSize)
            return failAt("list of " + std::to_string(n) +
                          " values is longer than the rest of the file");
        poly.resize(n);
        for (size_t k = 0; k < n; ++k, cur += idxSize) {
            double idx = decodeReal(p.type, cur, swap);
            if (idx < 0 || idx >= double(vertexCount))
                return failAt("vertex index " + std::to_string(int64_t(idx)) + " of face " +
                              std::to_string(f) + " out of range (" +
                              std::to_string(vertexCount) + " vertices)");
            poly[k] = uint32_t(idx);
        }
        addPolygon(poly.data(), n, mesh);
    }
    r.advance(size_t(cur - base));
    return true;
}

bool readFaces(BodyReader& r, const Element& e, uint64_t vertexCount, PlyMesh* mesh) {
    int listIdx = -1;
    for (size_t i = 0; i < e.props.size(); ++i)
        if (e.props[i].name == "vertex_indices" || e.props[i].name == "vertex_index") {
            listIdx = int(i);
            break;
        }
    if (listIdx < 0) return r.fail("element 'face' has no 'vertex_indices' list");
    const Property& lp = e.props[size_t(listIdx)];
    if (!lp.isList || !isIntegral(lp.type))
        return r.fail("face property " + quoted(lp.name) + " must be a list of integers");
    mesh->indices.reserve(size_t(e.count) * 3);
    if (!r.ascii() && e.props.size() == 1) return readBinaryFaceList(r, lp, e.count,
                                                                     vertexCount, mesh);
    std::vector<uint32_t> poly;
    for (uint64_t f = 0; f < e.count; ++f) {
        for (size_t i = 0; i < e.props.size(); ++i) {
            const Property& p = e.props[i];
            if (int(i) != listIdx) {
                if (p.isList) {
                    int64_t c;
                    if (!r.readInt(p.countType, &c)) return false;
                    if (c < 0) return r.fail("negative list count in element 'face'");
                    if (!r.skip(p.type, uint64_t(c))) return false;
                } else if (!r.skip(p.type, 1)) {
                    return false;
                }
                continue;
            }
            int64_t c;
            if (!r.readInt(p.countType, &c)) return false;
            if (c < 3)
                return r.fail("face " + std::to_string(f) + " has " + std::to_string(c) +
                              " vertices (at least 3 needed)");
            if (!r.listFits(p.type, uint64_t(c))) return false;
            poly.resize(size_t(c));
            for (size_t k = 0; k < size_t(c); ++k) {
                int64_t idx;
                if (!r.readInt(p.type, &idx)) return false;
                if (idx < 0 || uint64_t(idx) >= vertexCount)
                    return r.fail("vertex index " + std::to_string(idx) + " of face " +
                                  std::to_string(f) + " out of range (" +
                                  std::to_string(vertexCount) + " vertices)");
                poly[k] = uint32_t(idx);
            }
            addPolygon(poly.data(), poly.size(), mesh);
        }
    }
    return true;
}

}  // namespace

bool readPlyFromMemory(const char* data, size_t size, PlyMesh* mesh, std::string* error) {
    *mesh = PlyMesh();
    std::string dummy;
    if (!error) error = &dummy;
    Header h;
    if (!parseHeader(data, size, &h, error)) return false;

    // Validate the elements against the body size before allocating anything.
    uint64_t body = size - h.bodyOffset;
    // Ascii: the last value of the file may lack a trailing separator.
    uint64_t budget = body + (h.format == Format::Ascii ? 1 : 0);
    uint64_t needed = 0;
    const Element* vertexEl = nullptr;
    const Element* faceEl = nullptr;
    for (const Element& e : h.elements) {
        uint64_t minBytes = minItemBytes(e, h.format);
        if (minBytes > 0 && e.count > 0) {
            if (e.count > (budget - needed) / minBytes) {
                *error = "element " + quoted(e.name) + " declares " + std::to_string(e.count) +
                         " items, more than the " + std::to_string(body) +
                         " body bytes can hold" + atLine(e.headerLine);
                return false;
            }
            needed += e.count * minBytes;
        }
        if (e.name == "vertex") vertexEl = &e;
        if (e.name == "face") faceEl = &e;
    }
    if (!vertexEl) {
        *error = "PLY file has no 'vertex' element";
        return false;
    }
    if (!faceEl || faceEl->count == 0) {
        *error = "PLY file has no faces";
        return false;
    }
    if (vertexEl->count > std::numeric_limits<uint32_t>::max()) {
        *error = "too many vertices" + atLine(vertexEl->headerLine);
        return false;
    }

    BodyReader r(data, size, h);
    for (const Element& e : h.elements) {
        bool ok = true;
        if (&e == vertexEl) {
            ok = readVertices(r, e, mesh);
        } else if (&e == faceEl) {
            ok = readFaces(r, e, vertexEl->count, mesh);
        } else if (!e.props.empty()) {
            for (uint64_t i = 0; i < e.count && ok; ++i) ok = skipItem(r, e);
        }
        if (!ok) {
            *error = r.error();
            *mesh = PlyMesh();
            return false;
        }
    }
    return true;
}

bool readPly(const std::string& path, PlyMesh* mesh, std::string* error) {
    std::string dummy;
    if (!error) error = &dummy;
    // Only regular files: a FIFO would block and a device would never end.
    struct stat st;
    if (stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
        *error = "cannot read '" + path + "': not a regular file";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        *error = "cannot open '" + path + "': " + std::strerror(errno);
        return false;
    }
    in.seekg(0, std::ios::end);
    std::streamoff len = in.tellg();
    in.seekg(0, std::ios::beg);
    if (len < 0) {
        *error = "cannot read '" + path + "'";
        return false;
    }
    std::unique_ptr<char[]> buf(new char[size_t(len) + 1]);  // uninitialised: no memset
    if (len > 0 && !in.read(buf.get(), len)) {
        *error = "cannot read '" + path + "'";
        return false;
    }
    return readPlyFromMemory(buf.get(), size_t(len), mesh, error);
}

}  // namespace rlpbrt
