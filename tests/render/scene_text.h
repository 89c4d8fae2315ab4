// A scene from pbrt text, parsed and built as the command line does (without its files), for
// the renderer's tests.
#pragma once

#include <memory>
#include <string>

#include "parser/diagnostics.h"
#include "parser/parser.h"
#include "render/scene.h"
#include "render/scene_builder.h"

namespace rlpbrt::test {

// Parses `text` (called `name` in messages) and builds it; null on an error, which `diag`
// then holds (it prints nothing).
inline std::unique_ptr<Scene> sceneFromText(const std::string& text, const std::string& name,
                                            Diagnostics& diag,
                                            const BuildOptions& options = BuildOptions()) {
    diag.setStream(nullptr);
    SceneBuilder builder(diag);
    if (!parseString(text, name, builder, diag)) return nullptr;
    const SceneDesc desc = builder.takeDesc();
    return buildScene(desc, options, diag);
}

// The same where the diagnostics do not matter.
inline std::unique_ptr<Scene> sceneFromText(const std::string& text, const std::string& name,
                                            const BuildOptions& options = BuildOptions()) {
    Diagnostics diag;
    return sceneFromText(text, name, diag, options);
}

}  // namespace rlpbrt::test
