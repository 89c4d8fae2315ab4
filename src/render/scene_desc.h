// The scene description the builder records from the directives: plain entities with their
// parameters and locations, before any render object or Embree geometry is made.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "parser/params.h"
#include "render/math.h"

namespace rlpbrt {

// A directive with a type name and parameters (Camera, Film, Shape, Material, ...).
struct Entity {
    std::string type;
    ParamList params;
    FileLoc loc;
    bool present = false;  // false: the directive was absent; pbrt-v3's default applies

    // Records the directive's parameters and location (it is now present).
    void assign(ParamList&& p, const FileLoc& l) {
        params = std::move(p);
        loc = l;
        present = true;
    }
    void assign(const std::string& t, ParamList&& p, const FileLoc& l) {
        type = t;
        assign(std::move(p), l);
    }
};

// Named textures visible at one point of the file (copied on write, shared otherwise).
struct TextureScope {
    std::map<std::string, int> floatTextures;     // name -> index in SceneDesc::textures
    std::map<std::string, int> spectrumTextures;  // name -> index in SceneDesc::textures
};

struct TextureEntity : Entity {
    std::string name;
    bool isFloat = false;  // "float"; otherwise "spectrum"/"color"
    Mat4 worldFromTexture{1.f};
    std::shared_ptr<const TextureScope> textures;  // textures visible at its definition
};

struct MaterialEntity : Entity {
    std::string name;  // for named materials
    std::shared_ptr<const TextureScope> textures;
    bool interfaceOnly() const { return type.empty() || type == "none" || type == "interface"; }
};

struct MediumEntity : Entity {
    std::string name;
    Mat4 worldFromMedium{1.f};
};

struct LightEntity : Entity {
    Mat4 worldFromLight{1.f};
    std::string outsideMedium;
};

struct ShapeEntity : Entity {
    Mat4 worldFromObject{1.f};
    bool reverseOrientation = false;
    int material = -1;   // index in SceneDesc::materials; -1 = default matte
    int areaLight = -1;  // index in SceneDesc::areaLights, or -1
    std::string insideMedium, outsideMedium;
};

// ObjectBegin/End: shapes defined in the object's own space (their CTM inside the block).
struct ObjectEntity {
    std::string name;
    FileLoc loc;
    std::vector<int> shapes;  // indices in SceneDesc::shapes
};

struct InstanceEntity {
    int object = -1;
    Mat4 worldFromInstance{1.f};
    FileLoc loc;
};

struct SceneDesc {
    Entity camera, sampler, film, filter, integrator, accelerator;
    Mat4 cameraFromWorld{1.f};
    std::string cameraMedium;
    std::vector<MediumEntity> media;
    std::vector<TextureEntity> textures;
    std::vector<MaterialEntity> materials;
    std::vector<Entity> areaLights;
    std::vector<LightEntity> lights;
    std::vector<ShapeEntity> shapes;         // world shapes and object shapes alike
    std::vector<int> worldShapes;            // indices of shapes outside ObjectBegin/End
    std::vector<ObjectEntity> objects;
    std::vector<InstanceEntity> instances;
    bool worldEnded = false;

    const MediumEntity* findMedium(const std::string& name) const {
        for (const auto& m : media)
            if (m.name == name) return &m;
        return nullptr;
    }
};

}  // namespace rlpbrt
