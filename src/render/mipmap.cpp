// MIP maps and their cache (see mipmap.h).
#include "render/mipmap.h"

#include <array>
#include <tuple>
#include <utility>

#include "render/image.h"
#include "render/image_io.h"

namespace rlpbrt {

bool parseImageWrap(const std::string& name, ImageWrap* out) {
    if (name == "repeat") *out = ImageWrap::Repeat;
    else if (name == "black") *out = ImageWrap::Black;
    else if (name == "clamp") *out = ImageWrap::Clamp;
    else return false;
    return true;
}

bool parseMipFilter(const std::string& name, MipFilter* out) {
    if (name == "point") *out = MipFilter::Point;
    else if (name == "bilinear") *out = MipFilter::Bilinear;
    else if (name == "trilinear") *out = MipFilter::Trilinear;
    else if (name == "ewa" || name == "EWA") *out = MipFilter::EWA;
    else return false;
    return true;
}

namespace {

bool isPowerOf2(int v) { return v > 0 && (v & (v - 1)) == 0; }

int roundUpPow2(int v) {
    int p = 1;
    while (p < v) p *= 2;
    return p;
}

int log2Int(int v) {
    int l = 0;
    while ((1 << (l + 1)) <= v) ++l;
    return l;
}

// Non-negative remainder.
int mod(int a, int b) {
    int r = a % b;
    return r < 0 ? r + b : r;
}

// Windowed sinc: sinc(x * tau) * sinc(x) for |x| <= 1, else 0 (pbrt-v3's Lanczos).
float lanczos(float x, float tau = 2) {
    x = std::abs(x);
    if (x < 1e-5f) return 1;
    if (x > 1.f) return 0;
    x *= Pi;
    return (std::sin(x * tau) / (x * tau)) * (std::sin(x) / x);
}

// Four-tap resampling weights from oldRes texels to newRes >= oldRes texels.
struct ResampleWeight {
    int firstTexel;
    float weight[4];
};

std::vector<ResampleWeight> resampleWeights(int oldRes, int newRes) {
    std::vector<ResampleWeight> wt(newRes);
    const float filterWidth = 2.f;
    for (int i = 0; i < newRes; ++i) {
        // Centre of new texel i in old-texel units.
        float center = (i + 0.5f) * float(oldRes) / float(newRes);
        wt[i].firstTexel = int(std::floor(center - filterWidth + 0.5f));
        float sum = 0;
        for (int j = 0; j < 4; ++j) {
            float pos = float(wt[i].firstTexel + j) + 0.5f;
            wt[i].weight[j] = lanczos((pos - center) / filterWidth);
            sum += wt[i].weight[j];
        }
        for (float& w : wt[i].weight) w /= sum;
    }
    return wt;
}

// Index of an out-of-range texel under the wrap mode; -1 for black.
int wrapIndex(int i, int n, ImageWrap wrap) {
    if (i >= 0 && i < n) return i;  // every mode, without Repeat's division
    switch (wrap) {
    case ImageWrap::Repeat: return mod(i, n);
    case ImageWrap::Clamp: return clamp(i, 0, n - 1);
    case ImageWrap::Black: return (i < 0 || i >= n) ? -1 : i;
    }
    return -1;
}

inline float clampZero(float v) { return std::max(v, 0.f); }
inline Spectrum clampZero(const Spectrum& v) { return glm::max(v, Spectrum(0.f)); }

// Gaussian weights exp(-2 r^2) - exp(-2) tabulated at r^2 = i / 127 (pbrt-v3's EWA table).
constexpr int kWeightLutSize = 128;
const std::array<float, kWeightLutSize>& ewaWeights() {
    static const std::array<float, kWeightLutSize> lut = [] {
        std::array<float, kWeightLutSize> t{};
        for (int i = 0; i < kWeightLutSize; ++i) {
            float r2 = float(i) / float(kWeightLutSize - 1);
            t[i] = std::exp(-2.f * r2) - std::exp(-2.f);
        }
        return t;
    }();
    return lut;
}

}  // namespace

template <typename T>
MipMap<T>::MipMap(int width, int height, std::vector<T> texels, ImageWrap wrap)
    : wrap_(wrap) {
    if (!isPowerOf2(width) || !isPowerOf2(height)) {
        // Separable Lanczos resampling up to power-of-two resolution.
        int w2 = roundUpPow2(width), h2 = roundUpPow2(height);
        std::vector<ResampleWeight> sw = resampleWeights(width, w2);
        std::vector<T> wide(size_t(w2) * height, T(0.f));
        for (int t = 0; t < height; ++t)
            for (int s = 0; s < w2; ++s) {
                T sum(0.f);
                for (int j = 0; j < 4; ++j) {
                    int os = wrapIndex(sw[s].firstTexel + j, width, wrap);
                    if (os >= 0) sum += sw[s].weight[j] * texels[size_t(t) * width + os];
                }
                wide[size_t(t) * w2 + s] = sum;
            }
        std::vector<ResampleWeight> tw = resampleWeights(height, h2);
        std::vector<T> out(size_t(w2) * h2, T(0.f));
        for (int t = 0; t < h2; ++t) {
            T* row = &out[size_t(t) * w2];
            for (int j = 0; j < 4; ++j) {
                int ot = wrapIndex(tw[t].firstTexel + j, height, wrap);
                if (ot < 0) continue;
                const T* src = &wide[size_t(ot) * w2];
                for (int s = 0; s < w2; ++s) row[s] += tw[t].weight[j] * src[s];
            }
            // Lanczos lobes can ring below zero; texels must stay non-negative.
            for (int s = 0; s < w2; ++s) row[s] = clampZero(row[s]);
        }
        texels = std::move(out);
        width = w2;
        height = h2;
    }

    int nLevels = 1 + log2Int(std::max(width, height));
    levels_.resize(nLevels);
    levels_[0] = Level{width, height, std::move(texels)};
    for (int i = 1; i < nLevels; ++i) {
        // Each texel is the box average of the 2x2 texels below it (with the wrap mode
        // supplying the missing ones when a dimension is already 1).
        Level& l = levels_[i];
        l.width = std::max(1, levels_[i - 1].width / 2);
        l.height = std::max(1, levels_[i - 1].height / 2);
        l.texels.resize(size_t(l.width) * l.height);
        for (int t = 0; t < l.height; ++t)
            for (int s = 0; s < l.width; ++s)
                l.texels[size_t(t) * l.width + s] =
                    0.25f * (texel(i - 1, 2 * s, 2 * t) + texel(i - 1, 2 * s + 1, 2 * t) +
                             texel(i - 1, 2 * s, 2 * t + 1) +
                             texel(i - 1, 2 * s + 1, 2 * t + 1));
    }
}

template <typename T>
T MipMap<T>::texel(int level, int s, int t) const {
    const Level& l = levels_[level];
    int si = wrapIndex(s, l.width, wrap_), ti = wrapIndex(t, l.height, wrap_);
    if (si < 0 || ti < 0) return T(0.f);
    return l.texels[size_t(ti) * l.width + si];
}

template <typename T>
T MipMap<T>::bilerp(int level, const Vec2& st) const {
    level = clamp(level, 0, levels() - 1);
    const Level& l = levels_[level];
    float s = st.x * float(l.width) - 0.5f;
    float t = st.y * float(l.height) - 0.5f;
    float fs = std::floor(s), ft = std::floor(t);
    int s0 = int(fs), t0 = int(ft);
    float ds = s - fs, dt = t - ft;
    T t00, t01, t10, t11;  // t01: one row down
    if (s0 >= 0 && t0 >= 0 && s0 < l.width - 1 && t0 < l.height - 1) {
        // All four texels inside the level (the usual case): read without wrapping.
        const T* row0 = &l.texels[size_t(t0) * size_t(l.width) + size_t(s0)];
        const T* row1 = row0 + l.width;
        t00 = row0[0], t10 = row0[1], t01 = row1[0], t11 = row1[1];
    } else {
        t00 = texel(level, s0, t0), t10 = texel(level, s0 + 1, t0);
        t01 = texel(level, s0, t0 + 1), t11 = texel(level, s0 + 1, t0 + 1);
    }
    return (1 - ds) * (1 - dt) * t00 + (1 - ds) * dt * t01 + ds * (1 - dt) * t10 + ds * dt * t11;
}

template <typename T>
T MipMap<T>::nearest(const Vec2& st) const {
    int s = int(std::floor(st.x * float(width(0))));
    int t = int(std::floor(st.y * float(height(0))));
    return texel(0, s, t);
}

template <typename T>
T MipMap<T>::trilinear(const Vec2& st, float width) const {
    // Level whose texel spacing matches the filter width: 2^-(levels-1-level) = width.
    // A width of at most 1e-8 always reads level 0 (fewer than 27 levels): environment
    // maps' radiance lookups pass 0, without the logarithm.
    if (!(width > 1e-8f)) return bilerp(0, st);
    float level = float(levels() - 1) + std::log2(std::max(width, 1e-8f));
    if (level < 0) return bilerp(0, st);
    if (level >= float(levels() - 1)) return texel(levels() - 1, 0, 0);
    int il = int(std::floor(level));
    float delta = level - float(il);
    return (1 - delta) * bilerp(il, st) + delta * bilerp(il + 1, st);
}

template <typename T>
T MipMap<T>::ewa(const Vec2& st, Vec2 dst0, Vec2 dst1, float maxAnisotropy) const {
    // dst0 becomes the major axis.
    if (glm::dot(dst0, dst0) < glm::dot(dst1, dst1)) std::swap(dst0, dst1);
    float majorLength = glm::length(dst0), minorLength = glm::length(dst1);
    // Clamp the eccentricity by widening the minor axis (blurs rather than aliases).
    if (minorLength * maxAnisotropy < majorLength && minorLength > 0) {
        float scale = majorLength / (minorLength * maxAnisotropy);
        dst1 *= scale;
        minorLength *= scale;
    }
    if (minorLength == 0) return bilerp(0, st);
    // Level where the minor axis spans a few texels.
    float lod = std::max(0.f, float(levels() - 1) + std::log2(minorLength));
    int ilod = int(std::floor(lod));
    float d = lod - float(ilod);
    return (1 - d) * ewaLevel(ilod, st, dst0, dst1) + d * ewaLevel(ilod + 1, st, dst0, dst1);
}

template <typename T>
T MipMap<T>::ewaLevel(int level, Vec2 st, Vec2 dst0, Vec2 dst1) const {
    if (level >= levels()) return texel(levels() - 1, 0, 0);
    // To the level's texel units (texel centres at integers).
    float w = float(levels_[level].width), h = float(levels_[level].height);
    st = Vec2(st.x * w - 0.5f, st.y * h - 0.5f);
    dst0 = Vec2(dst0.x * w, dst0.y * h);
    dst1 = Vec2(dst1.x * w, dst1.y * h);

    // Implicit ellipse A s^2 + B s t + C t^2 < 1 spanned by the axes, each widened by one
    // texel so that at least one texel is always inside.
    float A = dst0.y * dst0.y + dst1.y * dst1.y + 1;
    float B = -2 * (dst0.x * dst0.y + dst1.x * dst1.y);
    float C = dst0.x * dst0.x + dst1.x * dst1.x + 1;
    float invF = 1 / (A * C - B * B * 0.25f);
    A *= invF;
    B *= invF;
    C *= invF;

    // The ellipse's bounding box in texel indices.
    float det = -B * B + 4 * A * C;
    float invDet = 1 / det;
    float uSqrt = std::sqrt(det * C), vSqrt = std::sqrt(A * det);
    int s0 = int(std::ceil(st.x - 2 * invDet * uSqrt));
    int s1 = int(std::floor(st.x + 2 * invDet * uSqrt));
    int t0 = int(std::ceil(st.y - 2 * invDet * vSqrt));
    int t1 = int(std::floor(st.y + 2 * invDet * vSqrt));

    const auto& lut = ewaWeights();
    T sum(0.f);
    float sumWts = 0;
    for (int it = t0; it <= t1; ++it) {
        float tt = float(it) - st.y;
        for (int is = s0; is <= s1; ++is) {
            float ss = float(is) - st.x;
            float r2 = A * ss * ss + B * ss * tt + C * tt * tt;
            if (r2 < 1) {
                int index = std::min(int(r2 * kWeightLutSize), kWeightLutSize - 1);
                float weight = lut[index];
                sum += texel(level, is, it) * weight;
                sumWts += weight;
            }
        }
    }
    return sumWts > 0 ? sum / sumWts : bilerp(level, st);
}

template <typename T>
T MipMap<T>::lookup(const Vec2& st, const Vec2& dstdx, const Vec2& dstdy, MipFilter filter,
                    float maxAnisotropy) const {
    switch (filter) {
    case MipFilter::Point: return nearest(st);
    case MipFilter::Bilinear: return bilerp(0, st);
    case MipFilter::Trilinear: {
        // pbrt-v3: isotropic width = twice the largest differential component.
        float width = std::max(std::max(std::abs(dstdx.x), std::abs(dstdx.y)),
                               std::max(std::abs(dstdy.x), std::abs(dstdy.y)));
        return trilinear(st, 2 * width);
    }
    case MipFilter::EWA: return ewa(st, dstdx, dstdy, maxAnisotropy);
    }
    return bilerp(0, st);
}

template class MipMap<float>;
template class MipMap<Spectrum>;

bool MipMapKey::operator<(const MipMapKey& o) const {
    return std::tie(filename, wrap, scale, gamma, invert) <
           std::tie(o.filename, o.wrap, o.scale, o.gamma, o.invert);
}

namespace {

// Reads the file and converts it to texels with row 0 at t = 0 (the image's bottom row),
// applying gamma, scale and invert. toTexel maps a raw RGB value to the texel type.
template <typename T, typename F>
bool loadTexels(const MipMapKey& key, F toTexel, int* width, int* height,
                std::vector<T>* texels, std::string* error) {
    Image img;
    std::string err;
    if (!readImage(key.filename, &img, &err)) {
        if (error) *error = "cannot read image texture \"" + key.filename + "\": " + err;
        return false;
    }
    if (img.width <= 0 || img.height <= 0 || img.channels <= 0) {
        if (error) *error = "image texture \"" + key.filename + "\" is empty";
        return false;
    }
    *width = img.width;
    *height = img.height;
    texels->resize(size_t(img.width) * img.height);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            // Grey (+alpha) images replicate their first channel; alpha is ignored.
            Spectrum rgb = img.channels >= 3
                               ? Spectrum(img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2))
                               : Spectrum(img.at(x, y, 0));
            (*texels)[size_t(img.height - 1 - y) * img.width + x] = toTexel(rgb);
        }
    return true;
}

