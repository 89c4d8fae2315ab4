// The pbrt-v3 scene parser: turns a token stream (across Includes) into calls on a SceneSink.
// It knows the syntax of every directive and parameter list, and nothing of what they mean:
// graphics state, named objects and geometry belong to the sink (render/scene_builder.h).
#pragma once

#include <array>
#include <string>

#include "parser/diagnostics.h"
#include "parser/params.h"

namespace rlpbrt {

// One virtual per pbrt-v3 directive; every call carries the directive's location.
// Parameter lists are handed over by value (moved).
class SceneSink {
public:
    virtual ~SceneSink() = default;

    // Transformations.
    virtual void identity(FileLoc loc) = 0;
    virtual void translate(float dx, float dy, float dz, FileLoc loc) = 0;
    virtual void scale(float sx, float sy, float sz, FileLoc loc) = 0;
    virtual void rotate(float angleDeg, float ax, float ay, float az, FileLoc loc) = 0;
    virtual void lookAt(float ex, float ey, float ez, float lx, float ly, float lz, float ux,
                        float uy, float uz, FileLoc loc) = 0;
    // Matrices as written in the file (16 numbers, pbrt-v3 order: the file lists the
    // transpose of the matrix applied to column vectors).
    virtual void concatTransform(const std::array<float, 16>& m, FileLoc loc) = 0;
    virtual void transform(const std::array<float, 16>& m, FileLoc loc) = 0;
    virtual void coordinateSystem(const std::string& name, FileLoc loc) = 0;
    virtual void coordSysTransform(const std::string& name, FileLoc loc) = 0;
    // which: "StartTime", "EndTime" or "All".
    virtual void activeTransform(const std::string& which, FileLoc loc) = 0;
    virtual void transformTimes(float start, float end, FileLoc loc) = 0;
    virtual void reverseOrientation(FileLoc loc) = 0;

    // Options (before WorldBegin).
    virtual void camera(const std::string& type, ParamList params, FileLoc loc) = 0;
    virtual void sampler(const std::string& type, ParamList params, FileLoc loc) = 0;
    virtual void film(const std::string& type, ParamList params, FileLoc loc) = 0;
    virtual void pixelFilter(const std::string& type, ParamList params, FileLoc loc) = 0;
    virtual void integrator(const std::string& type, ParamList params, FileLoc loc) = 0;
    virtual void accelerator(const std::string& type, ParamList params, FileLoc loc) = 0;
    virtual void makeNamedMedium(const std::string& name, ParamList params, FileLoc loc) = 0;
    virtual void mediumInterface(const std::string& inside, const std::string& outside,
                                 FileLoc loc) = 0;

    // Blocks.
    virtual void worldBegin(FileLoc loc) = 0;
    virtual void worldEnd(FileLoc loc) = 0;
    virtual void attributeBegin(FileLoc loc) = 0;
    virtual void attributeEnd(FileLoc loc) = 0;
    virtual void transformBegin(FileLoc loc) = 0;
    virtual void transformEnd(FileLoc loc) = 0;

    // The world.
    // type: "float" or "spectrum" (also "color"); texClass: "imagemap", "checkerboard", ...
    virtual void texture(const std::string& name, const std::string& type,
                         const std::string& texClass, ParamList params, FileLoc loc) = 0;
    virtual void material(const std::string& type, ParamList params, FileLoc loc) = 0;
    virtual void makeNamedMaterial(const std::string& name, ParamList params, FileLoc loc) = 0;
    virtual void namedMaterial(const std::string& name, FileLoc loc) = 0;
    virtual void lightSource(const std::string& type, ParamList params, FileLoc loc) = 0;
    virtual void areaLightSource(const std::string& type, ParamList params, FileLoc loc) = 0;
    virtual void shape(const std::string& type, ParamList params, FileLoc loc) = 0;
    virtual void objectBegin(const std::string& name, FileLoc loc) = 0;
    virtual void objectEnd(FileLoc loc) = 0;
    virtual void objectInstance(const std::string& name, FileLoc loc) = 0;

    // Called once after the last token of the main file.
    virtual void endOfFiles(FileLoc loc) = 0;
};

struct ParseLimits {
    int maxIncludeDepth = 64;
    // Upper bound of values in one parameter list (guards memory against absurd input).
    std::size_t maxValues = std::size_t(1) << 31;
};

// Parses a scene file. Errors and warnings go to `diag`; parsing goes on after recoverable
// errors so that one run reports them all. Returns true if no error was reported (by the
// parser or by the sink through the same Diagnostics).
bool parseFile(const std::string& path, SceneSink& sink, Diagnostics& diag,
               const ParseLimits& limits = {});
// The same for scene text held in memory; `name` is used in locations and for resolving
// relative Includes (its directory).
bool parseString(const std::string& text, const std::string& name, SceneSink& sink,
                 Diagnostics& diag, const ParseLimits& limits = {});

}  // namespace rlpbrt
