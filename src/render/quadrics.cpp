// Quadric shapes: double-precision intersection with hit refinement, pbrt-v3
// parametrisations, areas, bounds and sampling.
#include "render/quadrics.h"

#include "render/sampling.h"

namespace rlpbrt {
namespace {

using DVec3 = glm::dvec3;
constexpr double kTwoPi = 6.283185307179586476925;

// Relative float rounding bound gamma(n) of pbrt-v3 (machine epsilon 2^-24).
constexpr float gammaBound(int n) {
    return n * 0x1p-24f / (1 - n * 0x1p-24f);
}

float clampPhiMax(float deg) { return radians(clamp(deg, 0.f, 360.f)); }

// Real roots t0 <= t1 of a t^2 + b t + c = 0 (numerically stable form); a linear equation
// gives t0 == t1. False when there is no real root.
bool solveQuadratic(double a, double b, double c, double* t0, double* t1) {
    if (a == 0) {
        if (b == 0) return false;
        *t0 = *t1 = -c / b;
        return true;
    }
    double disc = b * b - 4 * a * c;
    if (disc < 0) return false;
    double root = std::sqrt(disc);
    double q = (b < 0) ? -0.5 * (b - root) : -0.5 * (b + root);
    if (q == 0) {  // b == 0 and disc == 0, so c == 0
        *t0 = *t1 = 0;
        return true;
    }
    *t0 = q / a;
    *t1 = c / q;
    if (*t0 > *t1) std::swap(*t0, *t1);
    return true;
}

double phiOf(double x, double y) {
    double phi = std::atan2(y, x);
    return phi < 0 ? phi + kTwoPi : phi;
}

// Candidate hit in double precision.
struct DHit {
    DVec3 p, dpdu, dpdv;
    double u = 0, v = 0;
};

// Scales (x, y) of p to radius r (no-op on the axis).
void projectRadius(DVec3* p, double r) {
    double cur = std::sqrt(p->x * p->x + p->y * p->y);
    if (cur > 0) {
        p->x *= r / cur;
        p->y *= r / cur;
    }
}

// Refines the raw ray point onto the surface, applies clipping and computes the
// parametrisation. False if the point is clipped away.
bool surfacePoint(const Quadric& q, DVec3 p, DHit* h) {
    const double phiMax = q.phiMax, r = q.radius;
    switch (q.kind) {
    case Quadric::Kind::Sphere: {
        p *= r / glm::length(p);
        if (p.x == 0 && p.y == 0) p.x = 1e-5 * r;
        double phi = phiOf(p.x, p.y);
        if ((q.zMin > -r && p.z < q.zMin) || (q.zMax < r && p.z > q.zMax) || phi > phiMax)
            return false;
        double cosTheta = clamp(p.z / r, -1.0, 1.0);
        double theta = std::acos(cosTheta);
        double dTheta = double(q.thetaZMax) - double(q.thetaZMin);
        h->u = phi / phiMax;
        h->v = (theta - q.thetaZMin) / dTheta;
        double zRadius = std::sqrt(p.x * p.x + p.y * p.y);
        double cosPhi = p.x / zRadius, sinPhi = p.y / zRadius;
        double sinTheta = std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta));
        h->dpdu = DVec3(-phiMax * p.y, phiMax * p.x, 0);
        h->dpdv = dTheta * DVec3(p.z * cosPhi, p.z * sinPhi, -r * sinTheta);
        break;
    }
    case Quadric::Kind::Cylinder: {
        projectRadius(&p, r);
        double phi = phiOf(p.x, p.y);
        if (p.z < q.zMin || p.z > q.zMax || phi > phiMax) return false;
        h->u = phi / phiMax;
        h->v = (p.z - q.zMin) / (double(q.zMax) - q.zMin);
        h->dpdu = DVec3(-phiMax * p.y, phiMax * p.x, 0);
        h->dpdv = DVec3(0, 0, double(q.zMax) - q.zMin);
        break;
    }
    case Quadric::Kind::Cone: {
        double hgt = q.height;
        if (p.z < 0 || p.z > hgt) return false;
        projectRadius(&p, r * (1 - p.z / hgt));
        double phi = phiOf(p.x, p.y);
        if (phi > phiMax) return false;
        h->u = phi / phiMax;
        h->v = p.z / hgt;
        h->dpdu = DVec3(-phiMax * p.y, phiMax * p.x, 0);
        // -(x, y) / (1 - v) written without the 0/0 at the apex.
        h->dpdv = DVec3(-r * std::cos(phi), -r * std::sin(phi), hgt);
        break;
    }
    case Quadric::Kind::Paraboloid: {
        if (p.z < q.zMin || p.z > q.zMax) return false;
        double k = double(q.zMax) / (r * r);  // z = k (x^2 + y^2)
        double rho = std::sqrt(std::max(0.0, p.z / k));
        projectRadius(&p, rho);
        double phi = phiOf(p.x, p.y);
        if (phi > phiMax) return false;
        h->u = phi / phiMax;
        h->v = (p.z - q.zMin) / (double(q.zMax) - q.zMin);
        h->dpdu = DVec3(-phiMax * p.y, phiMax * p.x, 0);
        // (x, y) / (2 z) = (cos, sin) / (2 k rho); kept finite at the apex.
        double inv = 1 / (2 * k * std::max(rho, 1e-7 * r));
        h->dpdv = (double(q.zMax) - q.zMin) * DVec3(std::cos(phi) * inv, std::sin(phi) * inv, 1);
        break;
    }
    case Quadric::Kind::Hyperboloid: {
        if (p.z < q.zMin || p.z > q.zMax) return false;
        projectRadius(&p, std::sqrt(std::max(0.0, (q.hypA * p.z + q.hypB) * p.z + q.hypC)));
        DVec3 p1(q.p1), p2(q.p2);
        double v = (p.z - p1.z) / (p2.z - p1.z);
        DVec3 pr = (1 - v) * p1 + v * p2;
        double phi = std::atan2(pr.x * p.y - p.x * pr.y, p.x * pr.x + p.y * pr.y);
        if (phi < 0) phi += kTwoPi;
        if (phi > phiMax) return false;
        h->u = phi / phiMax;
        h->v = v;
        double c = std::cos(phi), s = std::sin(phi);
        DVec3 d = p2 - p1;
        h->dpdu = DVec3(-phiMax * p.y, phiMax * p.x, 0);
        h->dpdv = DVec3(d.x * c - d.y * s, d.x * s + d.y * c, d.z);
        break;
    }
    case Quadric::Kind::Disk:
        return false;  // handled in intersect()
    }
    h->p = p;
    return true;
}

