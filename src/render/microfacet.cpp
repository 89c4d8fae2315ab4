#include "render/microfacet.h"

namespace rlpbrt {

using namespace shading;

namespace {

constexpr double SqrtPi = 1.77245385090551602730;

// Inverse error function: M. Giles, "Approximating the erfinv function" (GPU Computing Gems,
// 2011), single-precision polynomial coefficients (relative error about 4e-7), evaluated in
// double. Input is clamped to the open interval (-1, 1).
double erfInvApprox(double y) {
    y = clamp(y, -1.0 + 1e-15, 1.0 - 1e-15);
    double w = -std::log((1.0 - y) * (1.0 + y));
    double p;
    if (w < 5.0) {
        w -= 2.5;
        p = 2.81022636e-08;
        p = 3.43273939e-07 + p * w;
        p = -3.5233877e-06 + p * w;
        p = -4.39150654e-06 + p * w;
        p = 0.00021858087 + p * w;
        p = -0.00125372503 + p * w;
        p = -0.00417768164 + p * w;
        p = 0.246640727 + p * w;
        p = 1.50140941 + p * w;
    } else {
        w = std::sqrt(w) - 3.0;
        p = -0.000200214257;
        p = 0.000100950558 + p * w;
        p = 0.00134934322 + p * w;
        p = -0.00367342844 + p * w;
        p = 0.00573950773 + p * w;
        p = -0.0076224613 + p * w;
        p = 0.00943887047 + p * w;
        p = 1.00167406 + p * w;
        p = 2.83297682 + p * w;
    }
    return p * y;
}

// erfInvApprox refined by one Newton step on std::erf (double accuracy away from |y| = 1).
double erfInv(double y) {
    double x = erfInvApprox(y);
    double d = 2.0 / SqrtPi * std::exp(-x * x);
    if (d > 0.0) x -= (std::erf(x) - clamp(y, -1.0 + 1e-15, 1.0 - 1e-15)) / d;
    return x;
}

// Samples slopes (x, y) of the unit-alpha Beckmann distribution as seen from a direction with
// polar angle cos = cosThetaI in the xz-plane: density proportional to
// max(0, cos - x sin) exp(-x^2 - y^2) / pi. The x marginal's CDF is inverted numerically in
// the erf(x) domain (safeguarded Newton), y is an independent Gaussian.
Vec2 sampleBeckmannUnitSlopes(double cosThetaI, double u1, double u2) {
    u1 = clamp(u1, 1e-7, 1.0 - 1e-7);
    u2 = clamp(u2, 1e-7, 1.0 - 1e-7);
    if (cosThetaI > 0.9999) {
        double r = std::sqrt(-std::log(1.0 - u1));
        double phi = 2.0 * Pi * u2;
        return Vec2(float(r * std::cos(phi)), float(r * std::sin(phi)));
    }
    double sinThetaI = std::sqrt(std::max(0.0, 1.0 - cosThetaI * cosThetaI));
    double tanThetaI = sinThetaI / cosThetaI;
    double cotThetaI = cosThetaI / sinThetaI;
    // Unnormalised CDF in b = erf(x): 1 + b + tan * exp(-x^2) / sqrt(pi), x <= cot.
    double lo = -1.0, hi = std::erf(cotThetaI);
    double norm = 1.0 + hi + tanThetaI * std::exp(-cotThetaI * cotThetaI) / SqrtPi;
    double target = u1 * norm;
    double b = lo + (hi - lo) * u1;
    for (int it = 0; it < 40; ++it) {
        if (!(b > lo && b < hi)) b = 0.5 * (lo + hi);
        double x = erfInvApprox(b);
        double value = 1.0 + b + tanThetaI * std::exp(-x * x) / SqrtPi - target;
        if (std::abs(value) < 1e-7 * norm) break;
        if (value > 0.0)
            hi = b;
        else
            lo = b;
        double derivative = 1.0 - x * tanThetaI;
        b = derivative > 0.0 ? b - value / derivative : 0.5 * (lo + hi);
    }
    return Vec2(float(erfInv(b)), float(erfInv(2.0 * u2 - 1.0)));
}

// Anisotropic alpha along the azimuth of w: sqrt(cos^2 phi ax^2 + sin^2 phi ay^2).
float projectedAlpha(const Vec3& w, float ax, float ay) {
    return std::sqrt(cos2Phi(w) * ax * ax + sin2Phi(w) * ay * ay);
}

// Ellipse term cos^2 phi / ax^2 + sin^2 phi / ay^2 of both distributions.
float ellipse(const Vec3& wh, float ax, float ay) {
    return cos2Phi(wh) / (ax * ax) + sin2Phi(wh) / (ay * ay);
}

}  // namespace

// Polynomial in log(roughness) from pbrt-v3 (microfacet.h, RoughnessToAlpha).
static float pbrtRoughnessToAlpha(float roughness) {
    float x = std::log(std::max(roughness, 1e-3f));
    return 1.62142f + 0.819955f * x + 0.1734f * x * x + 0.0171201f * x * x * x +
           0.000640711f * x * x * x * x;
}

float TrowbridgeReitzDistribution::roughnessToAlpha(float roughness) {
    return pbrtRoughnessToAlpha(roughness);
}

float TrowbridgeReitzDistribution::D(const Vec3& wh) const {
    float t2 = tan2Theta(wh);
    if (std::isinf(t2) || std::isnan(t2)) return 0.f;
    float cos4Theta = cos2Theta(wh) * cos2Theta(wh);
    float e = ellipse(wh, alphaX, alphaY) * t2;
    return 1.f / (Pi * alphaX * alphaY * cos4Theta * (1.f + e) * (1.f + e));
}

float TrowbridgeReitzDistribution::lambda(const Vec3& w) const {
    float absTan = std::abs(tanTheta(w));
    if (std::isinf(absTan) || std::isnan(absTan)) return 0.f;
    float a = projectedAlpha(w, alphaX, alphaY) * absTan;
    return (-1.f + std::sqrt(1.f + a * a)) * 0.5f;
}

Vec3 TrowbridgeReitzDistribution::sampleVisible(const Vec3& wo, Vec2 u) const {
    // E. Heitz, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4), 2018.
    Vec3 vh = glm::normalize(Vec3(alphaX * wo.x, alphaY * wo.y, wo.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    Vec3 t1 = lensq > 0.f ? Vec3(-vh.y, vh.x, 0.f) / std::sqrt(lensq) : Vec3(1.f, 0.f, 0.f);
    Vec3 t2 = glm::cross(vh, t1);
    float r = std::sqrt(u.x);
    float phi = 2.f * Pi * u.y;
    float p1 = r * std::cos(phi);
    float p2 = r * std::sin(phi);
    float s = 0.5f * (1.f + vh.z);
    p2 = (1.f - s) * safeSqrt(1.f - p1 * p1) + s * p2;
    Vec3 nh = p1 * t1 + p2 * t2 + safeSqrt(1.f - p1 * p1 - p2 * p2) * vh;
    return glm::normalize(Vec3(alphaX * nh.x, alphaY * nh.y, std::max(1e-6f, nh.z)));
}

float BeckmannDistribution::roughnessToAlpha(float roughness) {
    return pbrtRoughnessToAlpha(roughness);
}

float BeckmannDistribution::D(const Vec3& wh) const {
    float t2 = tan2Theta(wh);
    if (std::isinf(t2) || std::isnan(t2)) return 0.f;
    float cos4Theta = cos2Theta(wh) * cos2Theta(wh);
    return std::exp(-t2 * ellipse(wh, alphaX, alphaY)) / (Pi * alphaX * alphaY * cos4Theta);
}

float BeckmannDistribution::lambda(const Vec3& w) const {
    float absTan = std::abs(tanTheta(w));
    if (std::isinf(absTan) || std::isnan(absTan) || absTan == 0.f) return 0.f;
    // Exact Smith Lambda for Beckmann (pbrt-v3 uses a rational fit of it).
    double a = 1.0 / (double(projectedAlpha(w, alphaX, alphaY)) * absTan);
    double l = -0.5 * std::erfc(a) + std::exp(-a * a) / (2.0 * a * SqrtPi);
    return float(std::max(0.0, l));
}

Vec3 BeckmannDistribution::sampleVisible(const Vec3& wo, Vec2 u) const {
    // Stretch to the unit-alpha configuration, sample slopes, rotate, unstretch.
    Vec3 ws = glm::normalize(Vec3(alphaX * wo.x, alphaY * wo.y, wo.z));
    Vec2 slope = sampleBeckmannUnitSlopes(ws.z, u.x, u.y);
    float c = cosPhi(ws), s = sinPhi(ws);
    float sx = c * slope.x - s * slope.y;
    float sy = s * slope.x + c * slope.y;
    return glm::normalize(Vec3(-alphaX * sx, -alphaY * sy, 1.f));
}

MicrofacetDistribution::MicrofacetDistribution(MicrofacetType type, float alphaX, float alphaY)
    : type_(type), alphaX_(std::max(alphaX, MinAlpha)), alphaY_(std::max(alphaY, MinAlpha)) {}

float MicrofacetDistribution::D(const Vec3& wh) const {
    if (type_ == MicrofacetType::TrowbridgeReitz)
        return TrowbridgeReitzDistribution{alphaX_, alphaY_}.D(wh);
    return BeckmannDistribution{alphaX_, alphaY_}.D(wh);
}

float MicrofacetDistribution::lambda(const Vec3& w) const {
    if (type_ == MicrofacetType::TrowbridgeReitz)
        return TrowbridgeReitzDistribution{alphaX_, alphaY_}.lambda(w);
    return BeckmannDistribution{alphaX_, alphaY_}.lambda(w);
}

Vec3 MicrofacetDistribution::sampleWh(const Vec3& wo, Vec2 u) const {
    bool flip = wo.z < 0.f;
    Vec3 w = flip ? -wo : wo;
    Vec3 wh = type_ == MicrofacetType::TrowbridgeReitz
                  ? TrowbridgeReitzDistribution{alphaX_, alphaY_}.sampleVisible(w, u)
                  : BeckmannDistribution{alphaX_, alphaY_}.sampleVisible(w, u);
    return flip ? -wh : wh;
}

float MicrofacetDistribution::pdf(const Vec3& wo, const Vec3& wh) const {
    if (wo.z == 0.f) return 0.f;
    return D(wh) * G1(wo) * std::abs(glm::dot(wo, wh)) / absCosTheta(wo);
}

}  // namespace rlpbrt
