// Loop subdivision surfaces with pbrt-v3's "loopsubdiv" semantics.
#pragma once

#include <string>
#include <vector>

#include "render/math.h"

namespace rlpbrt {

// Subdivides the triangle mesh (indices into P, three per triangle) nLevels times with Loop's
// rules (pbrt-v3's beta for interior vertices, 3/4-1/8 boundary rule), pushes the vertices to
// the limit surface and computes unit per-vertex normals from the limit tangents. Normals
// follow the winding (outward for a closed mesh wound counter-clockwise seen from outside).
// Vertices not referenced by any face are dropped. Returns false with *error for bad input
// (index out of range, degenerate face, edge shared by more than two faces, inconsistently
// oriented neighbours, non-manifold vertex, non-finite position, result too large).
bool loopSubdivide(int nLevels, const std::vector<int>& indices, const std::vector<Vec3>& P,
                   std::vector<Vec3>* outP, std::vector<Vec3>* outN,
                   std::vector<int>* outIndices, std::string* error);

}  // namespace rlpbrt
