// libFuzzer target: tokenizer + parser + parameter lists on scene text held in memory. The
// sink reads every parameter through the getters of every type (as the scene builder would,
// including the type-mismatch paths) and checks the parser's promises: finite numbers,
// whole parameter values, and a location on every diagnostic.
//
// The scene is named as if it lived in a directory that does not exist, so relative Includes
// and .spd files fail to open instead of reading whatever lies in the working directory.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "parser/parser.h"

namespace {

using namespace rlpbrt;

void check(bool ok) {
    if (!ok) __builtin_trap();
}

void checkFinite(std::initializer_list<float> v) {
    for (float x : v) check(std::isfinite(x));
}

class FuzzSink : public SceneSink {
public:
    explicit FuzzSink(Diagnostics& diag) : diag_(diag) {}

    void identity(FileLoc) override {}
    void translate(float x, float y, float z, FileLoc) override { checkFinite({x, y, z}); }
    void scale(float x, float y, float z, FileLoc) override { checkFinite({x, y, z}); }
    void rotate(float a, float x, float y, float z, FileLoc) override { checkFinite({a, x, y, z}); }
    void lookAt(float a, float b, float c, float d, float e, float f, float g, float h, float i,
                FileLoc) override {
        checkFinite({a, b, c, d, e, f, g, h, i});
    }
    void concatTransform(const std::array<float, 16>& m, FileLoc) override { matrix(m); }
    void transform(const std::array<float, 16>& m, FileLoc) override { matrix(m); }
    void coordinateSystem(const std::string&, FileLoc) override {}
    void coordSysTransform(const std::string&, FileLoc) override {}
    void activeTransform(const std::string& w, FileLoc) override {
        check(w == "StartTime" || w == "EndTime" || w == "All");
    }
    void transformTimes(float a, float b, FileLoc) override { checkFinite({a, b}); }
    void reverseOrientation(FileLoc) override {}
    void camera(const std::string&, ParamList p, FileLoc) override { use(p); }
    void sampler(const std::string&, ParamList p, FileLoc) override { use(p); }
    void film(const std::string&, ParamList p, FileLoc) override { use(p); }
    void pixelFilter(const std::string&, ParamList p, FileLoc) override { use(p); }
    void integrator(const std::string&, ParamList p, FileLoc) override { use(p); }
    void accelerator(const std::string&, ParamList p, FileLoc) override { use(p); }
    void makeNamedMedium(const std::string&, ParamList p, FileLoc) override { use(p); }
    void mediumInterface(const std::string&, const std::string&, FileLoc) override {}
    void worldBegin(FileLoc) override {}
    void worldEnd(FileLoc) override {}
    void attributeBegin(FileLoc) override {}
    void attributeEnd(FileLoc) override {}
    void transformBegin(FileLoc) override {}
    void transformEnd(FileLoc) override {}
    void texture(const std::string&, const std::string&, const std::string&, ParamList p,
                 FileLoc) override {
        use(p);
    }
    void material(const std::string&, ParamList p, FileLoc) override { use(p); }
    void makeNamedMaterial(const std::string&, ParamList p, FileLoc) override { use(p); }
    void namedMaterial(const std::string&, FileLoc) override {}
    void lightSource(const std::string&, ParamList p, FileLoc) override { use(p); }
    void areaLightSource(const std::string&, ParamList p, FileLoc) override { use(p); }
    void shape(const std::string&, ParamList p, FileLoc) override { use(p); }
    void objectBegin(const std::string&, FileLoc) override {}
    void objectEnd(FileLoc) override {}
    void objectInstance(const std::string&, FileLoc) override {}
    void endOfFiles(FileLoc) override {}

private:
    static void matrix(const std::array<float, 16>& m) {
        for (float x : m) check(std::isfinite(x));
    }

    void use(ParamList& list) {
        list.setDiagnostics(&diag_);
        for (const Param& p : list.params()) {
            check(p.size() > 0);
            check(p.loc.file != nullptr);
            if (p.spectrumFile.empty()) check(p.numbers.size() % size_t(paramTypeArity(p.type)) == 0);
            for (double v : p.numbers) check(std::isfinite(v));
            const std::string& n = p.name;
            // Every getter on every name: right type reads values, wrong type reports.
            (void)list.getFloat(n, 0.f);
            (void)list.getInt(n, 0);
            (void)list.getBool(n, false);
            (void)list.getString(n, "");
            (void)list.getTexture(n);
            (void)list.getFilename(n);
            (void)list.getPoint3(n, {});
            (void)list.getVector3(n, {});
            (void)list.getNormal3(n, {});
            (void)list.getPoint2(n, {});
            for (float x : list.getFloats(n)) check(std::isfinite(x));
            (void)list.getInts(n);
            (void)list.getPoint3s(n);
            (void)list.getNormal3s(n);
            (void)list.getVector3s(n);
            (void)list.getPoint2s(n);
            (void)list.getStrings(n);
            (void)list.getSpectral(n);
        }
        list.reportUnused("fuzz");
    }

    Diagnostics& diag_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Diagnostics diag;
    diag.setStream(nullptr);
    FuzzSink sink(diag);
    ParseLimits limits;
    limits.maxValues = 1 << 20;
    std::string text(reinterpret_cast<const char*>(data), size);
    bool ok = parseString(text, "/nonexistent-rlpbrt-fuzz/input.pbrt", sink, diag, limits);
    // Success means no error; every error names a file.
    check(ok == (diag.errorCount() == 0));
    for (const Diagnostic& d : diag.all()) check(d.loc.file != nullptr && !d.message.empty());
    return 0;
}