void fillHit(const DHit& h, double t, QuadricHit* hit) {
    hit->t = float(t);
    hit->p = Vec3(h.p);
    hit->uv = Vec2(float(clamp(h.u, 0.0, 1.0)), float(clamp(h.v, 0.0, 1.0)));
    hit->dpdu = Vec3(h.dpdu);
    hit->dpdv = Vec3(h.dpdv);
    DVec3 n = glm::cross(h.dpdu, h.dpdv);
    double len = glm::length(n);
    hit->n = len > 0 ? Vec3(n / len) : Vec3(0, 0, 1);
    hit->pError = gammaBound(5) * glm::abs(hit->p);
}

bool intersectDisk(const Quadric& q, const DVec3& o, const DVec3& d, double tMin, double tMax,
                   QuadricHit* hit) {
    if (d.z == 0) return false;
    double t = (double(q.height) - o.z) / d.z;
    if (!(t > tMin && t < tMax)) return false;
    DVec3 p = o + t * d;
    double dist2 = p.x * p.x + p.y * p.y;
    double r = q.radius, ri = q.innerRadius;
    if (dist2 > r * r || dist2 < ri * ri) return false;
    double phi = phiOf(p.x, p.y);
    if (phi > q.phiMax) return false;
    if (!hit) return true;
    double rHit = std::sqrt(dist2);
    DHit h;
    h.p = DVec3(p.x, p.y, q.height);
    h.u = phi / q.phiMax;
    h.v = (r - rHit) / (r - ri);
    h.dpdu = DVec3(-q.phiMax * p.y, q.phiMax * p.x, 0);
    h.dpdv = (ri - r) * DVec3(std::cos(phi), std::sin(phi), 0);
    fillHit(h, t, hit);
    hit->pError = Vec3(0.f);
    return true;
}

