#include "render/filter.h"

#include "parser/params.h"

namespace rlpbrt {

namespace {

// sin(pi x) / (pi x), with the limit 1 near 0 (pbrt-v3 uses the same 1e-5 cut-off).
float sinc(float x) {
    x = std::abs(x);
    if (x < 1e-5f) return 1.f;
    return std::sin(Pi * x) / (Pi * x);
}

}  // namespace

float BoxFilter::evaluate(Vec2) const { return 1.f; }

float TriangleFilter::evaluate(Vec2 p) const {
    Vec2 r = radius();
    return std::max(0.f, r.x - std::abs(p.x)) * std::max(0.f, r.y - std::abs(p.y));
}

GaussianFilter::GaussianFilter(Vec2 radius, float alpha)
    : Filter(radius),
      alpha_(alpha),
      expX_(std::exp(-alpha * radius.x * radius.x)),
      expY_(std::exp(-alpha * radius.y * radius.y)) {}

float GaussianFilter::gaussian1D(float d, float expEdge) const {
    return std::max(0.f, std::exp(-alpha_ * d * d) - expEdge);
}

float GaussianFilter::evaluate(Vec2 p) const {
    return gaussian1D(p.x, expX_) * gaussian1D(p.y, expY_);
}

float MitchellFilter::mitchell1D(float x) const {
    // The standard cubic lives on [-2, 2]; x is given in units of the radius.
    x = std::abs(2.f * x);
    const float b = b_, c = c_;
    if (x > 1.f) {
        return ((-b - 6 * c) * x * x * x + (6 * b + 30 * c) * x * x +
                (-12 * b - 48 * c) * x + (8 * b + 24 * c)) * (1.f / 6.f);
    }
    return ((12 - 9 * b - 6 * c) * x * x * x + (-18 + 12 * b + 6 * c) * x * x + (6 - 2 * b)) *
           (1.f / 6.f);
}

float MitchellFilter::evaluate(Vec2 p) const {
    Vec2 r = radius();
    return mitchell1D(p.x / r.x) * mitchell1D(p.y / r.y);
}

float LanczosSincFilter::windowedSinc(float x, float radius) const {
    x = std::abs(x);
    if (x > radius) return 0.f;
    return sinc(x) * sinc(x / tau_);
}

float LanczosSincFilter::evaluate(Vec2 p) const {
    Vec2 r = radius();
    return windowedSinc(p.x, r.x) * windowedSinc(p.y, r.y);
}

std::unique_ptr<Filter> createFilter(const std::string& name, const ParamList& params,
                                     std::string* error) {
    // Defaults of pbrt-v3's Create*Filter functions.
    float defaultRadius = 2.f;
    if (name == "box") defaultRadius = 0.5f;
    else if (name == "sinc") defaultRadius = 4.f;
    else if (name != "gaussian" && name != "mitchell" && name != "triangle") {
        if (error) *error = "unknown pixel filter \"" + name + "\"";
        return nullptr;
    }
    Vec2 radius(params.getFloat("xwidth", defaultRadius),
                params.getFloat("ywidth", defaultRadius));
    if (!(radius.x > 0.f && radius.y > 0.f && radius.x <= MaxFilterRadius &&
          radius.y <= MaxFilterRadius)) {
        if (error) {
            *error = "pixel filter \"" + name + "\": \"xwidth\" and \"ywidth\" must be in (0, " +
                     std::to_string(int(MaxFilterRadius)) + "]";
        }
        return nullptr;
    }
    if (name == "box") return std::make_unique<BoxFilter>(radius);
    if (name == "triangle") return std::make_unique<TriangleFilter>(radius);
    if (name == "gaussian") {
        return std::make_unique<GaussianFilter>(radius, params.getFloat("alpha", 2.f));
    }
    if (name == "mitchell") {
        float b = params.getFloat("B", 1.f / 3.f);
        float c = params.getFloat("C", 1.f / 3.f);
        return std::make_unique<MitchellFilter>(radius, b, c);
    }
    float tau = params.getFloat("tau", 3.f);
    if (!(tau > 0.f)) {
        if (error) *error = "pixel filter \"sinc\": \"tau\" must be positive";
        return nullptr;
    }
    return std::make_unique<LanczosSincFilter>(radius, tau);
}

}  // namespace rlpbrt
