// Pixel reconstruction filters with pbrt-v3's parameters and evaluation (PixelFilter directive).
// A filter is a separable-or-not weight function f(x, y) of the offset (in pixels) between a
// sample and a pixel centre, non-zero only for |x| <= radius.x, |y| <= radius.y. pbrt-v3 calls
// the radii "xwidth" and "ywidth" (they are half-widths). Filters need not be normalised: the
// film divides by the sum of weights.
#pragma once

#include <memory>
#include <string>

#include "render/math.h"

namespace rlpbrt {

class ParamList;

class Filter {
public:
    explicit Filter(Vec2 radius) : radius_(radius) {}
    virtual ~Filter() = default;
    // Weight at offset p (pixels) from the pixel centre; 0 outside the radius is not checked
    // by every filter, callers stay within [-radius, radius].
    virtual float evaluate(Vec2 p) const = 0;
    // pbrt-v3 name ("box", "gaussian", "mitchell", "sinc", "triangle").
    virtual const char* name() const = 0;
    // Half-widths of the support in pixels (pbrt-v3's xwidth, ywidth).
    Vec2 radius() const { return radius_; }

private:
    Vec2 radius_;
};

// Constant 1 over the support. Defaults: radius 0.5 (one pixel).
class BoxFilter : public Filter {
public:
    explicit BoxFilter(Vec2 radius) : Filter(radius) {}
    float evaluate(Vec2 p) const override;
    const char* name() const override { return "box"; }
};

// Tent max(0, r - |x|) * max(0, r - |y|) (peak r.x*r.y, not normalised). Default radius 2.
class TriangleFilter : public Filter {
public:
    explicit TriangleFilter(Vec2 radius) : Filter(radius) {}
    float evaluate(Vec2 p) const override;
    const char* name() const override { return "triangle"; }
};

// Truncated Gaussian max(0, e^{-alpha x^2} - e^{-alpha r^2}) per axis, multiplied.
// Defaults: radius 2, alpha 2.
class GaussianFilter : public Filter {
public:
    GaussianFilter(Vec2 radius, float alpha);
    float evaluate(Vec2 p) const override;
    const char* name() const override { return "gaussian"; }
    float alpha() const { return alpha_; }

private:
    float gaussian1D(float d, float expEdge) const;
    float alpha_, expX_, expY_;
};

// Mitchell-Netravali cubic with parameters B, C, stretched so that the cubic's [-2, 2] support
// maps to [-radius, radius]. Defaults: radius 2, B = C = 1/3.
class MitchellFilter : public Filter {
public:
    MitchellFilter(Vec2 radius, float b, float c) : Filter(radius), b_(b), c_(c) {}
    float evaluate(Vec2 p) const override;
    const char* name() const override { return "mitchell"; }
    // The 1D cubic at x in units of the radius (support [-1, 1]).
    float mitchell1D(float x) const;

private:
    float b_, c_;
};

// pbrt-v3's "sinc": sinc(x) * sinc(x / tau) per axis (Lanczos window), 0 beyond the radius.
// Defaults: radius 4, tau 3.
class LanczosSincFilter : public Filter {
public:
    LanczosSincFilter(Vec2 radius, float tau) : Filter(radius), tau_(tau) {}
    float evaluate(Vec2 p) const override;
    const char* name() const override { return "sinc"; }
    // Windowed sinc of one axis: x and radius in pixels.
    float windowedSinc(float x, float radius) const;

private:
    float tau_;
};

// Largest supported filter radius in pixels (keeps the film's per-sample loops bounded).
constexpr float MaxFilterRadius = 32.f;

// Creates the PixelFilter `name` from its parameters (pbrt-v3 names and defaults). Returns
// null and sets *error for an unknown name or invalid parameters.
std::unique_ptr<Filter> createFilter(const std::string& name, const ParamList& params,
                                     std::string* error);

}  // namespace rlpbrt