// Full sphere (no clipping) in pbrt-v3's sense.
bool isFullSphere(const Quadric& q) {
    return q.kind == Quadric::Kind::Sphere && q.zMin <= -q.radius && q.zMax >= q.radius &&
           q.phiMax >= 2 * Pi;
}

}  // namespace

Quadric makeSphere(float radius, float zMin, float zMax, float phiMaxDeg) {
    Quadric q;
    q.kind = Quadric::Kind::Sphere;
    q.radius = radius;
    q.zMin = clamp(std::min(zMin, zMax), -radius, radius);
    q.zMax = clamp(std::max(zMin, zMax), -radius, radius);
    q.thetaZMin = std::acos(clamp(q.zMin / radius, -1.f, 1.f));
    q.thetaZMax = std::acos(clamp(q.zMax / radius, -1.f, 1.f));
    q.phiMax = clampPhiMax(phiMaxDeg);
    return q;
}

Quadric makeSphere(float radius) { return makeSphere(radius, -radius, radius, 360.f); }

Quadric makeDisk(float height, float radius, float innerRadius, float phiMaxDeg) {
    Quadric q;
    q.kind = Quadric::Kind::Disk;
    q.height = height;
    q.radius = radius;
    q.innerRadius = innerRadius;
    q.zMin = q.zMax = height;
    q.phiMax = clampPhiMax(phiMaxDeg);
    return q;
}

Quadric makeCylinder(float radius, float zMin, float zMax, float phiMaxDeg) {
    Quadric q;
    q.kind = Quadric::Kind::Cylinder;
    q.radius = radius;
    q.zMin = std::min(zMin, zMax);
    q.zMax = std::max(zMin, zMax);
    q.phiMax = clampPhiMax(phiMaxDeg);
    return q;
}

Quadric makeCone(float height, float radius, float phiMaxDeg) {
    Quadric q;
    q.kind = Quadric::Kind::Cone;
    q.height = height;
    q.radius = radius;
    q.zMin = 0;
    q.zMax = height;
    q.phiMax = clampPhiMax(phiMaxDeg);
    return q;
}

Quadric makeParaboloid(float radius, float zMin, float zMax, float phiMaxDeg) {
    Quadric q;
    q.kind = Quadric::Kind::Paraboloid;
    q.radius = radius;
    q.zMin = std::min(zMin, zMax);
    q.zMax = std::max(zMin, zMax);
    q.phiMax = clampPhiMax(phiMaxDeg);
    return q;
}

