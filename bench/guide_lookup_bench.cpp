// Lookup cost per query of the guiding backends: vdb (OpenVDB grid, three accessor modes,
// several voxel sizes) against hemi (nanoflann kd-tree over surface points), on
// ../shared/scenes/cornell-box/scene.small.pbrt. Queries are uniform random surface points
// with their normal (what the integrator asks at path vertices), in random order: the worst
// case for the accessors' caches. Counters: bytes of the field (MiB), regions, active voxels.
//   build/bench/rlpbrt_bench --benchmark_filter=Lookup
#include <benchmark/benchmark.h>

#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "guiding/guiding.h"
#include "guiding/vdb.h"
#include "parser/diagnostics.h"
#include "render/integrator.h"
#include "render/scene.h"
#include "render/scene_builder.h"

namespace rlpbrt {
namespace {

struct Query {
    glm::vec3 p, n;
};

struct Fixture {
    std::unique_ptr<Scene> scene;
    std::vector<Query> queries;  // power of two
};

Fixture& fixture() {
    static Fixture f = [] {
        Fixture fx;
        Diagnostics diag;
        diag.setStream(nullptr);
        SceneDesc desc;
        const std::string path =
            std::string(RLPBRT_SOURCE_DIR) + "/../shared/scenes/cornell-box/scene.small.pbrt";
        if (!loadSceneDesc(path, diag, &desc)) return fx;
        BuildOptions bo;
        fx.scene = buildScene(desc, bo, diag);
        if (!fx.scene) return fx;
        std::mt19937_64 rng(1);
        std::uniform_real_distribution<float> uni(0.f, 1.f);
        while (fx.queries.size() < (1u << 16)) {
            Query q;
            if (fx.scene->sampleSurface(glm::vec3(uni(rng), uni(rng), uni(rng)), &q.p, &q.n))
                fx.queries.push_back(q);
        }
        return fx;
    }();
    return f;
}

std::unique_ptr<guiding::GuidingField> makeField(const std::string& backend,
                                                 std::map<std::string, std::string> params) {
    Fixture& fx = fixture();
    if (!fx.scene) return nullptr;
    guiding::GuideConfig gc;
    gc.backend = backend;
    gc.params = std::move(params);
    std::unique_ptr<guiding::GuidingField> field;
    GuideSettings settings;
    std::string err;
    if (!setupGuiding(*fx.scene, gc, &field, &settings, &err)) return nullptr;
    return field;
}

void runLookups(benchmark::State& state, const guiding::GuidingField& field) {
    const std::vector<Query>& q = fixture().queries;
    const size_t mask = q.size() - 1;
    size_t i = 0, misses = 0;
    for (auto _ : state) {
        const Query& x = q[i++ & mask];
        int r = field.lookup(x.p, x.n);
        misses += r < 0;
        benchmark::DoNotOptimize(r);
    }
    state.SetItemsProcessed(int64_t(state.iterations()));
    state.counters["MiB"] = double(field.bytes()) / (1024.0 * 1024.0);
    state.counters["miss_frac"] = double(misses) / double(std::max<size_t>(i, 1));
}

void BM_LookupHemi(benchmark::State& state) {
    auto field = makeField("hemi", {{"points", std::to_string(state.range(0))}});
    if (!field) return state.SkipWithError("no scene (../shared missing?)");
    runLookups(state, *field);
}
BENCHMARK(BM_LookupHemi)->Arg(2048)->Arg(8192)->Arg(32768);

// Args: voxels along the longest axis (0 = default size), accessor mode (0 per lookup,
// 1 per thread, 2 uncached, 3 hybrid = the default).
void BM_LookupVdb(benchmark::State& state) {
    std::map<std::string, std::string> params;
    if (state.range(0) > 0) params["voxel"] = std::to_string(state.range(0));
    auto field = makeField("vdb", params);
    if (!field) return state.SkipWithError("no scene (../shared missing?)");
    auto* vdb = dynamic_cast<guiding::VdbField*>(field.get());
    vdb->setAccessor(static_cast<guiding::VdbField::Accessor>(state.range(1)));
    runLookups(state, *field);
    state.counters["voxels"] = double(vdb->activeVoxels());
    state.counters["voxel_size"] = vdb->voxelSize();
    state.counters["grid_KiB"] = double(vdb->gridBytes()) / 1024.0;
}
BENCHMARK(BM_LookupVdb)
    ->Args({0, 0})
    ->Args({0, 1})
    ->Args({0, 2})
    ->Args({0, 3})
    ->Args({16, 3})
    ->Args({32, 3})
    ->Args({64, 3})
    ->Args({128, 3});  // 256: ~1.3 GiB, refused by the default max-mb

}  // namespace
}  // namespace rlpbrt
