// Shapes as render data: triangle meshes, analytic quadrics and curves, made from Shape
// entities (trianglemesh, plymesh, loopsubdiv, heightfield, nurbs, sphere, disk, cylinder, curve,
// ...). No Embree here: scene.cpp turns these into Embree geometry.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "parser/diagnostics.h"
#include "render/curves.h"
#include "render/math.h"
#include "render/quadrics.h"
#include "render/scene_desc.h"

namespace rlpbrt {

// A triangle mesh in world space (or in object space for shapes inside ObjectBegin).
struct TriangleMesh {
    std::vector<Vec3> p;
    std::vector<Vec3> n;   // per-vertex shading normals, or empty
    std::vector<Vec3> s;   // per-vertex shading tangents, or empty
    std::vector<Vec2> uv;  // per-vertex uv, or empty (pbrt-v3's (0,0),(1,0),(1,1) then)
    std::vector<uint32_t> indices;
    // Geometric normals are flipped (when there are no shading normals) because of
    // ReverseOrientation xor a handedness-swapping transform, as in pbrt-v3.
    bool flipNormals = false;
    size_t triangleCount() const { return indices.size() / 3; }
    float triangleArea(size_t tri) const;
};

// An analytic quadric placed in the world (or in an object's space) by a transform.
struct QuadricShape {
    Quadric quadric;
    Mat4 worldFromObject{1.f}, objectFromWorld{1.f};
    bool flipNormals = false;  // ReverseOrientation xor handedness swap
};

// The geometry made from one Shape directive.
struct ShapeData {
    std::shared_ptr<TriangleMesh> mesh;          // set for mesh shapes
    std::shared_ptr<QuadricShape> quadric;       // set for quadrics
    std::shared_ptr<CurveShape> curve;           // set for curves (curves.h)
    std::string type;                            // the directive's type name
    FileLoc loc;
    size_t triangleCount() const { return mesh ? mesh->triangleCount() : 0; }
};

// Creates the geometry of a Shape entity, with the entity's CTM applied (for shapes inside
// ObjectBegin/End that is the object's space; instances add their own transform on top).
// Unsupported shapes are reported
// as ignored features (warning with location) and produce no data (returns false); errors
// (bad parameters, unreadable files) are reported as errors.
bool createShape(const ShapeEntity& e, Diagnostics& diag, ShapeData* out);

}  // namespace rlpbrt
