// The film (pbrt-v3's Film "image"): pixel bounds with crop window, filtered accumulation of
// radiance samples through tiles, and the final image.
//
// Accumulation follows pbrt-v3: a sample at raster position pFilm (pixels of the full image,
// y down, pixel (x, y) covers [x, x+1) x [y, y+1)) adds w * L and w to every pixel whose centre
// lies within the filter radius, with w read from a 16x16 table of the filter over one
// quadrant; pixel = sum(w L) / sum(w), clamped at 0, times `scale`.
//
// Determinism: samples go to a FilmTile (a private buffer covering the pixels that the tile's
// samples can reach, i.e. its sample region plus a filter-radius border). Tiles are rendered
// independently and merged into the film. Floating-point sums depend on the order of merges in
// overlapping borders, so the renderer gets bit-identical images for the same samples
// regardless of thread scheduling by merging a pass's tiles in a fixed order: collect them in a
// vector indexed by tile number (sampleTiles() gives a fixed tiling) and call mergeTiles().
// mergeTile() is thread-safe but then the order (and so the last bits) follow completion order.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "render/filter.h"
#include "render/image.h"
#include "render/math.h"

namespace rlpbrt {

class ParamList;

// Integer pixel rectangle [pMin, pMax) (max exclusive).
struct Bounds2i {
    glm::ivec2 pMin{0, 0}, pMax{0, 0};

    Bounds2i() = default;
    Bounds2i(glm::ivec2 lo, glm::ivec2 hi) : pMin(lo), pMax(hi) {}
    int width() const { return std::max(0, pMax.x - pMin.x); }
    int height() const { return std::max(0, pMax.y - pMin.y); }
    int area() const { return width() * height(); }
    bool empty() const { return pMax.x <= pMin.x || pMax.y <= pMin.y; }
    bool contains(glm::ivec2 p) const {
        return p.x >= pMin.x && p.x < pMax.x && p.y >= pMin.y && p.y < pMax.y;
    }
    bool operator==(const Bounds2i& o) const { return pMin == o.pMin && pMax == o.pMax; }
    bool operator!=(const Bounds2i& o) const { return !(*this == o); }
};

// The overlap of two rectangles (possibly empty).
inline Bounds2i intersect(const Bounds2i& a, const Bounds2i& b) {
    return Bounds2i(glm::max(a.pMin, b.pMin), glm::min(a.pMax, b.pMax));
}

// Largest film accepted (xresolution * yresolution): 8192 x 8192, about 2 GiB of pixel sums.
// Bounds memory and keeps pixel counts within int.
constexpr int64_t MaxFilmPixels = int64_t(1) << 26;

// Parameters of Film "image" with pbrt-v3's defaults.
struct FilmParams {
    int xResolution = 1280, yResolution = 720;  // full image size in pixels
    Vec2 cropMin{0.f, 0.f}, cropMax{1.f, 1.f};  // crop window in NDC [0,1]^2 (y down)
    float scale = 1.f;                          // multiplies the final pixel values
    float maxSampleLuminance = Infinity;        // samples above this luminance are scaled down
    std::string filename = "pbrt.exr";          // output file (as written, not resolved)
    float diagonal = 35.f;  // film diagonal in mm; only for "realistic" cameras, unused

    // Pixels to render and store: [ceil(res * cropMin), ceil(res * cropMax)) as pbrt-v3,
    // computed in single precision.
    Bounds2i pixelBounds() const;
};

// Reads Film "image" parameters. On error sets *error (non-empty) and returns what could be
// read. Reads every parameter it knows, so ParamList::reportUnused flags only unknown ones.
FilmParams parseFilm(const ParamList& params, std::string* error);

// pbrt-v3's filter table resolution (entries per axis over [0, radius]).
constexpr int FilterTableWidth = 16;
using FilterTable = std::array<float, FilterTableWidth * FilterTableWidth>;

// Private accumulation buffer for the samples of one region of the image. Not thread-safe:
// one tile per thread at a time. Obtained from Film::makeTile.
class FilmTile {
public:
    // Pixels this tile accumulates (already clipped to the film's pixel bounds).
    const Bounds2i& pixelBounds() const { return pixelBounds_; }
    // Adds radiance L (RGB) seen through raster position pFilm (full-image pixels) with
    // sampleWeight (the camera ray weight). Non-finite L or L with luminance < -1e-5 counts as
    // black (pbrt-v3's integrator rule); L brighter than maxsampleluminance is scaled down.
    void addSample(Vec2 pFilm, Spectrum L, float sampleWeight = 1.f);
    // Accumulated sum(w L) at a pixel in pixelBounds() (full-image coordinates).
    Spectrum contribution(int x, int y) const { return pixel(x, y).contrib; }
    // Accumulated sum(w) at a pixel in pixelBounds().
    float weightSum(int x, int y) const { return pixel(x, y).weightSum; }
    // Resets all sums to zero (to reuse the tile for the next pass).
    void clear();
    // Multiplies all sums by w >= 0: the tile's samples then weigh w each in the film (the
    // pixel's value stays their weighted mean).
    void scale(float w);
    // The sums as a flat array of floats (4 per pixel: RGB and weight), for exchanging tiles
    // between the ranks of a distributed render.
    float* data() { return reinterpret_cast<float*>(pixels_.data()); }
    size_t floatCount() const { return pixels_.size() * 4; }

private:
    friend class Film;
    struct Pixel {
        Spectrum contrib{0.f};
        float weightSum = 0.f;
    };
    FilmTile(const Bounds2i& pixelBounds, Vec2 radius, const FilterTable& table,
             float maxSampleLuminance);
    const Pixel& pixel(int x, int y) const {
        return pixels_[size_t(y - pixelBounds_.pMin.y) * pixelBounds_.width() +
                       (x - pixelBounds_.pMin.x)];
    }

