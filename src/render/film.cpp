#include "render/film.h"

#include <stdexcept>

#include "parser/params.h"

namespace rlpbrt {

Bounds2i FilmParams::pixelBounds() const {
    // Single-precision products as in pbrt-v3, so that e.g. 200 * 0.9f rounds to 180.
    auto edge = [](int res, float t) { return int(std::ceil(float(res) * t)); };
    return Bounds2i(glm::ivec2(edge(xResolution, cropMin.x), edge(yResolution, cropMin.y)),
                    glm::ivec2(edge(xResolution, cropMax.x), edge(yResolution, cropMax.y)));
}

FilmParams parseFilm(const ParamList& params, std::string* error) {
    FilmParams fp;
    std::string err;
    fp.xResolution = params.getInt("xresolution", fp.xResolution);
    fp.yResolution = params.getInt("yresolution", fp.yResolution);
    if (fp.xResolution <= 0 || fp.yResolution <= 0)
        err = "film \"xresolution\" and \"yresolution\" must be positive";
    else if (int64_t(fp.xResolution) * fp.yResolution > MaxFilmPixels)
        err = "film resolution " + std::to_string(fp.xResolution) + "x" +
              std::to_string(fp.yResolution) + " is too large (at most " +
              std::to_string(MaxFilmPixels) + " pixels)";
    if (params.has("cropwindow")) {
        std::vector<float> cw = params.getFloats("cropwindow");
        if (cw.size() == 4) {
            // pbrt-v3 orders each pair and clamps to [0, 1].
            fp.cropMin = Vec2(clamp(std::min(cw[0], cw[1]), 0.f, 1.f),
                              clamp(std::min(cw[2], cw[3]), 0.f, 1.f));
            fp.cropMax = Vec2(clamp(std::max(cw[0], cw[1]), 0.f, 1.f),
                              clamp(std::max(cw[2], cw[3]), 0.f, 1.f));
        } else if (err.empty()) {
            err = std::to_string(cw.size()) +
                  " values supplied for film \"cropwindow\"; expected 4";
        }
    }
    fp.scale = params.getFloat("scale", fp.scale);
    fp.maxSampleLuminance = params.getFloat("maxsampleluminance", fp.maxSampleLuminance);
    fp.filename = params.getString("filename", fp.filename);
    fp.diagonal = params.getFloat("diagonal", fp.diagonal);
    if (err.empty() && fp.pixelBounds().empty())
        err = "film \"cropwindow\" selects no pixels";
    if (!(fp.maxSampleLuminance > 0.f) && err.empty())
        err = "film \"maxsampleluminance\" must be positive";
    if (error) *error = err;
    return fp;
}

// ---------------------------------------------------------------------------------------------

FilmTile::FilmTile(const Bounds2i& pixelBounds, Vec2 radius, const FilterTable& table,
                   float maxSampleLuminance)
    : pixelBounds_(pixelBounds),
      radius_(radius),
      invRadius_(1.f / radius.x, 1.f / radius.y),
      table_(table),
      maxSampleLuminance_(maxSampleLuminance),
      pixels_(size_t(std::max(0, pixelBounds.area()))) {}

void FilmTile::clear() { std::fill(pixels_.begin(), pixels_.end(), Pixel()); }

void FilmTile::scale(float w) {
    for (Pixel& p : pixels_) {
        p.contrib *= w;
        p.weightSum *= w;
    }
}

void FilmTile::addSample(Vec2 pFilm, Spectrum L, float sampleWeight) {
    // Invalid radiance counts as a black sample (pbrt-v3 zeroes it in the integrator).
    float y = luminance(L);
    if (!isFinite(L) || !std::isfinite(y) || y < -1e-5f) {
        L = Spectrum(0.f);
        y = 0.f;
    }
    if (y > maxSampleLuminance_) L *= maxSampleLuminance_ / y;

    // Pixel centres are at integer + 0.5: work in "discrete" coordinates where they are integers.
    Vec2 pd = pFilm - Vec2(0.5f);
    glm::ivec2 p0(int(std::ceil(pd.x - radius_.x)), int(std::ceil(pd.y - radius_.y)));
    glm::ivec2 p1(int(std::floor(pd.x + radius_.x)) + 1, int(std::floor(pd.y + radius_.y)) + 1);
    p0 = glm::max(p0, pixelBounds_.pMin);
    p1 = glm::min(p1, pixelBounds_.pMax);
    if (p0.x >= p1.x || p0.y >= p1.y) return;

    // Filter table indices per column and row; the extent is at most 2 * MaxFilterRadius + 1.
    constexpr int MaxExtent = 2 * int(MaxFilterRadius) + 2;
    int ifx[MaxExtent], ify[MaxExtent];
    for (int x = p0.x; x < p1.x; ++x) {
        float fx = std::abs((float(x) - pd.x) * invRadius_.x * FilterTableWidth);
        ifx[x - p0.x] = std::min(int(std::floor(fx)), FilterTableWidth - 1);
    }
    for (int y = p0.y; y < p1.y; ++y) {
        float fy = std::abs((float(y) - pd.y) * invRadius_.y * FilterTableWidth);
        ify[y - p0.y] = std::min(int(std::floor(fy)), FilterTableWidth - 1);
    }
    const int width = pixelBounds_.width();
    for (int y = p0.y; y < p1.y; ++y) {
        const float* row = &table_[size_t(ify[y - p0.y]) * FilterTableWidth];
        Pixel* out = pixels_.data() + size_t(y - pixelBounds_.pMin.y) * width +
                     (p0.x - pixelBounds_.pMin.x);
        for (int x = p0.x; x < p1.x; ++x, ++out) {
            float filterWeight = row[ifx[x - p0.x]];
            // As pbrt-v3: the sample weight scales the contribution, not the weight sum.
            out->contrib += L * (sampleWeight * filterWeight);
            out->weightSum += filterWeight;
        }
    }
}

// ---------------------------------------------------------------------------------------------

Film::Film(const FilmParams& params, std::shared_ptr<const Filter> filter)
    : params_(params), filter_(std::move(filter)), pixelBounds_(params.pixelBounds()) {
    if (!filter_) throw std::invalid_argument("Film: null filter");
    Vec2 r = filter_->radius();
    if (!(r.x > 0.f && r.y > 0.f && r.x <= MaxFilterRadius && r.y <= MaxFilterRadius))
        throw std::invalid_argument("Film: filter radius out of range");
    if (pixelBounds_.empty()) throw std::invalid_argument("Film: empty pixel bounds");
    // Tabulate the filter over the positive quadrant at cell centres.
    for (int y = 0; y < FilterTableWidth; ++y) {
        for (int x = 0; x < FilterTableWidth; ++x) {
            Vec2 p((x + 0.5f) * r.x / FilterTableWidth, (y + 0.5f) * r.y / FilterTableWidth);
            table_[size_t(y) * FilterTableWidth + x] = filter_->evaluate(p);
        }
    }
    pixels_.resize(size_t(pixelBounds_.area()));
}

Bounds2i Film::sampleBounds() const {
    Vec2 r = filter_->radius();
    Vec2 lo = Vec2(pixelBounds_.pMin) + Vec2(0.5f) - r;
    Vec2 hi = Vec2(pixelBounds_.pMax) - Vec2(0.5f) + r;
    return Bounds2i(glm::ivec2(int(std::floor(lo.x)), int(std::floor(lo.y))),
                    glm::ivec2(int(std::ceil(hi.x)), int(std::ceil(hi.y))));
}

std::vector<Bounds2i> Film::sampleTiles(int tileSize) const {
    tileSize = std::max(1, tileSize);
    Bounds2i sb = sampleBounds();
    std::vector<Bounds2i> tiles;
    for (int y = sb.pMin.y; y < sb.pMax.y; y += tileSize) {
        for (int x = sb.pMin.x; x < sb.pMax.x; x += tileSize) {
            tiles.emplace_back(glm::ivec2(x, y), glm::min(glm::ivec2(x + tileSize, y + tileSize),
                                                          sb.pMax));
        }
    }
    return tiles;
}

std::unique_ptr<FilmTile> Film::makeTile(const Bounds2i& sampleBounds) const {
    // Pixels whose centre is within the radius of some point of [pMin, pMax).
    Vec2 r = filter_->radius();
    Vec2 lo = Vec2(sampleBounds.pMin) - Vec2(0.5f) - r;
    Vec2 hi = Vec2(sampleBounds.pMax) - Vec2(0.5f) + r;
    Bounds2i pixels(glm::ivec2(int(std::ceil(lo.x)), int(std::ceil(lo.y))),
                    glm::ivec2(int(std::floor(hi.x)) + 1, int(std::floor(hi.y)) + 1));
    pixels = intersect(pixels, pixelBounds_);
    if (pixels.empty()) pixels = Bounds2i();
    return std::unique_ptr<FilmTile>(
        new FilmTile(pixels, r, table_, params_.maxSampleLuminance));
}

void Film::mergeLocked(const FilmTile& tile) {
    const Bounds2i& tb = tile.pixelBounds();
    const int width = pixelBounds_.width();
    for (int y = tb.pMin.y; y < tb.pMax.y; ++y) {
        for (int x = tb.pMin.x; x < tb.pMax.x; ++x) {
            const FilmTile::Pixel& src = tile.pixel(x, y);
            Pixel& dst = pixels_[size_t(y - pixelBounds_.pMin.y) * width +
                                 (x - pixelBounds_.pMin.x)];
            for (int c = 0; c < 3; ++c) dst.contrib[c] += double(src.contrib[c]);
            dst.weightSum += double(src.weightSum);
        }
    }
}

void Film::mergeTile(const FilmTile& tile) {
    std::lock_guard<std::mutex> lock(mutex_);
    mergeLocked(tile);
}

void Film::mergeTiles(const std::vector<std::unique_ptr<FilmTile>>& tiles) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& t : tiles)
        if (t) mergeLocked(*t);
}