float finishTexel(float v, const MipMapKey& key) {
    v *= key.scale;
    return key.invert ? std::max(0.f, 1.f - v) : v;
}

}  // namespace

std::shared_ptr<const MipMap<float>> MipMapCache::getFloat(const MipMapKey& key,
                                                           std::string* error) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = floatMaps_.find(key);
    if (it != floatMaps_.end()) return it->second;
    int w = 0, h = 0;
    std::vector<float> texels;
    // pbrt-v3: luminance of the stored RGB values, then the inverse gamma, then the scale.
    auto toTexel = [&](const Spectrum& rgb) {
        float y = luminance(rgb);
        return finishTexel(key.gamma ? srgbToLinear(y) : y, key);
    };
    if (!loadTexels(key, toTexel, &w, &h, &texels, error)) return nullptr;
    auto map = std::make_shared<const MipMap<float>>(w, h, std::move(texels), key.wrap);
    floatMaps_[key] = map;
    return map;
}

std::shared_ptr<const MipMap<Spectrum>> MipMapCache::getSpectrum(const MipMapKey& key,
                                                                 std::string* error) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = spectrumMaps_.find(key);
    if (it != spectrumMaps_.end()) return it->second;
    int w = 0, h = 0;
    std::vector<Spectrum> texels;
    auto toTexel = [&](const Spectrum& rgb) {
        Spectrum out;
        for (int c = 0; c < 3; ++c)
            out[c] = finishTexel(key.gamma ? srgbToLinear(rgb[c]) : rgb[c], key);
        return out;
    };
    if (!loadTexels(key, toTexel, &w, &h, &texels, error)) return nullptr;
    auto map = std::make_shared<const MipMap<Spectrum>>(w, h, std::move(texels), key.wrap);
    spectrumMaps_[key] = map;
    return map;
}

size_t MipMapCache::size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return floatMaps_.size() + spectrumMaps_.size();
}

}  // namespace rlpbrt