    Bounds2i pixelBounds_;
    Vec2 radius_, invRadius_;
    FilterTable table_;
    float maxSampleLuminance_;
    std::vector<Pixel> pixels_;
    static_assert(sizeof(Spectrum) == 3 * sizeof(float), "FilmTile::data() needs plain floats");
};

class Film {
public:
    // Throws std::invalid_argument for a null filter, a radius above MaxFilterRadius or an
    // empty pixel region.
    Film(const FilmParams& params, std::shared_ptr<const Filter> filter);

    const FilmParams& params() const { return params_; }
    const Filter& filter() const { return *filter_; }
    const FilterTable& filterTable() const { return table_; }
    int fullWidth() const { return params_.xResolution; }
    int fullHeight() const { return params_.yResolution; }
    // The cropped pixel range that is stored and output (x0,y0 inclusive, x1,y1 exclusive).
    Bounds2i pixelBounds() const { return pixelBounds_; }
    // The pixels to take samples in (pbrt-v3's GetSampleBounds): pixelBounds() grown by the
    // filter radius, so that border pixels get their full filter support. May extend beyond
    // the full image (camera rays are generated there too, as in pbrt-v3).
    Bounds2i sampleBounds() const;
    // A fixed row-major tiling of sampleBounds() into tileSize x tileSize regions.
    std::vector<Bounds2i> sampleTiles(int tileSize = 16) const;

    // A zeroed tile for samples taken in the pixels of `sampleBounds` (pFilm in
    // [pMin, pMax)); it covers every stored pixel those samples can reach.
    // Thread-safe (const).
    std::unique_ptr<FilmTile> makeTile(const Bounds2i& sampleBounds) const;
    // Same as tile.addSample (kept for call sites that hold the film).
    void addSample(FilmTile& tile, Vec2 pFilm, Spectrum L, float weight = 1.f) const {
        tile.addSample(pFilm, L, weight);
    }
    // Adds a finished tile's sums. Thread-safe; merge order decides the last bits.
    void mergeTile(const FilmTile& tile);
    // Adds the tiles in the order given (null entries are skipped): deterministic.
    void mergeTiles(const std::vector<std::unique_ptr<FilmTile>>& tiles);

    // The cropped image (pixelBounds() size, 3 channels RGB, top row first) with `scale`
    // applied; pixels without weight are 0, never NaN. Callable after any merge.
    Image toImage() const;
    // sum(w) at a stored pixel (full-image coordinates), e.g. to check coverage.
    double weightSum(int x, int y) const;
    // Zeroes all pixel sums.
    void clear();
    // The stored pixels' exact sums, 4 doubles per pixel (sum(w L) RGB, sum(w)), row-major
    // over pixelBounds(): what a resumed render continues from (render/resume.h). setSums
    // replaces them (false, and the film unchanged, if the count does not match).
    std::vector<double> sums() const;
    bool setSums(const std::vector<double>& sums);

private:
    struct Pixel {
        double contrib[3] = {0, 0, 0};
        double weightSum = 0;
    };
    void mergeLocked(const FilmTile& tile);

    FilmParams params_;
    std::shared_ptr<const Filter> filter_;
    Bounds2i pixelBounds_;
    FilterTable table_;
    std::vector<Pixel> pixels_;
    mutable std::mutex mutex_;
};

}  // namespace rlpbrt