Quadric makeHyperboloid(const Vec3& p1, const Vec3& p2, float phiMaxDeg) {
    Quadric q;
    q.kind = Quadric::Kind::Hyperboloid;
    q.p1 = p1;
    q.p2 = p2;
    q.phiMax = clampPhiMax(phiMaxDeg);
    q.zMin = std::min(p1.z, p2.z);
    q.zMax = std::max(p1.z, p2.z);
    q.rMax = std::max(std::hypot(p1.x, p1.y), std::hypot(p2.x, p2.y));
    q.radius = q.rMax;
    if (p1.z == p2.z) return q;  // degenerate: never hit, zero area
    // Radius^2 along the segment is quadratic in v = (z - z1) / dz, hence in z.
    DVec3 a(p1), d = DVec3(p2) - DVec3(p1);
    double alpha = a.x * a.x + a.y * a.y;
    double beta = 2 * (a.x * d.x + a.y * d.y) / d.z;
    double gamma = (d.x * d.x + d.y * d.y) / (d.z * d.z);
    q.hypA = gamma;
    q.hypB = beta - 2 * gamma * a.z;
    q.hypC = alpha - beta * a.z + gamma * a.z * a.z;
    // Area = phiMax * integral over v of |(-y, x, 0) x d| at phi = 0 (composite Simpson).
    auto integrand = [&](double v) {
        DVec3 l = a + v * d;
        double s = l.x * d.x + l.y * d.y;
        return std::sqrt(d.z * d.z * (l.x * l.x + l.y * l.y) + s * s);
    };
    const int n = 256;
    double sum = integrand(0) + integrand(1);
    for (int i = 1; i < n; ++i) sum += (i % 2 ? 4 : 2) * integrand(double(i) / n);
    q.hypArea = float(double(q.phiMax) * sum / (3 * n));
    return q;
}

bool intersect(const Quadric& q, const Vec3& oF, const Vec3& dF, float tMinF, float tMaxF,
               QuadricHit* hit) {
    DVec3 o(oF), d(dF);
    double tMin = tMinF, tMax = tMaxF;
    if (q.kind == Quadric::Kind::Disk) return intersectDisk(q, o, d, tMin, tMax, hit);
    double a, b, c;
    double r = q.radius;
    switch (q.kind) {
    case Quadric::Kind::Sphere:
        a = glm::dot(d, d);
        b = 2 * glm::dot(d, o);
        c = glm::dot(o, o) - r * r;
        break;
    case Quadric::Kind::Cylinder:
        a = d.x * d.x + d.y * d.y;
        b = 2 * (d.x * o.x + d.y * o.y);
        c = o.x * o.x + o.y * o.y - r * r;
        break;
    case Quadric::Kind::Cone: {
        double k = (r / q.height) * (r / q.height);
        double oz = o.z - q.height;
        a = d.x * d.x + d.y * d.y - k * d.z * d.z;
        b = 2 * (d.x * o.x + d.y * o.y - k * d.z * oz);
        c = o.x * o.x + o.y * o.y - k * oz * oz;
        break;
    }
    case Quadric::Kind::Paraboloid: {
        double k = double(q.zMax) / (r * r);
        a = k * (d.x * d.x + d.y * d.y);
        b = 2 * k * (d.x * o.x + d.y * o.y) - d.z;
        c = k * (o.x * o.x + o.y * o.y) - o.z;
        break;
    }
    case Quadric::Kind::Hyperboloid:
        if (q.p1.z == q.p2.z) return false;
        a = d.x * d.x + d.y * d.y - q.hypA * d.z * d.z;
        b = 2 * (d.x * o.x + d.y * o.y) - (2 * q.hypA * o.z + q.hypB) * d.z;
        c = o.x * o.x + o.y * o.y - ((q.hypA * o.z + q.hypB) * o.z + q.hypC);
        break;
    default:
        return false;
    }
    double t0, t1;
    if (!solveQuadratic(a, b, c, &t0, &t1)) return false;
    if (t0 >= tMax || t1 <= tMin) return false;
    const double ts[2] = {t0, t1};
    for (int i = 0; i < (t0 == t1 ? 1 : 2); ++i) {
        double t = ts[i];
        if (!(t > tMin && t < tMax)) continue;
        if (!hit && isFullSphere(q)) return true;  // nothing clipped: no parametrisation
        DHit h;
        if (!surfacePoint(q, o + t * d, &h)) continue;
        if (hit) fillHit(h, t, hit);
        return true;
    }
    return false;
}

