#include "guiding/options.h"

namespace rlpbrt::guiding {

namespace {
using O = GuideOption;
constexpr const char* kIntegrator = "integrator";
constexpr const char* kField = "field";
}  // namespace

const std::vector<GuideOption>& guideOptions() {
    static const std::vector<GuideOption> options = {
        // How the integrator uses the guide (any backend).
        {"mix", O::kBoth, kIntegrator, "0.5", "a number in [0, 1] or \"learn\"",
         "probability of sampling a direction from the guide (mixed with the BSDF); learn: "
         "learned per region from the samples' second moments"},
        {"target", O::kBoth, kIntegrator, "path", "\"sum\", \"sample\" or \"path\"",
         "what a guided vertex learns: the light its path brought back (path), or the "
         "paper's Eq. 1 bootstrap, summed over strata (sum) or by the sampled direction "
         "(sample)"},
        {"rr", O::kBoth, kIntegrator, "adjoint", "\"adjoint\" or \"pbrt\"",
         "Russian roulette on the expected contribution from the learned light against the "
         "pixel's estimate (adjoint), or pbrt-v3's on the throughput"},
        {"rr-window", O::kBoth, kIntegrator, "0.1", "a number in (0, 1]",
         "the adjoint roulette's window: paths below this share of the pixel estimate play"},
        {"split", O::kBoth, kIntegrator, "16", "an integer in 1..64",
         "splitting: a vertex whose expected contribution exceeds split-window x the pixel's "
         "estimate continues as up to this many paths (1: off)"},
        {"split-window", O::kBoth, kIntegrator, "1", "a positive number",
         "split: the multiple of the pixel's estimate above which a path splits"},
        {"lights", O::kBoth, kIntegrator, "learned", "\"learned\" or \"scene\"",
         "next-event estimation's light selection: learned per region from what its shadow "
         "rays found, mixed with the scene's lightsamplestrategy (scenes of 2 to 16 lights, "
         "hemi), or the scene's strategy alone"},
        {"samples", O::kBoth, kIntegrator, "sequence", "\"sequence\" or \"independent\"",
         "passes continue one low-discrepancy sequence per pixel, or draw independent sets "
         "(exactly unbiased, less stratified)"},
        {"learn", O::kBoth, kIntegrator, "all", "\"all\" or a sample count in [0, 16777216]",
         "learn in every pass, or in the first N spp only (0 with --guide-load: a trained "
         "guide)"},
        {"auto", O::kBoth, kIntegrator, "0",
         "a sample count in [0, 16777216] (0 = always guide)",
         "after N spp compare a guided and a plain pass and render the rest plain if guiding "
         "does not pay"},
        // The learned tables (hemi and vdb).
        {"strata", O::kBoth, kField, "16x16", "WxH or N with integers in 1..64",
         "strata per hemisphere: W in azimuth, H in cos(theta)"},
        {"alpha", O::kBoth, kField, "visits", "'visits' or a number in (0, 1]",
         "learning rate: 1 / (1 + visits) (a running mean) or a fixed rate"},
        {"init", O::kBoth, kField, "1e-3", "a positive number <= 3.4e38",
         "initial Q of every stratum"},
        {"epsilon", O::kBoth, kField, "0.1", "a number in [0, 1]",
         "uniform share mixed into every stratum distribution"},
        {"cosine", O::kBoth, kField, "1", "0 or 1",
         "sample strata in proportion to Q cos(theta) (1) or Q alone (0)"},
        {"smooth", O::kBoth, kField, "2", "a number in [0, 1e9]",
         "prior strength, in visits, that shrinks a stratum towards the mean of its "
         "neighbours (0: off)"},
        {"warmup", O::kBoth, kField, "8", "a number in [0, 1e9]",
         "records per stratum before a region's guide gets the full mix (0: at once)"},
        {"learn-cap", O::kBoth, kField, "256", "a number in [0, 1e9]",
         "records per stratum (a region's mean) after which a region stops learning and "
         "keeps its guide (0: never)"},
        {"prune", O::kBoth, kField, "hemi: 0.3; vdb: 0", "a number in [0, 1e9]",
         "a learned region (surfaces; hemi: without spot lobes) samples the BSDF alone where "
         "the cosine sampling of its learned light has at most this relative variance "
         "(0: never)"},
        {"normal-angle", O::kBoth, kField, "30", "degrees in (0, 180)",
         "admissible deviation between a vertex's normal and a region's"},
        {"points", O::kBoth, kField,
         "hemi: 1024; vdb: 16 per voxel's worth of surface (65536 .. 2^24)",
         "an integer in 1..67108864",
         "surface samples: hemi's regions (two hemispheres each); vdb's voxel activation"},
        {"max-mb", O::kBoth, kField, "4096", "a positive number",
         "refuse configurations whose tables would exceed this many MiB"},
        // hemi only.
        {"knn", O::kHemi, kField, "8", "an integer in 1..64",
         "nearest points checked for an admissible normal"},
        {"lookup", O::kHemi, kField, "patch", "patch, cell or exact",
         "how a vertex finds its point: memo per surface patch, memo per grid cell, or a "
         "kd-tree query per vertex"},
        {"directions", O::kHemi, kField, "strata", "strata or tree",
         "each hemisphere's directions: the fixed strata, or an adaptive quadtree refined "
         "where the learned light concentrates (experimental; no --guide-save)"},
        {"tree-split", O::kHemi, kField, "0.03", "a number in (0, 1]",
         "directions=tree: a node splits while it holds more than this share of its "
         "hemisphere's learned light"},
        {"tree-depth", O::kHemi, kField, "12", "an integer in 1..16",
         "directions=tree: the deepest level (leaf edge 2^-depth of the square)"},
        {"judge", O::kHemi, kField, "0.8", "a number in [0, 1]",
         "once the regions' visit-weighted confidence reaches 0.5: if the guide's mixture "
         "would keep more than this share of cosine sampling's second moment, direction "
         "guiding stops for good (0: never)"},
        {"spot-judge", O::kHemi, kField, "3", "a number >= 0",
         "once the regions' visit-weighted confidence reaches 0.8: if their spot lobes' "
         "visit-weighted worth (light share x how many times narrower than a stratum) is "
         "below this, the lobes stop for good (0: never)"},
        {"spots", O::kHemi, kField, "4 (0 with directions=tree)", "an integer in 0..16",
         "narrow lobes per hemisphere aimed at small bright spots that a stratum is too coarse "
         "for (a lamp's opening, a light's highlight on a near-specular surface; 0: off)"},
        {"spot-share", O::kHemi, kField, "0.5", "a number in (0, 1]",
         "spots: the largest probability of the lobes within the guide"},
        {"spot-outlier", O::kHemi, kField, "5", "a number >= 1",
         "spots: a direction's light at the next vertex must exceed this multiple of its "
         "stratum's estimate to shape a lobe"},
        // vdb only.
        {"voxel", O::kVdb, kField, "sqrt(area / 1024) as the edge",
         "a voxel count along the longest axis, 1..4096",
         "voxels along the longest axis of the scene (not with voxel-size)"},
        {"voxel-size", O::kVdb, kField, "sqrt(area / 1024)",
         "a positive voxel edge in world units", "the voxel edge in world units"},
        {"dirs", O::kVdb, kField, "hemi", "hemi or sphere",
         "two hemisphere tables per dominant normal, or one full-sphere table per voxel"},
        {"normals", O::kVdb, kField, "4", "an integer in 1..16",
         "dominant normals per voxel (two hemispheres each)"},
        {"volume", O::kVdb, kField, "1", "0 or 1",
         "guide at medium vertices too (scenes with media)"},
        {"volume-voxel", O::kVdb, kField, "32",
         "a voxel count along the longest axis of the media, 1..1024",
         "medium voxels along the longest axis of the media"},
        {"volume-strata", O::kVdb, kField, "8x8", "WxH or N with integers in 1..64",
         "the medium tables' strata per hemisphere"},
        {"volume-warmup", O::kVdb, kField, "16", "a number in [0, 1e9]",
         "the medium tables' warmup"},
    };
    return options;
}

const GuideOption* findGuideOption(const std::string& key) {
    for (const GuideOption& o : guideOptions())
        if (key == o.key) return &o;
    return nullptr;
}

namespace {
unsigned backendBit(const std::string& backend) {
    return backend == "hemi" ? GuideOption::kHemi : backend == "vdb" ? GuideOption::kVdb : 0u;
}
const char* backendsText(unsigned b) {
    return b == GuideOption::kBoth ? "hemi, vdb" : b == GuideOption::kHemi ? "hemi" : "vdb";
}
}  // namespace

const GuideOption* findGuideOption(const std::string& key, const std::string& backend) {
    const GuideOption* o = findGuideOption(key);
    return o && (o->backends & backendBit(backend)) ? o : nullptr;
}

std::string knownGuideOptions(const std::string& backend) {
    std::string out;
    for (const GuideOption& o : guideOptions()) {
        if (!(o.backends & backendBit(backend))) continue;
        if (!out.empty()) out += ", ";
        out += o.key;
    }
    return out;
}

std::string guideOptionsHelp() {
    std::string out;
    for (const GuideOption& o : guideOptions()) {
        out += std::string("  ") + o.key + "=" + o.defaultValue + "  [" +
               backendsText(o.backends) + "]\n      " + o.help + "\n";
    }
    return out;
}

std::string guideOptionsMarkdown() {
    std::string out = "| key | backends | default | values | meaning |\n|---|---|---|---|---|\n";
    for (const GuideOption& o : guideOptions()) {
        out += std::string("| `") + o.key + "` | " + backendsText(o.backends) + " | `" +
               o.defaultValue + "` | " + o.expected + " | " + o.help + " |\n";
    }
    return out;
}

}  // namespace rlpbrt::guiding
