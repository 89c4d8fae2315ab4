// MIP-mapped images for texture filtering (pbrt-v3's MIPMap semantics): the image is
// resampled to a power-of-two resolution with a Lanczos filter (tau = 2, radius 2 texels),
// clamped to non-negative values, then box-filtered level by level down to 1x1. Lookups:
// point, bilinear (finest level only), trilinear (isotropic width) and EWA (anisotropic
// elliptical Gaussian, the pbrt-v3 default for image textures).
//
// Texture coordinates: s along the width, t along the height; texel (i, j) covers
// [i, i+1)/width x [j, j+1)/height, so texel centres sit at half-integers. Row j = 0 is at
// t = 0; image textures flip images on load so that t = 0 is the image's bottom row
// (pbrt-v3's convention).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "render/math.h"

namespace rlpbrt {

// What a lookup returns outside [0,1]^2.
enum class ImageWrap { Repeat, Black, Clamp };
// Parses "repeat", "black", "clamp"; false if unknown.
bool parseImageWrap(const std::string& name, ImageWrap* out);

// How a MIP map is filtered for a lookup with screen-space differentials.
enum class MipFilter { Point, Bilinear, Trilinear, EWA };
// Parses "point", "bilinear", "trilinear", "ewa"; false if unknown.
bool parseMipFilter(const std::string& name, MipFilter* out);

// A MIP pyramid of texels of type T (float or Spectrum).
template <typename T>
class MipMap {
public:
    // Builds the pyramid from width*height texels, row-major with row 0 at t = 0.
    // Non-power-of-two images are first resampled up to the next powers of two.
    MipMap(int width, int height, std::vector<T> texels, ImageWrap wrap);

    int levels() const { return int(levels_.size()); }
    // Resolution of a level (level 0 is the finest, after power-of-two resampling).
    int width(int level = 0) const { return levels_[level].width; }
    int height(int level = 0) const { return levels_[level].height; }
    ImageWrap wrap() const { return wrap_; }

    // Texel (s, t) of a level with the wrap mode applied to out-of-range indices.
    T texel(int level, int s, int t) const;
    // Bilinear interpolation of a level at texture coordinates st in [0,1]^2 units.
    T bilerp(int level, const Vec2& st) const;
    // Nearest texel of the finest level.
    T nearest(const Vec2& st) const;
    // Trilinear lookup for an isotropic filter of the given width (texture-space units).
    T trilinear(const Vec2& st, float width) const;
    // EWA lookup for the footprint spanned by the texture-space differentials dst0, dst1;
    // the ellipse's eccentricity is clamped to maxAnisotropy.
    T ewa(const Vec2& st, Vec2 dst0, Vec2 dst1, float maxAnisotropy) const;
    // Filtered lookup at st with texture-space differentials dstdx, dstdy.
    T lookup(const Vec2& st, const Vec2& dstdx, const Vec2& dstdy, MipFilter filter,
             float maxAnisotropy) const;

private:
    struct Level {
        int width = 0, height = 0;
        std::vector<T> texels;
    };
    T ewaLevel(int level, Vec2 st, Vec2 dst0, Vec2 dst1) const;

    ImageWrap wrap_;
    std::vector<Level> levels_;
};

extern template class MipMap<float>;
extern template class MipMap<Spectrum>;

// Identifies the decoded contents of an image texture's MIP map.
struct MipMapKey {
    std::string filename;  // resolved path
    ImageWrap wrap = ImageWrap::Repeat;
    float scale = 1;      // multiplies texel values (after gamma)
    bool gamma = false;   // apply the sRGB inverse gamma (8-bit files)
    bool invert = false;  // texel = max(0, 1 - texel) after scaling (pbrt-v4's "invert")
    bool operator<(const MipMapKey& o) const;
};

// Decodes image files into MIP maps and shares them between textures with equal keys.
// Owned by the scene builder; thread-safe.
class MipMapCache {
public:
    // The single-channel MIP map (pbrt-v3: luminance of the RGB texels, then gamma); null and
    // *error set when the file cannot be read.
    std::shared_ptr<const MipMap<float>> getFloat(const MipMapKey& key, std::string* error);
    // The RGB MIP map; null and *error set when the file cannot be read.
    std::shared_ptr<const MipMap<Spectrum>> getSpectrum(const MipMapKey& key,
                                                        std::string* error);
    // Number of distinct MIP maps held (float and RGB).
    size_t size() const;

private:
    mutable std::mutex mutex_;
    std::map<MipMapKey, std::shared_ptr<const MipMap<float>>> floatMaps_;
    std::map<MipMapKey, std::shared_ptr<const MipMap<Spectrum>>> spectrumMaps_;
};

}  // namespace rlpbrt