float area(const Quadric& q) {
    double r = q.radius, phiMax = q.phiMax;
    switch (q.kind) {
    case Quadric::Kind::Sphere: return float(phiMax * r * (double(q.zMax) - q.zMin));
    case Quadric::Kind::Disk:
        return float(phiMax * 0.5 * (r * r - double(q.innerRadius) * q.innerRadius));
    case Quadric::Kind::Cylinder: return float((double(q.zMax) - q.zMin) * r * phiMax);
    case Quadric::Kind::Cone:
        return float(r * std::sqrt(double(q.height) * q.height + r * r) * phiMax / 2);
    case Quadric::Kind::Paraboloid: {
        double k = 4 * double(q.zMax) / (r * r);
        return float((r * r * r * r * phiMax / (12 * double(q.zMax) * q.zMax)) *
                     (std::pow(k * q.zMax + 1, 1.5) - std::pow(k * q.zMin + 1, 1.5)));
    }
    case Quadric::Kind::Hyperboloid: return q.hypArea;
    }
    return 0;
}

void bounds(const Quadric& q, Vec3* pMin, Vec3* pMax) {
    float r = q.kind == Quadric::Kind::Hyperboloid ? q.rMax : q.radius;
    float z0 = q.zMin, z1 = q.zMax;
    if (q.kind == Quadric::Kind::Disk) z0 = z1 = q.height;
    if (q.kind == Quadric::Kind::Cone) {
        z0 = std::min(0.f, q.height);
        z1 = std::max(0.f, q.height);
    }
    *pMin = Vec3(-r, -r, z0);
    *pMax = Vec3(r, r, z1);
}

bool sampleArea(const Quadric& q, Vec2 u, QuadricSample* s) {
    float a = area(q);
    if (!(a > 0) || q.kind == Quadric::Kind::Hyperboloid) return false;
    double r = q.radius;
    double phi = double(u.y) * q.phiMax;
    double c = std::cos(phi), sn = std::sin(phi);
    DVec3 p, n;
    switch (q.kind) {
    case Quadric::Kind::Sphere: {
        // Archimedes: z uniform in [zMin, zMax] gives uniform area.
        double z = double(q.zMin) + double(u.x) * (double(q.zMax) - q.zMin);
        double rho = std::sqrt(std::max(0.0, r * r - z * z));
        p = DVec3(rho * c, rho * sn, z);
        n = p / r;
        break;
    }
    case Quadric::Kind::Disk: {
        double ri = q.innerRadius;
        if (ri == 0 && q.phiMax >= 2 * Pi) {
            Vec2 pd = sampleUniformDiskConcentric(u);  // pbrt-v3's mapping for full disks
            p = DVec3(pd.x * r, pd.y * r, q.height);
        } else {
            double rho = std::sqrt(ri * ri + double(u.x) * (r * r - ri * ri));
            p = DVec3(rho * c, rho * sn, q.height);
        }
        n = DVec3(0, 0, 1);
        break;
    }
    case Quadric::Kind::Cylinder: {
        double z = double(q.zMin) + double(u.x) * (double(q.zMax) - q.zMin);
        p = DVec3(r * c, r * sn, z);
        n = DVec3(c, sn, 0);
        break;
    }
    case Quadric::Kind::Cone: {
        // Area density grows linearly with the distance from the apex.
        double h = q.height, f = std::sqrt(double(u.x));
        p = DVec3(r * f * c, r * f * sn, h * (1 - f));
        n = glm::normalize(DVec3(h * c, h * sn, r));
        break;
    }
    case Quadric::Kind::Paraboloid: {
        // Invert the area CDF A(z) ~ (1 + 4kz)^1.5 with z = k rho^2.
        double k = double(q.zMax) / (r * r);
        double a0 = std::pow(1 + 4 * k * q.zMin, 1.5), a1 = std::pow(1 + 4 * k * q.zMax, 1.5);
        double z = (std::pow(a0 + double(u.x) * (a1 - a0), 2.0 / 3.0) - 1) / (4 * k);
        z = clamp(z, double(q.zMin), double(q.zMax));
        double rho = std::sqrt(z / k);
        p = DVec3(rho * c, rho * sn, z);
        n = glm::normalize(DVec3(2 * k * rho * c, 2 * k * rho * sn, -1));
        break;
    }
    default:
        return false;
    }
    s->p = Vec3(p);
    s->n = Vec3(n);
    s->pdf = 1 / a;
    return true;
}