Image Film::toImage() const {
    std::lock_guard<std::mutex> lock(mutex_);
    Image img;
    img.width = pixelBounds_.width();
    img.height = pixelBounds_.height();
    img.channels = 3;
    img.pixels.assign(size_t(img.width) * img.height * 3, 0.f);
    const double scale = params_.scale;
    for (size_t i = 0; i < pixels_.size(); ++i) {
        const Pixel& p = pixels_[i];
        if (p.weightSum == 0) continue;  // no filter weight: black, as pbrt-v3
        double invWt = 1.0 / p.weightSum;
        for (int c = 0; c < 3; ++c) {
            double v = std::max(0.0, p.contrib[c] * invWt) * scale;
            img.pixels[i * 3 + c] = std::isnan(v) ? 0.f : float(v);
        }
    }
    return img;
}

double Film::weightSum(int x, int y) const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!pixelBounds_.contains(glm::ivec2(x, y))) return 0.0;
    return pixels_[size_t(y - pixelBounds_.pMin.y) * pixelBounds_.width() +
                   (x - pixelBounds_.pMin.x)].weightSum;
}

void Film::clear() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::fill(pixels_.begin(), pixels_.end(), Pixel());
}

std::vector<double> Film::sums() const {
    static_assert(sizeof(Pixel) == 4 * sizeof(double), "Film::sums needs plain doubles");
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<double> out(pixels_.size() * 4);
    for (size_t i = 0; i < pixels_.size(); ++i) {
        const Pixel& p = pixels_[i];
        out[4 * i] = p.contrib[0], out[4 * i + 1] = p.contrib[1], out[4 * i + 2] = p.contrib[2];
        out[4 * i + 3] = p.weightSum;
    }
    return out;
}

bool Film::setSums(const std::vector<double>& sums) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (sums.size() != pixels_.size() * 4) return false;
    for (size_t i = 0; i < pixels_.size(); ++i) {
        Pixel& p = pixels_[i];
        p.contrib[0] = sums[4 * i], p.contrib[1] = sums[4 * i + 1], p.contrib[2] = sums[4 * i + 2];
        p.weightSum = sums[4 * i + 3];
    }
    return true;
}

}  // namespace rlpbrt
