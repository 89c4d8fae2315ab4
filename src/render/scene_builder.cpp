#include "render/scene_builder.h"

#include "render/transform.h"

namespace rlpbrt {

namespace {
const char* blockName(int kind) {
    static const char* names[] = {"AttributeBegin", "TransformBegin", "ObjectBegin"};
    return names[kind];
}
const char* endName(int kind) {
    static const char* names[] = {"AttributeEnd", "TransformEnd", "ObjectEnd"};
    return names[kind];
}
}  // namespace

SceneBuilder::SceneBuilder(Diagnostics& diag) : diag_(diag) {
    // pbrt-v3's default material: matte with Kd 0.5.
    MaterialEntity def;
    def.type = "matte";
    def.textures = std::make_shared<TextureScope>();
    desc_.materials.push_back(std::move(def));
    gs_.textures = std::make_shared<TextureScope>();
    gs_.namedMaterials = std::make_shared<std::map<std::string, int>>();
}

template <typename F>
void SceneBuilder::applyTransform(F&& f) {
    for (int i = 0; i < 2; ++i)
        if (activeMask_ & (1u << i)) gs_.ctm[i] = f(gs_.ctm[i]);
}

void SceneBuilder::identity(FileLoc) {
    applyTransform([](const Mat4&) { return Mat4(1.f); });
}
void SceneBuilder::translate(float dx, float dy, float dz, FileLoc) {
    Mat4 t = translateMatrix(Vec3(dx, dy, dz));
    applyTransform([&](const Mat4& m) { return m * t; });
}
void SceneBuilder::scale(float sx, float sy, float sz, FileLoc loc) {
    if (sx == 0.f || sy == 0.f || sz == 0.f)
        diag_.warning(loc, "Scale with a zero factor makes a degenerate transform");
    Mat4 t = scaleMatrix(Vec3(sx, sy, sz));
    applyTransform([&](const Mat4& m) { return m * t; });
}
void SceneBuilder::rotate(float angle, float ax, float ay, float az, FileLoc loc) {
    if (ax == 0.f && ay == 0.f && az == 0.f) {
        diag_.error(loc, "Rotate about a zero-length axis");
        return;
    }
    Mat4 t = rotateMatrix(angle, Vec3(ax, ay, az));
    applyTransform([&](const Mat4& m) { return m * t; });
}
void SceneBuilder::lookAt(float ex, float ey, float ez, float lx, float ly, float lz, float ux,
                          float uy, float uz, FileLoc loc) {
    Mat4 t;
    if (!lookAtMatrix(Vec3(ex, ey, ez), Vec3(lx, ly, lz), Vec3(ux, uy, uz), &t)) {
        diag_.error(loc, "LookAt with eye equal to the look-at point, or the up vector "
                         "parallel to the view direction");
        return;
    }
    applyTransform([&](const Mat4& m) { return m * t; });
}
void SceneBuilder::concatTransform(const std::array<float, 16>& v, FileLoc) {
    Mat4 t = matrixFromPbrt(v);
    applyTransform([&](const Mat4& m) { return m * t; });
}
void SceneBuilder::transform(const std::array<float, 16>& v, FileLoc) {
    Mat4 t = matrixFromPbrt(v);
    applyTransform([&](const Mat4&) { return t; });
}
void SceneBuilder::coordinateSystem(const std::string& name, FileLoc) {
    namedCoordSys_[name] = gs_.ctm[0];
}
void SceneBuilder::coordSysTransform(const std::string& name, FileLoc loc) {
    auto it = namedCoordSys_.find(name);
    if (it == namedCoordSys_.end()) {
        diag_.error(loc, "undefined coordinate system \"" + name + "\"");
        return;
    }
    Mat4 t = it->second;
    applyTransform([&](const Mat4&) { return t; });
}
void SceneBuilder::activeTransform(const std::string& which, FileLoc) {
    activeMask_ = which == "StartTime" ? 1u : which == "EndTime" ? 2u : 3u;
}
void SceneBuilder::transformTimes(float start, float end, FileLoc loc) {
    if (end < start) diag_.error(loc, "TransformTimes end time is before its start time");
}
void SceneBuilder::reverseOrientation(FileLoc) { gs_.reverseOrientation = !gs_.reverseOrientation; }

bool SceneBuilder::inWorld(const char* directive, const FileLoc& loc) {
    if (phase_ == Phase::World) return true;
    if (phase_ == Phase::Options)
        diag_.error(loc, std::string(directive) + " is only allowed between WorldBegin and "
                                                  "WorldEnd");
    else if (!warnedAfterEnd_) {
        warnedAfterEnd_ = true;
        diag_.warning(loc, std::string(directive) + " after WorldEnd is ignored (rlpbrt renders "
                                                    "one world per file)");
    }
    return false;
}

bool SceneBuilder::beforeWorld(const char* directive, const FileLoc& loc) {
    if (phase_ == Phase::Options) return true;
    if (phase_ == Phase::World)
        diag_.error(loc, std::string(directive) + " is not allowed inside the world block");
    else if (!warnedAfterEnd_) {
        warnedAfterEnd_ = true;
        diag_.warning(loc, std::string(directive) + " after WorldEnd is ignored (rlpbrt renders "
                                                    "one world per file)");
    }
    return false;
}

void SceneBuilder::setOption(Entity& e, const char* directive, const std::string& type,
                             ParamList&& params, const FileLoc& loc) {
    if (!beforeWorld(directive, loc)) return;
    // Repeated directives: the last one wins, as in pbrt-v3.
    e.assign(type, std::move(params), loc);
}

void SceneBuilder::camera(const std::string& type, ParamList params, FileLoc loc) {
    if (!beforeWorld("Camera", loc)) return;
    setOption(desc_.camera, "Camera", type, std::move(params), loc);
    checkStatic(loc);
    desc_.cameraFromWorld = gs_.ctm[0];
    namedCoordSys_["camera"] = glm::inverse(gs_.ctm[0]);
    desc_.cameraMedium = gs_.outside;
    if (!gs_.outside.empty() && !desc_.findMedium(gs_.outside))
        diag_.error(gs_.mediumLoc.file ? gs_.mediumLoc : loc,
                    "undefined medium \"" + gs_.outside + "\" for the camera");
}
void SceneBuilder::sampler(const std::string& type, ParamList params, FileLoc loc) {
    setOption(desc_.sampler, "Sampler", type, std::move(params), loc);
}
void SceneBuilder::film(const std::string& type, ParamList params, FileLoc loc) {
    setOption(desc_.film, "Film", type, std::move(params), loc);
}
void SceneBuilder::pixelFilter(const std::string& type, ParamList params, FileLoc loc) {
    setOption(desc_.filter, "PixelFilter", type, std::move(params), loc);
}
void SceneBuilder::integrator(const std::string& type, ParamList params, FileLoc loc) {
    setOption(desc_.integrator, "Integrator", type, std::move(params), loc);
}
void SceneBuilder::accelerator(const std::string& type, ParamList params, FileLoc loc) {
    setOption(desc_.accelerator, "Accelerator", type, std::move(params), loc);
}

void SceneBuilder::makeNamedMedium(const std::string& name, ParamList params, FileLoc loc) {
    checkStatic(loc);
    for (auto& m : desc_.media)
        if (m.name == name) {
            diag_.warning(loc, "named medium \"" + name + "\" redefined");
            m.params = std::move(params);
            m.loc = loc;
            m.worldFromMedium = gs_.ctm[0];
            m.type = m.params.getString("type", "");
            return;
        }
    MediumEntity m;
    m.name = name;
    m.assign(std::move(params), loc);
    m.type = m.params.getString("type", "");
    m.worldFromMedium = gs_.ctm[0];
    if (m.type.empty()) {
        diag_.error(loc, "MakeNamedMedium \"" + name + "\" has no \"string type\"");
        return;
    }
    desc_.media.push_back(std::move(m));
}

void SceneBuilder::mediumInterface(const std::string& inside, const std::string& outside,
                                   FileLoc loc) {
    gs_.inside = inside;
    gs_.outside = outside;
    gs_.mediumLoc = loc;
}

bool SceneBuilder::checkMedia(const FileLoc& loc) {
    bool ok = true;
    for (const std::string* n : {&gs_.inside, &gs_.outside})
        if (!n->empty() && !desc_.findMedium(*n)) {
            diag_.error(gs_.mediumLoc.file ? gs_.mediumLoc : loc,
                        "undefined medium \"" + *n + "\"");
            ok = false;
        }
    return ok;
}

void SceneBuilder::checkStatic(const FileLoc& loc) {
    if (gs_.ctm[0] != gs_.ctm[1])
        diag_.ignored(loc, "animated transforms (motion blur) are not supported; the start "
                           "transform is used");
}

void SceneBuilder::worldBegin(FileLoc loc) {
    if (phase_ != Phase::Options) {
        diag_.error(loc, phase_ == Phase::World ? "WorldBegin inside the world block"
                                                : "a second WorldBegin after WorldEnd");
        return;
    }
    if (!stack_.empty())
        diag_.error(stack_.back().loc, std::string(blockName(int(stack_.back().kind))) +
                                           " is still open at WorldBegin");
    phase_ = Phase::World;
    gs_.ctm[0] = gs_.ctm[1] = Mat4(1.f);
    activeMask_ = 3;
    namedCoordSys_["world"] = Mat4(1.f);
}

void SceneBuilder::worldEnd(FileLoc loc) {
    if (phase_ != Phase::World) {
        diag_.error(loc, phase_ == Phase::Options ? "WorldEnd without WorldBegin"
                                                  : "a second WorldEnd");
        return;
    }
    while (!stack_.empty()) {
        const Block& b = stack_.back();
        diag_.error(b.loc, std::string(blockName(int(b.kind))) + " without a matching " +
                               endName(int(b.kind)) + " before WorldEnd");
        stack_.pop_back();
    }
    phase_ = Phase::Ended;
    desc_.worldEnded = true;
}

void SceneBuilder::attributeBegin(FileLoc loc) {
    stack_.push_back({BlockKind::Attribute, loc, gs_});
}
void SceneBuilder::transformBegin(FileLoc loc) {
    stack_.push_back({BlockKind::Transform, loc, gs_});
}

void SceneBuilder::popBlock(BlockKind kind, const char* directive, const FileLoc& loc) {
    if (stack_.empty()) {
        diag_.error(loc, std::string(directive) + " without a matching " +
                             blockName(int(kind)));
        return;
    }
    Block& b = stack_.back();
    if (b.kind != kind) {
        diag_.error(loc, std::string(directive) + " does not match the " +
                             blockName(int(b.kind)) + " at " + b.loc.str());
        return;
    }
    if (kind == BlockKind::Transform) {
        gs_.ctm[0] = b.state.ctm[0];
        gs_.ctm[1] = b.state.ctm[1];
    } else {
        gs_ = b.state;
    }
    stack_.pop_back();
}

void SceneBuilder::attributeEnd(FileLoc loc) { popBlock(BlockKind::Attribute, "AttributeEnd", loc); }
void SceneBuilder::transformEnd(FileLoc loc) { popBlock(BlockKind::Transform, "TransformEnd", loc); }

void SceneBuilder::texture(const std::string& name, const std::string& type,
                           const std::string& texClass, ParamList params, FileLoc loc) {
    if (!inWorld("Texture", loc)) return;
    bool isFloat = type == "float";
    if (!isFloat && type != "spectrum" && type != "color" && type != "rgb") {
        diag_.error(loc, "texture \"" + name + "\" has unknown type \"" + type +
                             "\"; expected \"float\" or \"spectrum\"");
        return;
    }
    checkStatic(loc);
    TextureEntity t;
    t.name = name;
    t.type = texClass;
    t.isFloat = isFloat;
    t.assign(std::move(params), loc);
    t.worldFromTexture = gs_.ctm[0];
    t.textures = gs_.textures;
    int index = int(desc_.textures.size());
    desc_.textures.push_back(std::move(t));
    auto scope = std::make_shared<TextureScope>(*gs_.textures);
    auto& map = isFloat ? scope->floatTextures : scope->spectrumTextures;
    if (map.count(name)) diag_.warning(loc, "texture \"" + name + "\" redefined");
    map[name] = index;
    gs_.textures = scope;
}

void SceneBuilder::material(const std::string& type, ParamList params, FileLoc loc) {
    if (!inWorld("Material", loc)) return;
    MaterialEntity m;
    m.assign(type, std::move(params), loc);
    m.textures = gs_.textures;
    gs_.material = int(desc_.materials.size());
    desc_.materials.push_back(std::move(m));
}

void SceneBuilder::makeNamedMaterial(const std::string& name, ParamList params, FileLoc loc) {
    if (!inWorld("MakeNamedMaterial", loc)) return;
    MaterialEntity m;
    m.name = name;
    m.assign(std::move(params), loc);
    m.textures = gs_.textures;
    const Param* t = m.params.find("type");
    if (!t || t->type != ParamType::String || t->strings.empty()) {
        diag_.error(loc, "named material \"" + name + "\" has no \"string type\" parameter");
        return;
    }
    m.type = m.params.getString("type", "");
    int index = int(desc_.materials.size());
    desc_.materials.push_back(std::move(m));
    auto named = std::make_shared<std::map<std::string, int>>(*gs_.namedMaterials);
    if (named->count(name)) diag_.warning(loc, "named material \"" + name + "\" redefined");
    (*named)[name] = index;
    gs_.namedMaterials = named;
}

void SceneBuilder::namedMaterial(const std::string& name, FileLoc loc) {
    if (!inWorld("NamedMaterial", loc)) return;
    auto it = gs_.namedMaterials->find(name);
    if (it == gs_.namedMaterials->end()) {
        // pbrt-v3 reports it and keeps the current material (a scene may use a name before
        // its MakeNamedMaterial).
        diag_.substituted(loc, "undefined named material \"" + name +
                                   "\"; the current material is kept (as pbrt-v3)");
        return;
    }
    gs_.material = it->second;
}

void SceneBuilder::lightSource(const std::string& type, ParamList params, FileLoc loc) {
    if (!inWorld("LightSource", loc)) return;
    checkStatic(loc);
    if (!checkMedia(loc)) return;
    if (currentObject_ >= 0) {
        diag_.error(loc, "LightSource inside ObjectBegin/ObjectEnd is not supported");
        return;
    }
    LightEntity l;
    l.assign(type, std::move(params), loc);
    l.worldFromLight = gs_.ctm[0];
    l.outsideMedium = gs_.outside;
    desc_.lights.push_back(std::move(l));
}

void SceneBuilder::areaLightSource(const std::string& type, ParamList params, FileLoc loc) {
    if (!inWorld("AreaLightSource", loc)) return;
    Entity e;
    e.assign(type, std::move(params), loc);
    gs_.areaLight = int(desc_.areaLights.size());
    desc_.areaLights.push_back(std::move(e));
}

void SceneBuilder::shape(const std::string& type, ParamList params, FileLoc loc) {
    if (!inWorld("Shape", loc)) return;
    checkStatic(loc);
    if (!checkMedia(loc)) return;
    ShapeEntity s;
    s.assign(type, std::move(params), loc);
    s.worldFromObject = gs_.ctm[0];
    s.reverseOrientation = gs_.reverseOrientation;
    s.material = gs_.material;
    s.areaLight = gs_.areaLight;
    s.insideMedium = gs_.inside;
    s.outsideMedium = gs_.outside;
    int index = int(desc_.shapes.size());
    if (currentObject_ >= 0) {
        if (s.areaLight >= 0) {
            diag_.ignored(loc, "area lights inside object instances are not supported (as in "
                               "pbrt-v3); the shape is not emissive");
            s.areaLight = -1;
        }
        desc_.objects[currentObject_].shapes.push_back(index);
    } else {
        desc_.worldShapes.push_back(index);
    }
    desc_.shapes.push_back(std::move(s));
}

void SceneBuilder::objectBegin(const std::string& name, FileLoc loc) {
    if (!inWorld("ObjectBegin", loc)) return;
    if (currentObject_ >= 0) {
        diag_.error(loc, "ObjectBegin \"" + name + "\" inside the definition of object \"" +
                             desc_.objects[currentObject_].name + "\"");
        return;
    }
    if (objectIndex_.count(name)) diag_.warning(loc, "object \"" + name + "\" redefined");
    stack_.push_back({BlockKind::Object, loc, gs_});
    currentObject_ = int(desc_.objects.size());
    objectIndex_[name] = currentObject_;
    desc_.objects.push_back({name, loc, {}});
}

void SceneBuilder::objectEnd(FileLoc loc) {
    if (!inWorld("ObjectEnd", loc)) return;
    if (currentObject_ < 0) {
        diag_.error(loc, "ObjectEnd without a matching ObjectBegin");
        return;
    }
    if (stack_.empty() || stack_.back().kind != BlockKind::Object) {
        popBlock(BlockKind::Object, "ObjectEnd", loc);  // reports the mismatch
        return;
    }
    popBlock(BlockKind::Object, "ObjectEnd", loc);
    currentObject_ = -1;
}

void SceneBuilder::objectInstance(const std::string& name, FileLoc loc) {
    if (!inWorld("ObjectInstance", loc)) return;
    if (currentObject_ >= 0) {
        diag_.error(loc, "ObjectInstance inside an object definition is not supported");
        return;
    }
    auto it = objectIndex_.find(name);
    if (it == objectIndex_.end()) {
        diag_.error(loc, "undefined object \"" + name + "\"");
        return;
    }
    checkStatic(loc);
    desc_.instances.push_back({it->second, gs_.ctm[0], loc});
}

void SceneBuilder::endOfFiles(FileLoc loc) {
    if (phase_ == Phase::Options) {
        diag_.error(loc, "end of input before WorldBegin: the scene has no world block");
    } else if (phase_ == Phase::World) {
        for (const Block& b : stack_)
            diag_.error(b.loc, std::string(blockName(int(b.kind))) + " without a matching " +
                                   endName(int(b.kind)));
        diag_.error(loc, "end of input inside the world block: missing WorldEnd");
    }
}

bool loadSceneDesc(const std::string& path, Diagnostics& diag, SceneDesc* out) {
    SceneBuilder builder(diag);
    bool ok = parseFile(path, builder, diag);
    *out = builder.takeDesc();
    return ok && diag.errorCount() == 0;
}

}  // namespace rlpbrt
