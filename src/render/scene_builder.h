// SceneBuilder: the SceneSink that keeps pbrt-v3's graphics state (transforms, material,
// area light, media, named objects) and records a SceneDesc. Semantic errors (unbalanced
// blocks, undefined names, directives in the wrong block) are reported here with locations.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "parser/parser.h"
#include "render/scene_desc.h"

namespace rlpbrt {

class SceneBuilder : public SceneSink {
public:
    explicit SceneBuilder(Diagnostics& diag);

    SceneDesc& desc() { return desc_; }
    SceneDesc takeDesc() { return std::move(desc_); }

    void identity(FileLoc loc) override;
    void translate(float dx, float dy, float dz, FileLoc loc) override;
    void scale(float sx, float sy, float sz, FileLoc loc) override;
    void rotate(float angleDeg, float ax, float ay, float az, FileLoc loc) override;
    void lookAt(float ex, float ey, float ez, float lx, float ly, float lz, float ux, float uy,
                float uz, FileLoc loc) override;
    void concatTransform(const std::array<float, 16>& m, FileLoc loc) override;
    void transform(const std::array<float, 16>& m, FileLoc loc) override;
    void coordinateSystem(const std::string& name, FileLoc loc) override;
    void coordSysTransform(const std::string& name, FileLoc loc) override;
    void activeTransform(const std::string& which, FileLoc loc) override;
    void transformTimes(float start, float end, FileLoc loc) override;
    void reverseOrientation(FileLoc loc) override;

    void camera(const std::string& type, ParamList params, FileLoc loc) override;
    void sampler(const std::string& type, ParamList params, FileLoc loc) override;
    void film(const std::string& type, ParamList params, FileLoc loc) override;
    void pixelFilter(const std::string& type, ParamList params, FileLoc loc) override;
    void integrator(const std::string& type, ParamList params, FileLoc loc) override;
    void accelerator(const std::string& type, ParamList params, FileLoc loc) override;
    void makeNamedMedium(const std::string& name, ParamList params, FileLoc loc) override;
    void mediumInterface(const std::string& inside, const std::string& outside,
                         FileLoc loc) override;

    void worldBegin(FileLoc loc) override;
    void worldEnd(FileLoc loc) override;
    void attributeBegin(FileLoc loc) override;
    void attributeEnd(FileLoc loc) override;
    void transformBegin(FileLoc loc) override;
    void transformEnd(FileLoc loc) override;

    void texture(const std::string& name, const std::string& type, const std::string& texClass,
                 ParamList params, FileLoc loc) override;
    void material(const std::string& type, ParamList params, FileLoc loc) override;
    void makeNamedMaterial(const std::string& name, ParamList params, FileLoc loc) override;
    void namedMaterial(const std::string& name, FileLoc loc) override;
    void lightSource(const std::string& type, ParamList params, FileLoc loc) override;
    void areaLightSource(const std::string& type, ParamList params, FileLoc loc) override;
    void shape(const std::string& type, ParamList params, FileLoc loc) override;
    void objectBegin(const std::string& name, FileLoc loc) override;
    void objectEnd(FileLoc loc) override;
    void objectInstance(const std::string& name, FileLoc loc) override;
    void endOfFiles(FileLoc loc) override;

private:
    struct GraphicsState {
        Mat4 ctm[2] = {Mat4(1.f), Mat4(1.f)};
        bool reverseOrientation = false;
        int material = 0;
        int areaLight = -1;
        std::string inside, outside;
        FileLoc mediumLoc;
        std::shared_ptr<const TextureScope> textures;
        std::shared_ptr<const std::map<std::string, int>> namedMaterials;
    };
    enum class BlockKind { Attribute, Transform, Object };
    struct Block {
        BlockKind kind;
        FileLoc loc;
        GraphicsState state;
    };

    template <typename F> void applyTransform(F&& f);
    bool inWorld(const char* directive, const FileLoc& loc);
    bool beforeWorld(const char* directive, const FileLoc& loc);
    void setOption(Entity& e, const char* directive, const std::string& type, ParamList&& params,
                   const FileLoc& loc);
    void popBlock(BlockKind kind, const char* directive, const FileLoc& loc);
    bool checkMedia(const FileLoc& loc);
    void checkStatic(const FileLoc& loc);

    Diagnostics& diag_;
    SceneDesc desc_;
    GraphicsState gs_;
    std::vector<Block> stack_;
    std::map<std::string, Mat4> namedCoordSys_;
    std::map<std::string, int> objectIndex_;
    unsigned activeMask_ = 3;  // bit 0: start transform, bit 1: end transform
    enum class Phase { Options, World, Ended } phase_ = Phase::Options;
    int currentObject_ = -1;
    bool warnedAfterEnd_ = false;
};

// Parses a scene file into a SceneDesc. Returns false if any error was reported.
bool loadSceneDesc(const std::string& path, Diagnostics& diag, SceneDesc* out);

}  // namespace rlpbrt
