#include "guiding/guiding.h"

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <new>
#include <stdexcept>
#include <cstdlib>

#include "guiding/hemi.h"
#include "guiding/options.h"
#include "guiding/vdb.h"

namespace rlpbrt::guiding {

GuidingField::~GuidingField() = default;

float GuidingField::confidence(int region) const { return region >= 0 ? 1.f : 0.f; }

bool GuidingField::learns(int) const { return true; }

bool GuidingField::guides(int) const { return true; }

float GuidingField::selection(int) const { return -1.f; }

float GuidingField::policyRadiance(int region, const glm::vec3& w, int bin) const {
    return radiance(region, w, bin);
}

void GuidingField::recordSelection(int, int, const SelectionSample&) {}

void GuidingField::prefetch(const VertexQuery&) const {}
float GuidingField::patchSize() const { return 0.f; }
void GuidingField::setPatches(uint32_t, std::function<bool(uint32_t, glm::vec3*, glm::vec3*)>) {}

void GuidingField::requestMedium(int, const glm::vec3&) {}

glm::vec3 GuidingField::sampleAt(int region, const glm::vec3&, glm::vec2 u, float uPick,
                                 float* pdf, int* bin) const {
    return sample(region, u, uPick, pdf, bin);
}
float GuidingField::pdfAt(int region, const glm::vec3&, const glm::vec3& w, int* bin) const {
    return pdf(region, w, bin);
}
void GuidingField::recordSpot(int, int, const glm::vec3&, const glm::vec3&, const glm::vec3&,
                              float, int) {}
bool GuidingField::learnsSpots() const { return false; }
bool GuidingField::guidesMedia() const { return false; }
bool GuidingField::enableChoices(int) { return false; }
GuidingField::Choice GuidingField::choice(int) const { return Choice(); }
void GuidingField::recordChoice(int, int, int, float) {}

void SumAcrossProcesses::sumCounts(std::vector<uint64_t>& v, double bound) const {
    if (bound < countLimit) {
        std::vector<uint32_t> c(v.begin(), v.end());
        counts(c);
        std::copy(c.begin(), c.end(), v.begin());
    } else {
        std::vector<double> c(v.begin(), v.end());
        doubles(c);
        for (size_t i = 0; i < c.size(); ++i) v[i] = uint64_t(c[i]);
    }
}

void GuidingField::endPassShared(const SumAcrossProcesses&) { endPass(); }

bool GuidingField::sharesPasses() const { return false; }

float GuidingField::irradianceEstimate(int region, const glm::vec3& n) const {
    return scatteredEstimate(region,
                             [&n](const glm::vec3& w) { return std::max(0.f, glm::dot(w, n)); });
}

bool GuidingField::save(const std::string&, std::string* error) const {
    *error = "this guiding backend cannot save its field";
    return false;
}

bool GuidingField::load(const std::string&, std::string* error) {
    *error = "this guiding backend cannot load a field";
    return false;
}

bool GuidingField::saveState(std::string*, std::string* error) const {
    *error = "this guiding backend cannot save its learning state";
    return false;
}

bool GuidingField::loadState(const std::string&, std::string* error) {
    *error = "this guiding backend cannot restore a learning state";
    return false;
}

namespace {

// Parses a whole string as a finite double.
bool parseDouble(const std::string& s, double* out) {
    if (s.empty()) return false;
    const char* begin = s.c_str();
    char* end = nullptr;
    errno = 0;
    double v = std::strtod(begin, &end);
    if (end != begin + s.size() || errno == ERANGE || !std::isfinite(v)) return false;
    *out = v;
    return true;
}

// Parses a whole string of decimal digits as an unsigned integer <= maxValue.
bool parseUnsigned(const std::string& s, uint64_t maxValue, uint64_t* out) {
    if (s.empty() || s.size() > 19) return false;
    uint64_t v = 0;
    for (char c : s) {
        if (c < '0' || c > '9') return false;
        v = v * 10 + uint64_t(c - '0');
    }
    if (v > maxValue) return false;
    *out = v;
    return true;
}

// The "bad value" message of a backend's parameter, with what the options table
// (guiding/options.h) says it accepts; returns false.
bool badValue(const char* backend, const std::string& key, const std::string& value,
              std::string* error) {
    const GuideOption* o = findGuideOption(key);
    *error = std::string("guiding backend '") + backend + "': bad value '" + value +
             "' for parameter '" + key + "' (expected " + (o ? o->expected : "?") + ")";
    return false;
}

// The "unknown parameter" message of a backend; returns false.
bool unknownParam(const char* backend, const std::string& key, std::string* error) {
    *error = std::string("guiding backend '") + backend + "': unknown parameter '" + key +
             "' (known: " + knownGuideOptions(backend) + ")";
    return false;
}

// A strata value, "WxH" or "N" (N x N), with integers in 1..64; false if it is anything else.
bool parseStrata(const std::string& value, int* cols, int* rows) {
    const size_t x = value.find_first_of("xX");
    uint64_t w = 0, h = 0;
    if (x == std::string::npos) {
        if (!parseUnsigned(value, 64, &w)) return false;
        h = w;
    } else if (!parseUnsigned(value.substr(0, x), 64, &w) ||
               !parseUnsigned(value.substr(x + 1), 64, &h)) {
        return false;
    }
    if (w < 1 || h < 1) return false;
    *cols = int(w);
    *rows = int(h);
    return true;
}

// The parameters hemi and vdb share (same names, ranges and members): 1 if `key` is one of
// them and its value is valid, 0 if it is not a shared key, -1 (and *error) on a bad value.
template <class Params>
int parseSharedParam(const char* backend, const std::string& key, const std::string& value,
                     Params* p, double* maxMiB, std::string* error) {
    auto bad = [&]() {
        badValue(backend, key, value, error);
        return -1;
    };
    double d = 0.0;
    uint64_t u = 0;
    if (key == "alpha") {
        if (value == "visits") {
            p->alphaVisits = true;
        } else if (parseDouble(value, &d) && d > 0.0 && d <= 1.0) {
            p->alphaVisits = false;
            p->fixedAlpha = d;
        } else {
            return bad();
        }
    } else if (key == "strata") {
        if (!parseStrata(value, &p->cols, &p->rows))
            return bad();
    } else if (key == "points") {
        if (!parseUnsigned(value, uint64_t(1) << 26, &u) || u < 1)
            return bad();
        p->points = u;
    } else if (key == "normal-angle") {
        if (!parseDouble(value, &d) || !(d > 0.0) || !(d < 180.0))
            return bad();
        p->normalAngleDeg = d;
    } else if (key == "init") {
        if (!parseDouble(value, &d) || !(d > 0.0) || d > double(FLT_MAX))
            return bad();
        p->init = d;
    } else if (key == "epsilon") {
        if (!parseDouble(value, &d) || d < 0.0 || d > 1.0) return bad();
        p->epsilon = d;
    } else if (key == "cosine") {
        if (value != "0" && value != "1") return bad();
        p->cosine = value == "1";
    } else if (key == "smooth") {
        if (!parseDouble(value, &d) || d < 0.0 || d > 1e9) return bad();
        p->smooth = d;
    } else if (key == "warmup") {
        if (!parseDouble(value, &d) || d < 0.0 || d > 1e9) return bad();
        p->warmup = d;
    } else if (key == "learn-cap") {
        if (!parseDouble(value, &d) || d < 0.0 || d > 1e9) return bad();
        p->learnCap = d;
    } else if (key == "prune") {
        if (!parseDouble(value, &d) || !(d >= 0.0) || d > 1e9) return bad();
        p->prune = d;
    } else if (key == "max-mb") {
        if (!parseDouble(value, &d) || !(d > 0.0)) return bad();
        *maxMiB = d;
    } else if (const GuideOption* o = findGuideOption(key);
               o && std::string(o->owner) == "integrator") {
        // Consumed by the integrator and the render loop.
    } else {
        return 0;
    }
    return 1;
}

// hemi's spot lobes per region by default (issue 30: veach-bidir's lamp openings; the
// measurement is in docs/BENCHMARKS.md, "Spot lobes").
constexpr int kDefaultSpots = 4;

// Reads the hemi parameters; false and *error on an unknown key or a bad value.
bool parseHemiParams(const std::map<std::string, std::string>& params, HemiParams* hp,
                     double* maxMiB, std::string* error) {
    for (const auto& [key, value] : params) {
        if (key == "target") hp->bootstrapTargets = value != "path";  // (validated elsewhere)
        const int shared = parseSharedParam("hemi", key, value, hp, maxMiB, error);
        if (shared < 0) return false;
        if (shared > 0) continue;
        uint64_t u = 0;
        if (key == "knn") {
            if (!parseUnsigned(value, 64, &u) || u < 1)
                return badValue("hemi", key, value, error);
            hp->knn = int(u);
        } else if (key == "lookup") {
            if (value != "patch" && value != "cell" && value != "exact")
                return badValue("hemi", key, value, error);
            hp->cellLookup = value != "exact";
            hp->patchLookup = value == "patch";
        } else if (key == "directions") {
            if (value != "strata" && value != "tree") return badValue("hemi", key, value, error);
            hp->treeDirections = value == "tree";
        } else if (key == "tree-split") {
            double d = 0.0;
            if (!parseDouble(value, &d) || !(d > 0.0) || d > 1.0)
                return badValue("hemi", key, value, error);
            hp->treeSplit = d;
        } else if (key == "tree-depth") {
            if (!parseUnsigned(value, uint64_t(DirTree::kMaxDepth), &u) || u < 1)
                return badValue("hemi", key, value, error);
            hp->treeDepth = int(u);
        } else if (key == "judge") {
            double d = 0.0;
            if (!parseDouble(value, &d) || !(d >= 0.0) || d > 1.0)
                return badValue("hemi", key, value, error);
            hp->judge = d;
        } else if (key == "spot-judge") {
            double d = 0.0;
            if (!parseDouble(value, &d) || !(d >= 0.0) || !std::isfinite(d))
                return badValue("hemi", key, value, error);
            hp->spotJudge = d;
        } else if (key == "spots") {
            if (!parseUnsigned(value, 16, &u)) return badValue("hemi", key, value, error);
            hp->spots = int(u);
        } else if (key == "spot-share") {
            double d = 0.0;
            if (!parseDouble(value, &d) || !(d > 0.0) || d > 1.0)
                return badValue("hemi", key, value, error);
            hp->spotShare = d;
        } else if (key == "spot-outlier") {
            double d = 0.0;
            if (!parseDouble(value, &d) || !(d >= 1.0) || d > 1e9)
                return badValue("hemi", key, value, error);
            hp->spotOutlier = d;
        } else {
            return unknownParam("hemi", key, error);
        }
    }
    if (hp->spots > 0 && hp->treeDirections) {
        *error = "guiding backend 'hemi': spots need directions=strata";
        return false;
    }
    if (hp->spots < 0) hp->spots = hp->treeDirections ? 0 : kDefaultSpots;
    return true;
}

// Reads the vdb parameters; false and *error on an unknown key or a bad value.
bool parseVdbParams(const std::map<std::string, std::string>& params, VdbParams* vp,
                    double* maxMiB, std::string* error) {
    for (const auto& [key, value] : params) {
        const int shared = parseSharedParam("vdb", key, value, vp, maxMiB, error);
        if (shared < 0) return false;
        if (shared > 0) continue;
        double d = 0.0;
        uint64_t u = 0;
        if (key == "voxel") {
            if (!parseUnsigned(value, 4096, &u) || u < 1)
                return badValue("vdb", key, value, error);
            vp->voxelCount = int(u);
        } else if (key == "voxel-size") {
            if (!parseDouble(value, &d) || !(d > 0.0))
                return badValue("vdb", key, value, error);
            vp->voxelSize = d;
        } else if (key == "dirs") {
            if (value != "hemi" && value != "sphere")
                return badValue("vdb", key, value, error);
            vp->sphere = value == "sphere";
        } else if (key == "normals") {
            if (!parseUnsigned(value, 16, &u) || u < 1)
                return badValue("vdb", key, value, error);
            vp->normals = int(u);
        } else if (key == "volume") {
            if (value != "0" && value != "1") return badValue("vdb", key, value, error);
            vp->volume = value == "1";
        } else if (key == "volume-strata") {
            if (!parseStrata(value, &vp->volumeCols, &vp->volumeRows))
                return badValue("vdb", key, value, error);
        } else if (key == "volume-warmup") {
            if (!parseDouble(value, &d) || d < 0.0 || d > 1e9)
                return badValue("vdb", key, value, error);
            vp->volumeWarmup = d;
        } else if (key == "volume-voxel") {
            if (!parseUnsigned(value, 1024, &u) || u < 1)
                return badValue("vdb", key, value, error);
            vp->volumeVoxels = int(u);
        } else {
            return unknownParam("vdb", key, error);
        }
    }
    if (vp->voxelCount > 0 && vp->voxelSize > 0.0) {
        *error = "guiding backend 'vdb': give 'voxel' (a count) or 'voxel-size' (world units), "
                 "not both";
        return false;
    }
    return true;
}

}  // namespace

std::unique_ptr<GuidingField> createGuidingField(const GuideConfig& config,
                                                 const SceneInfo& scene, std::string* error) {
    std::string scratch;
    if (!error) error = &scratch;
    error->clear();
    if (config.backend == "none") return nullptr;
    if (config.backend == "hemi") {
        HemiParams hp;
        double maxMiB = 4096.0;
        if (!parseHemiParams(config.params, &hp, &maxMiB, error)) return nullptr;
        if (!scene.samplePoint) {
            *error = "guiding backend 'hemi': the scene provides no surface sampler";
            return nullptr;
        }
        double mib = hemiEstimatedBytes(hp) / (1024.0 * 1024.0);
        if (mib > maxMiB) {
            char buf[256];
            std::snprintf(buf, sizeof(buf),
                          "guiding backend 'hemi': %llu points with %dx%d strata need about "
                          "%.0f MiB, more than max-mb=%g",
                          (unsigned long long)hp.points, hp.cols, hp.rows, mib, maxMiB);
            *error = buf;
            return nullptr;
        }
        try {
            return std::make_unique<HemiField>(hp, scene);
        } catch (const std::bad_alloc&) {
            *error = "guiding backend 'hemi': out of memory for the tables";
            return nullptr;
        }
    }
    if (config.backend == "vdb") {
        VdbParams vp;
        double maxMiB = 4096.0;
        if (!parseVdbParams(config.params, &vp, &maxMiB, error)) return nullptr;
        if (!scene.samplePoint) {
            *error = "guiding backend 'vdb': the scene provides no surface sampler";
            return nullptr;
        }
        const double mib = vdbEstimatedBytes(vp, scene) / (1024.0 * 1024.0);
        if (mib > maxMiB) {
            char buf[256];
            std::snprintf(buf, sizeof(buf),
                          "guiding backend 'vdb': voxel size %g with %dx%d strata needs up to "
                          "about %.0f MiB, more than max-mb=%g",
                          vdbVoxelSize(vp, scene), vp.cols, vp.rows, mib, maxMiB);
            *error = buf;
            return nullptr;
        }
        // The volume tables grow during rendering: they get the rest of the budget.
        vp.volumeMaxVoxels = uint64_t(
            std::max(0.0, (maxMiB - mib) * 1024.0 * 1024.0 / vdbMediumCellBytes(vp)));
        // OpenVDB reports trouble (e.g. an allocation) by exceptions: a message, not a crash.
        try {
            return std::make_unique<VdbField>(vp, scene);
        } catch (const std::exception& e) {
            *error = std::string("guiding backend 'vdb': ") + e.what();
            return nullptr;
        }
    }
    *error = "unknown guiding backend '" + config.backend + "' (available: none, hemi, vdb)";
    return nullptr;
}

}  // namespace rlpbrt::guiding
