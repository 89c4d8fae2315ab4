// A SceneSink for tests: records every call of the parser as one line of text, e.g.
// `Shape "sphere" float radius=[3] @scene.pbrt:12:1`, so that tests can compare whole
// directive streams with a list of expected lines.
#pragma once

#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "parser/parser.h"

namespace rlpbrt {
namespace test {

// Line format: the directive's pbrt-v3 name, its arguments (strings quoted, floats in %g),
// then every parameter as `type name=[v1 v2 ...]` (type after synonyms are resolved, strings
// quoted, numbers in %.10g, bools as true/false; a spectrum read from a file as
// `spectrum eta="file"[...]`), then ` @file:line:col` unless showLocations is false.
class RecordingSink : public SceneSink {
public:
    std::vector<std::string> lines;      // one per call, in call order
    std::vector<ParamList> paramLists;   // the parameter lists handed over, in call order
    bool showLocations = true;
    // Removed from the front of file names in locations (e.g. a temporary directory).
    std::string stripPrefix;
    // Parameters with more values are recorded as `type name=[<n> values]` (saves time on
    // big scenes).
    std::size_t maxValues = std::size_t(-1);

    // Formats a number as the recorded lines do: %g for the float arguments of directives,
    // %.10g for parameter values (doubles, so that integers print exactly).
    static std::string num(double v, bool precise = false) {
        char buf[64];
        std::snprintf(buf, sizeof buf, precise ? "%.10g" : "%g", v);
        return buf;
    }

    // `file:line:col` with stripPrefix removed from the file name.
    std::string where(const FileLoc& loc) const {
        std::string s = loc.str();
        if (!stripPrefix.empty() && s.compare(0, stripPrefix.size(), stripPrefix) == 0)
            s.erase(0, stripPrefix.size());
        return s;
    }

    // Formats one parameter as `type name=[values]`.
    std::string format(const Param& p) const {
        std::string s = std::string(paramTypeName(p.type)) + " " + p.name + "=";
        if (!p.spectrumFile.empty()) s += "\"" + strip(p.spectrumFile) + "\"";
        if (p.size() > maxValues) return s + "[" + std::to_string(p.size()) + " values]";
        s += "[";
        bool first = true;
        auto sep = [&] {
            if (!first) s += " ";
            first = false;
        };
        if (p.type == ParamType::Bool) {
            for (uint8_t b : p.bools) sep(), s += b ? "true" : "false";
        } else if (p.type == ParamType::String || p.type == ParamType::Texture) {
            for (const auto& str : p.strings) sep(), s += "\"" + str + "\"";
        } else {
            for (double v : p.numbers) sep(), s += num(v, true);
        }
        return s + "]";
    }

    void identity(FileLoc loc) override { rec("Identity", loc); }
    void translate(float dx, float dy, float dz, FileLoc loc) override {
        rec("Translate " + nums({dx, dy, dz}), loc);
    }
    void scale(float sx, float sy, float sz, FileLoc loc) override {
        rec("Scale " + nums({sx, sy, sz}), loc);
    }
    void rotate(float angleDeg, float ax, float ay, float az, FileLoc loc) override {
        rec("Rotate " + nums({angleDeg, ax, ay, az}), loc);
    }
    void lookAt(float ex, float ey, float ez, float lx, float ly, float lz, float ux, float uy,
                float uz, FileLoc loc) override {
        rec("LookAt " + nums({ex, ey, ez, lx, ly, lz, ux, uy, uz}), loc);
    }
    void concatTransform(const std::array<float, 16>& m, FileLoc loc) override {
        rec("ConcatTransform [" + nums(m) + "]", loc);
    }
    void transform(const std::array<float, 16>& m, FileLoc loc) override {
        rec("Transform [" + nums(m) + "]", loc);
    }
    void coordinateSystem(const std::string& name, FileLoc loc) override {
        rec("CoordinateSystem " + q(name), loc);
    }
    void coordSysTransform(const std::string& name, FileLoc loc) override {
        rec("CoordSysTransform " + q(name), loc);
    }
    void activeTransform(const std::string& which, FileLoc loc) override {
        rec("ActiveTransform " + which, loc);
    }
    void transformTimes(float start, float end, FileLoc loc) override {
        rec("TransformTimes " + nums({start, end}), loc);
    }
    void reverseOrientation(FileLoc loc) override { rec("ReverseOrientation", loc); }

