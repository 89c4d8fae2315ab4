#include "parser/params.h"

#include <climits>
#include <cmath>

namespace rlpbrt {

namespace {
struct TypeInfo {
    const char* name;
    ParamType type;
};
const TypeInfo kTypeNames[] = {
    {"integer", ParamType::Integer},   {"float", ParamType::Float},
    {"point2", ParamType::Point2},     {"vector2", ParamType::Vector2},
    {"point3", ParamType::Point3},     {"point", ParamType::Point3},
    {"vector3", ParamType::Vector3},   {"vector", ParamType::Vector3},
    {"normal3", ParamType::Normal3},   {"normal", ParamType::Normal3},
    {"rgb", ParamType::RGB},           {"color", ParamType::RGB},
    {"xyz", ParamType::XYZ},           {"blackbody", ParamType::Blackbody},
    {"spectrum", ParamType::Spectrum}, {"bool", ParamType::Bool},
    {"string", ParamType::String},     {"texture", ParamType::Texture},
};
}  // namespace

const char* paramTypeName(ParamType t) {
    switch (t) {
    case ParamType::Integer: return "integer";
    case ParamType::Float: return "float";
    case ParamType::Point2: return "point2";
    case ParamType::Vector2: return "vector2";
    case ParamType::Point3: return "point3";
    case ParamType::Vector3: return "vector3";
    case ParamType::Normal3: return "normal";
    case ParamType::RGB: return "rgb";
    case ParamType::XYZ: return "xyz";
    case ParamType::Blackbody: return "blackbody";
    case ParamType::Spectrum: return "spectrum";
    case ParamType::Bool: return "bool";
    case ParamType::String: return "string";
    case ParamType::Texture: return "texture";
    }
    return "?";
}

bool parseParamType(const std::string& name, ParamType* out) {
    for (const auto& ti : kTypeNames)
        if (name == ti.name) {
            *out = ti.type;
            return true;
        }
    return false;
}

int paramTypeArity(ParamType t) {
    switch (t) {
    case ParamType::Point2: case ParamType::Vector2: case ParamType::Blackbody:
    case ParamType::Spectrum:
        return 2;
    case ParamType::Point3: case ParamType::Vector3: case ParamType::Normal3:
    case ParamType::RGB: case ParamType::XYZ:
        return 3;
    default:
        return 1;
    }
}

std::size_t Param::size() const {
    if (type == ParamType::Bool) return bools.size();
    if (type == ParamType::String || type == ParamType::Texture) return strings.size();
    return numbers.size();
}

void ParamList::add(Param p) {
    auto [it, inserted] = index_.emplace(p.name, params_.size());
    if (inserted) params_.push_back(std::move(p));
    else params_[it->second] = std::move(p);
}

const Param* ParamList::find(const std::string& name) const {
    auto it = index_.find(name);
    return it == index_.end() ? nullptr : &params_[it->second];
}

void ParamList::typeError(const Param& p, const char* expected) const {
    if (diag_)
        diag_->error(p.loc, "parameter \"" + p.name + "\" has type " + paramTypeName(p.type) +
                                ", expected " + expected);
}

const Param* ParamList::lookup(const std::string& name,
                               std::initializer_list<ParamType> types) const {
    const Param* p = find(name);
    if (!p) return nullptr;
    p->used = true;
    for (ParamType t : types)
        if (p->type == t) return p;
    std::string expected;
    for (ParamType t : types) expected += (expected.empty() ? "" : " or ") + std::string(paramTypeName(t));
    typeError(*p, expected.c_str());
    return nullptr;
}

float ParamList::getFloat(const std::string& name, float def) const {
    const Param* p = lookup(name, {ParamType::Float});
    return p && !p->numbers.empty() ? float(p->numbers[0]) : def;
}

int ParamList::getInt(const std::string& name, int def) const {
    const Param* p = lookup(name, {ParamType::Integer});
    if (!p || p->numbers.empty()) return def;
    double v = p->numbers[0];
    if (v < INT_MIN || v > INT_MAX) {
        if (diag_) diag_->error(p->loc, "integer parameter \"" + name + "\" is out of range");
        return def;
    }
    return int(v);
}

bool ParamList::getBool(const std::string& name, bool def) const {
    const Param* p = lookup(name, {ParamType::Bool});
    return p && !p->bools.empty() ? p->bools[0] != 0 : def;
}

std::string ParamList::getString(const std::string& name, const std::string& def) const {
    const Param* p = lookup(name, {ParamType::String});
    return p && !p->strings.empty() ? p->strings[0] : def;
}

std::string ParamList::getTexture(const std::string& name) const {
    const Param* p = lookup(name, {ParamType::Texture});
    return p && !p->strings.empty() ? p->strings[0] : std::string();
}

std::string ParamList::getFilename(const std::string& name) const {
    const Param* p = lookup(name, {ParamType::String});
    if (!p || p->strings.empty() || p->strings[0].empty()) return std::string();
    const std::string& f = p->strings[0];
    if (f[0] == '/') return f;
    return p->loc.directory() + f;
}

namespace {
template <int N>
std::vector<std::array<float, N>> group(const Param* p) {
    std::vector<std::array<float, N>> out;
    if (!p) return out;
    out.resize(p->numbers.size() / N);
    for (std::size_t i = 0; i < out.size(); ++i)
        for (int k = 0; k < N; ++k) out[i][k] = float(p->numbers[i * N + k]);
    return out;
}
}  // namespace

Float3 ParamList::getPoint3(const std::string& name, Float3 def) const {
    auto v = group<3>(lookup(name, {ParamType::Point3}));
    return v.empty() ? def : v[0];
}
Float3 ParamList::getVector3(const std::string& name, Float3 def) const {
    auto v = group<3>(lookup(name, {ParamType::Vector3}));
    return v.empty() ? def : v[0];
}
Float3 ParamList::getNormal3(const std::string& name, Float3 def) const {
    auto v = group<3>(lookup(name, {ParamType::Normal3}));
    return v.empty() ? def : v[0];
}
Float2 ParamList::getPoint2(const std::string& name, Float2 def) const {
    auto v = group<2>(lookup(name, {ParamType::Point2}));
    return v.empty() ? def : v[0];
}

std::vector<float> ParamList::getFloats(const std::string& name) const {
    const Param* p = lookup(name, {ParamType::Float});
    if (!p) return {};
    return std::vector<float>(p->numbers.begin(), p->numbers.end());
}

std::vector<int> ParamList::getInts(const std::string& name) const {
    const Param* p = lookup(name, {ParamType::Integer});
    if (!p) return {};
    std::vector<int> out;
    out.reserve(p->numbers.size());
    for (double v : p->numbers) {
        if (v < INT_MIN || v > INT_MAX) {
            if (diag_) diag_->error(p->loc, "integer parameter \"" + name + "\" is out of range");
            return {};
        }
        out.push_back(int(v));
    }
    return out;
}

std::vector<Float3> ParamList::getPoint3s(const std::string& name) const {
    return group<3>(lookup(name, {ParamType::Point3}));
}
std::vector<Float3> ParamList::getNormal3s(const std::string& name) const {
    return group<3>(lookup(name, {ParamType::Normal3}));
}
std::vector<Float3> ParamList::getVector3s(const std::string& name) const {
    return group<3>(lookup(name, {ParamType::Vector3}));
}
std::vector<Float2> ParamList::getPoint2s(const std::string& name) const {
    return group<2>(lookup(name, {ParamType::Point2}));
}
std::vector<std::string> ParamList::getStrings(const std::string& name) const {
    const Param* p = lookup(name, {ParamType::String});
    return p ? p->strings : std::vector<std::string>();
}

const Param* ParamList::getSpectral(const std::string& name) const {
    return lookup(name, {ParamType::RGB, ParamType::XYZ, ParamType::Blackbody, ParamType::Spectrum});
}

void ParamList::reportUnused(const std::string& context) const {
    if (!diag_) return;
    for (const auto& p : params_)
        if (!p.used)
            diag_->warning(p.loc, "parameter \"" + std::string(paramTypeName(p.type)) + " " +
                                      p.name + "\" is not used by " + context);
}

void ParamList::markAllUsed() const {
    for (const auto& p : params_) p.used = true;
}

}  // namespace rlpbrt
