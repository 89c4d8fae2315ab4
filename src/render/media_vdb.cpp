// The `vdbvolume` medium: density from a float grid of an OpenVDB file, tracked with the
// same delta / ratio trackers as pbrt-v3's grid medium. The only file that includes OpenVDB.
//
//   MakeNamedMedium "smoke" "string type" "vdbvolume" "string filename" "cloud.vdb"
//       "string grid" "density" "rgb sigma_a" [1 1 1] "rgb sigma_s" [9 9 9] "float scale" 1
//       "float g" 0
//
// The grid's own index-to-world transform (which must be linear) places it in the medium's
// space, then the CTM at MakeNamedMedium places that in the world. Densities are
// trilinear between voxel centres (openvdb::tools::BoxSampler), the background outside
// the active voxels (a non-zero background is not extended beyond them). Majorants: a
// coarse grid (about 8 voxels per cell) of the largest active value (voxels and tiles)
// within the trilinear filter's reach of each cell.
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include <mutex>

#include "render/media.h"

namespace rlpbrt {

namespace {

class VdbMedium final : public DensityMediumT<VdbMedium> {
public:
    VdbMedium(const Spectrum& sigmaA, const Spectrum& sigmaS, float g, const Mat4& worldFromIndex,
              const Vec3& boxMin, const Vec3& boxMax, openvdb::FloatGrid::ConstPtr grid,
              const openvdb::CoordBBox& bbox)
        : DensityMediumT<VdbMedium>(sigmaA, sigmaS, g, worldFromIndex, boxMin, boxMax),
          grid_(std::move(grid)) {
        // About 8 voxels per majorant cell along each axis (at most 64 cells). An active
        // value (voxel or tile) is seen by the trilinear filter within one voxel of it.
        openvdb::Coord dim = bbox.dim();
        auto cells = [](int n) { return std::max(1, std::min(64, (n + 7) / 8)); };
        initMajorants(glm::ivec3(cells(dim.x() + 2), cells(dim.y() + 2), cells(dim.z() + 2)));
        for (auto it = grid_->cbeginValueOn(); it; ++it) {
            openvdb::CoordBBox b;
            it.getBoundingBox(b);
            Vec3 lo(float(b.min().x() - 1), float(b.min().y() - 1), float(b.min().z() - 1));
            Vec3 hi(float(b.max().x() + 1), float(b.max().y() + 1), float(b.max().z() + 1));
            addMajorant(lo, hi, *it);
        }
        finishMajorants();
    }

    // One lookup object per tracking call: an unregistered accessor caches the tree path
    // between the nearby points of one ray.
    struct Lookup {
        openvdb::FloatGrid::ConstUnsafeAccessor acc;
        float operator()(const Vec3& p) {
            return openvdb::tools::BoxSampler::sample(acc, openvdb::Vec3R(p.x, p.y, p.z));
        }
    };
    Lookup densityLookup() const { return Lookup{grid_->getConstUnsafeAccessor()}; }

private:
    openvdb::FloatGrid::ConstPtr grid_;
};

}  // namespace

std::unique_ptr<Medium> createVdbMedium(const MediumEntity& e, const Spectrum& sigmaA,
                                        const Spectrum& sigmaS, float g, Diagnostics& diag) {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
    const ParamList& ps = e.params;
    const std::string name = "medium \"" + e.name + "\"";
    std::string filename = ps.getFilename("filename");
    std::string gridName = ps.getString("grid", "density");
    if (filename.empty()) {
        diag.error(e.loc, name + ": vdbvolume needs a \"string filename\"");
        return nullptr;
    }
    FileLoc fileLoc = ps.find("filename")->loc;
    openvdb::FloatGrid::Ptr grid;
    try {
        openvdb::io::File file(filename);
        file.open(false);  // read the whole file now (no delayed loading)
        if (!file.hasGrid(gridName)) {
            std::string names;
            for (auto it = file.beginName(); it != file.endName(); ++it)
                names += (names.empty() ? "" : ", ") + std::string("\"") + *it + "\"";
            file.close();
            diag.error(fileLoc, name + ": \"" + filename + "\" has no grid \"" + gridName +
                                    "\" (grids: " + (names.empty() ? "none" : names) + ")");
            return nullptr;
        }
        openvdb::GridBase::Ptr base = file.readGrid(gridName);
        file.close();
        grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
        if (!grid) {
            diag.error(fileLoc, name + ": grid \"" + gridName + "\" of \"" + filename +
                                    "\" is not a float grid (it is " + base->valueType() + ")");
            return nullptr;
        }
    } catch (const std::exception& ex) {
        diag.error(fileLoc, name + ": cannot read OpenVDB file \"" + filename + "\": " + ex.what());
        return nullptr;
    }
    if (!grid->transform().isLinear()) {
        diag.error(fileLoc, name + ": grid \"" + gridName + "\" has a non-linear transform");
        return nullptr;
    }
    openvdb::math::Mat4d m = grid->transform().baseMap()->getAffineMap()->getMat4();
    Mat4 mediumFromIndex;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) mediumFromIndex[i][j] = float(m(i, j));  // row vectors
    float minDensity = 0.f;
    for (auto it = grid->cbeginValueOn(); it; ++it) minDensity = std::min(minDensity, *it);
    if (minDensity < 0.f)
        diag.warning(fileLoc, name + ": negative densities read as 0");
    if (grid->background() != 0.f)
        diag.warning(fileLoc, name + ": the grid's background is not 0; the medium ends at the "
                                     "bounds of the active voxels");
    openvdb::CoordBBox bbox = grid->evalActiveVoxelBoundingBox();
    Vec3 lo(0.f), hi(0.f);
    if (!bbox.empty()) {
        // Trilinear filtering reaches one voxel beyond the active voxels.
        lo = Vec3(float(bbox.min().x() - 1), float(bbox.min().y() - 1), float(bbox.min().z() - 1));
        hi = Vec3(float(bbox.max().x() + 1), float(bbox.max().y() + 1), float(bbox.max().z() + 1));
    }
    Mat4 worldFromIndex = e.worldFromMedium * mediumFromIndex;
    return std::make_unique<VdbMedium>(sigmaA, sigmaS, g, worldFromIndex, lo, hi,
                                       openvdb::FloatGrid::ConstPtr(grid), bbox);
}

}  // namespace rlpbrt