    void camera(const std::string& type, ParamList params, FileLoc loc) override {
        recParams("Camera " + q(type), std::move(params), loc);
    }
    void sampler(const std::string& type, ParamList params, FileLoc loc) override {
        recParams("Sampler " + q(type), std::move(params), loc);
    }
    void film(const std::string& type, ParamList params, FileLoc loc) override {
        recParams("Film " + q(type), std::move(params), loc);
    }
    void pixelFilter(const std::string& type, ParamList params, FileLoc loc) override {
        recParams("PixelFilter " + q(type), std::move(params), loc);
    }
    void integrator(const std::string& type, ParamList params, FileLoc loc) override {
        recParams("Integrator " + q(type), std::move(params), loc);
    }
    void accelerator(const std::string& type, ParamList params, FileLoc loc) override {
        recParams("Accelerator " + q(type), std::move(params), loc);
    }
    void makeNamedMedium(const std::string& name, ParamList params, FileLoc loc) override {
        recParams("MakeNamedMedium " + q(name), std::move(params), loc);
    }
    void mediumInterface(const std::string& inside, const std::string& outside,
                         FileLoc loc) override {
        rec("MediumInterface " + q(inside) + " " + q(outside), loc);
    }

    void worldBegin(FileLoc loc) override { rec("WorldBegin", loc); }
    void worldEnd(FileLoc loc) override { rec("WorldEnd", loc); }
    void attributeBegin(FileLoc loc) override { rec("AttributeBegin", loc); }
    void attributeEnd(FileLoc loc) override { rec("AttributeEnd", loc); }
    void transformBegin(FileLoc loc) override { rec("TransformBegin", loc); }
    void transformEnd(FileLoc loc) override { rec("TransformEnd", loc); }

    void texture(const std::string& name, const std::string& type, const std::string& texClass,
                 ParamList params, FileLoc loc) override {
        recParams("Texture " + q(name) + " " + q(type) + " " + q(texClass), std::move(params),
                  loc);
    }
    void material(const std::string& type, ParamList params, FileLoc loc) override {
        recParams("Material " + q(type), std::move(params), loc);
    }
    void makeNamedMaterial(const std::string& name, ParamList params, FileLoc loc) override {
        recParams("MakeNamedMaterial " + q(name), std::move(params), loc);
    }
    void namedMaterial(const std::string& name, FileLoc loc) override {
        rec("NamedMaterial " + q(name), loc);
    }
    void lightSource(const std::string& type, ParamList params, FileLoc loc) override {
        recParams("LightSource " + q(type), std::move(params), loc);
    }
    void areaLightSource(const std::string& type, ParamList params, FileLoc loc) override {
        recParams("AreaLightSource " + q(type), std::move(params), loc);
    }
    void shape(const std::string& type, ParamList params, FileLoc loc) override {
        recParams("Shape " + q(type), std::move(params), loc);
    }
    void objectBegin(const std::string& name, FileLoc loc) override {
        rec("ObjectBegin " + q(name), loc);
    }
    void objectEnd(FileLoc loc) override { rec("ObjectEnd", loc); }
    void objectInstance(const std::string& name, FileLoc loc) override {
        rec("ObjectInstance " + q(name), loc);
    }
    void endOfFiles(FileLoc loc) override { rec("EndOfFiles", loc); }

private:
    static std::string q(const std::string& s) { return "\"" + s + "\""; }
    std::string strip(const std::string& file) const {
        if (!stripPrefix.empty() && file.compare(0, stripPrefix.size(), stripPrefix) == 0)
            return file.substr(stripPrefix.size());
        return file;
    }
    template <typename C>
    static std::string nums(const C& values) {
        std::string s;
        for (float v : values) s += (s.empty() ? "" : " ") + num(v);
        return s;
    }
    static std::string nums(std::initializer_list<float> values) {
        return nums<std::initializer_list<float>>(values);
    }
    void rec(std::string line, const FileLoc& loc) {
        if (showLocations) line += " @" + where(loc);
        lines.push_back(std::move(line));
    }
    void recParams(std::string line, ParamList params, const FileLoc& loc) {
        for (const auto& p : params.params()) line += " " + format(p);
        paramLists.push_back(std::move(params));
        rec(std::move(line), loc);
    }
};

}  // namespace test
}  // namespace rlpbrt
