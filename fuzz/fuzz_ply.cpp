// libFuzzer target: the PLY reader on an in-memory file (ascii and binary bodies).
#include <cstddef>
#include <cstdint>
#include <string>

#include "parser/ply.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    rlpbrt::PlyMesh mesh;
    std::string error;
    bool ok = rlpbrt::readPlyFromMemory(reinterpret_cast<const char*>(data), size, &mesh, &error);
    if (ok) {
        // What the shape code relies on: whole triangles, indices within the vertices,
        // attribute arrays empty or one entry per vertex.
        if (mesh.indices.size() % 3 != 0 || mesh.positions.size() % 3 != 0) __builtin_trap();
        for (uint32_t i : mesh.indices)
            if (i >= mesh.vertexCount()) __builtin_trap();
        if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
            __builtin_trap();
        if (!mesh.uvs.empty() && mesh.uvs.size() / 2 != mesh.vertexCount()) __builtin_trap();
    } else if (error.empty()) {
        __builtin_trap();  // every failure has a message
    }
    return 0;
}
