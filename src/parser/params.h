// Typed parameter lists of pbrt-v3 directives ("float fov" [45], "rgb Kd" [.5 .5 .5], ...).
// Standard library only. Every parameter keeps its own location and a "used" flag so that
// the consumer can report unused parameters at the right place.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "parser/diagnostics.h"

namespace rlpbrt {

// Parameter types after synonyms are resolved: point=point3, vector=vector3,
// normal=normal3, color=rgb.
enum class ParamType {
    Integer, Float, Point2, Vector2, Point3, Vector3, Normal3,
    RGB, XYZ, Blackbody, Spectrum, Bool, String, Texture
};

const char* paramTypeName(ParamType t);
// Parses a declared type name ("point", "color", ...); false if unknown.
bool parseParamType(const std::string& name, ParamType* out);
// Number of values per element (point3: 3, rgb: 3, blackbody: 2, spectrum: 2, ...).
int paramTypeArity(ParamType t);
// True for the types that describe a spectral distribution (rgb, xyz, blackbody, spectrum).
inline bool isSpectral(ParamType t) {
    return t == ParamType::RGB || t == ParamType::XYZ || t == ParamType::Blackbody ||
           t == ParamType::Spectrum;
}

struct Param {
    ParamType type = ParamType::Float;
    std::string name;
    FileLoc loc;                       // location of the "type name" string
    std::vector<double> numbers;       // numeric types; spectrum: (lambda, value) pairs,
                                       // read from the .spd file when one is named
    std::vector<std::string> strings;  // string and texture
    std::vector<uint8_t> bools;        // bool
    std::string spectrumFile;          // spectrum given as a file: its resolved path
    mutable bool used = false;

    std::size_t size() const;  // number of values (numbers, strings or bools)
};

using Float3 = std::array<float, 3>;
using Float2 = std::array<float, 2>;

// An ordered list of parameters. Adding a parameter whose name is already present replaces
// the earlier one (pbrt-v3's rule). Getters mark what they read as used; a getter that finds
// the name with a different type reports an error at the parameter's location (through the
// Diagnostics given at construction, if any) and returns the default.
class ParamList {
public:
    ParamList() = default;
    explicit ParamList(Diagnostics* diag) : diag_(diag) {}

    void add(Param p);
    void setDiagnostics(Diagnostics* d) { diag_ = d; }
    Diagnostics* diagnostics() const { return diag_; }

    const std::vector<Param>& params() const { return params_; }
    bool empty() const { return params_.empty(); }
    // The parameter of that name (any type), or null. Does not mark it used.
    const Param* find(const std::string& name) const;
    bool has(const std::string& name) const { return find(name) != nullptr; }

    // Single values: the first value, or `def` when absent.
    float getFloat(const std::string& name, float def) const;
    int getInt(const std::string& name, int def) const;
    bool getBool(const std::string& name, bool def) const;
    std::string getString(const std::string& name, const std::string& def) const;
    Float3 getPoint3(const std::string& name, Float3 def) const;
    Float3 getVector3(const std::string& name, Float3 def) const;
    Float3 getNormal3(const std::string& name, Float3 def) const;
    Float2 getPoint2(const std::string& name, Float2 def) const;
    // The name of a "texture" parameter, or "" when absent.
    std::string getTexture(const std::string& name) const;
    // A file-name parameter resolved relative to the directory of the file it appeared in
    // (absolute names are kept); "" when absent.
    std::string getFilename(const std::string& name) const;

    // Arrays (empty when absent). Integers are checked to fit in int.
    std::vector<float> getFloats(const std::string& name) const;
    std::vector<int> getInts(const std::string& name) const;
    std::vector<Float3> getPoint3s(const std::string& name) const;
    std::vector<Float3> getNormal3s(const std::string& name) const;
    std::vector<Float3> getVector3s(const std::string& name) const;
    std::vector<Float2> getPoint2s(const std::string& name) const;
    std::vector<std::string> getStrings(const std::string& name) const;

    // A spectral parameter (rgb/xyz/blackbody/spectrum), or null; marks it used.
    const Param* getSpectral(const std::string& name) const;

    // Warn (at each parameter's location) about every parameter not read by any getter.
    // `context` names the consumer, e.g. `shape "sphere"`.
    void reportUnused(const std::string& context) const;
    // Mark every parameter used (for directives whose parameters are deliberately ignored).
    void markAllUsed() const;

private:
    const Param* lookup(const std::string& name, std::initializer_list<ParamType> types) const;
    void typeError(const Param& p, const char* expected) const;

    std::vector<Param> params_;
    // Name -> position in params_: keeps add() and find() constant-time, so that a directive
    // with very many parameters is not quadratic.
    std::unordered_map<std::string, std::size_t> index_;
    Diagnostics* diag_ = nullptr;
};

}  // namespace rlpbrt
