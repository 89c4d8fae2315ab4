// Reader for PLY triangle meshes (ascii 1.0, binary_little_endian, binary_big_endian), as used
// by pbrt-v3's "plymesh" shape. Standard library only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace rlpbrt {

// A triangulated PLY mesh. Attribute arrays are either empty or hold one entry per vertex.
struct PlyMesh {
    std::vector<float> positions;   // x y z per vertex
    std::vector<float> normals;     // nx ny nz per vertex, or empty
    std::vector<float> uvs;         // u v per vertex, or empty
    std::vector<uint32_t> indices;  // triangles; quads split (0,1,2),(0,2,3); n-gons fanned
    size_t quadCount = 0, polygonCount = 0;  // faces split (quads; polygons with > 4 vertices)

    size_t vertexCount() const { return positions.size() / 3; }
    size_t triangleCount() const { return indices.size() / 3; }
};

// Reads the PLY file at `path` into *mesh (replacing its contents). On failure returns false
// and sets *error to a message without location prefix that names the PLY line (ascii) or
// byte offset (binary) where the problem was found.
bool readPly(const std::string& path, PlyMesh* mesh, std::string* error);

// Same as readPly() but decodes a PLY file already held in memory (`size` bytes at `data`).
bool readPlyFromMemory(const char* data, size_t size, PlyMesh* mesh, std::string* error);

}  // namespace rlpbrt