bool usesSphereCone(const Quadric& q, const Vec3& refF) {
    DVec3 ref(refF);
    double r = q.radius;
    return isFullSphere(q) && glm::dot(ref, ref) > r * r * (1 + 1e-4);
}

bool sampleSolidAngle(const Quadric& q, const Vec3& refF, Vec2 u, QuadricSample* s) {
    DVec3 ref(refF);
    double r = q.radius;
    double dc2 = glm::dot(ref, ref);
    if (usesSphereCone(q, refF)) {
        // Uniform direction in the cone subtended by the sphere, mapped to the visible point.
        double dc = std::sqrt(dc2);
        double sin2Max = r * r / dc2;
        double cosMax = std::sqrt(std::max(0.0, 1 - sin2Max));
        double oneMinusCosMax = sin2Max / (1 + cosMax);
        double cosTheta = 1 - double(u.x) * oneMinusCosMax;
        double sin2Theta = std::max(0.0, 1 - cosTheta * cosTheta);
        double phi = double(u.y) * kTwoPi;
        // Distance to the near intersection, then the angle alpha at the centre.
        double ds = dc * cosTheta - std::sqrt(std::max(0.0, r * r - dc2 * sin2Theta));
        double cosAlpha = clamp((dc2 + r * r - ds * ds) / (2 * dc * r), -1.0, 1.0);
        double sinAlpha = std::sqrt(std::max(0.0, 1 - cosAlpha * cosAlpha));
        Frame frame = Frame::fromZ(Vec3(ref / dc));  // z from the centre towards ref
        DVec3 n = DVec3(frame.toWorld(Vec3(float(sinAlpha * std::cos(phi)),
                                           float(sinAlpha * std::sin(phi)), float(cosAlpha))));
        n = glm::normalize(n);
        s->n = Vec3(n);
        s->p = Vec3(r * n);
        s->pdf = float(1 / (kTwoPi * oneMinusCosMax));
        return true;
    }
    if (!sampleArea(q, u, s)) return false;
    Vec3 wi = s->p - refF;
    float dist2 = glm::dot(wi, wi);
    if (dist2 == 0) {
        s->pdf = 0;
        return false;
    }
    wi /= std::sqrt(dist2);
    float cosT = std::abs(glm::dot(s->n, wi));
    if (cosT == 0) {
        s->pdf = 0;
        return false;
    }
    s->pdf *= dist2 / cosT;
    return std::isfinite(s->pdf);
}

float pdfSolidAngle(const Quadric& q, const Vec3& refF, const Vec3& wiF) {
    DVec3 ref(refF), wi(wiF);
    double r = q.radius;
    double dc2 = glm::dot(ref, ref);
    if (usesSphereCone(q, refF)) {
        double len = glm::length(wi);
        if (len == 0) return 0;
        double sin2Max = r * r / dc2;
        double cosMax = std::sqrt(std::max(0.0, 1 - sin2Max));
        double cosTheta = glm::dot(-ref, wi) / (std::sqrt(dc2) * len);
        if (cosTheta < cosMax) return 0;
        return float(1 / (kTwoPi * (sin2Max / (1 + cosMax))));
    }
    QuadricHit hit;
    if (!intersect(q, refF, wiF, 0.f, Infinity, &hit)) return 0;
    float a = area(q);
    Vec3 w = glm::normalize(wiF);
    float cosT = std::abs(glm::dot(hit.n, w));
    Vec3 toHit = hit.p - refF;
    float dist2 = glm::dot(toHit, toHit);
    if (cosT == 0 || !(a > 0)) return 0;
    return dist2 / (cosT * a);
}

}  // namespace rlpbrt
