#include "guiding/spots.h"

#include <algorithm>
#include <cmath>

#include "guiding/field_io.h"
#include "util/math.h"

namespace rlpbrt::guiding {

namespace {

// The lobes' concentration: from the records' spread (E[1 - cos] = 1 / kappa for a
// von Mises-Fisher lobe), widened by kWiden, within [kMinKappa, kMaxKappa] (a cone of about
// 18 to 0.6 degrees). A new lobe is matched with kInitKappa (about 2 degrees).
constexpr double kWiden = 2.0;
constexpr float kMinKappa = 20.f;
constexpr float kMaxKappa = 2e4f;
constexpr float kInitKappa = 1600.f;
// A candidate joins a lobe within this many lobe widths (1 - cos < kMatch / kappa), and at
// least within kMatchFloor (about 3 degrees).
constexpr float kMatch = 8.f;
constexpr float kMatchFloor = 1.4e-3f;
// The lobes' share of the guide is at least this where a region has active lobes.
constexpr double kMinShare = 0.05;
// Lobes whose light is less than this share of everything their region has learned do not
// sample at all (rather than at kMinShare): measured in session 25, most regions of scenes
// without spots (cornell-box: 87%, median share 0.2%) held such lobes, fitted to noise, and
// veach-bidir's and breakfast's errors per sample stayed as they were without them.
constexpr double kMinActiveShare = 0.01;
// pdf() skips a lobe where its exponent kappa (cos - 1) is below -kSkipExponent.
constexpr float kSkipExponent = 40.f;

}  // namespace

float vmfPdf(float kappa, float cosTheta) {
    // kappa / (2 pi (1 - e^-2kappa)) e^(kappa (cos - 1)); -expm1 keeps small kappa exact.
    const float norm = kappa / (TwoPi * -std::expm1(-2.f * kappa));
    return norm * std::exp(kappa * (std::min(cosTheta, 1.f) - 1.f));
}

glm::vec3 vmfSample(const glm::vec3& mean, float kappa, glm::vec2 u) {
    // 1 - cos = -log(v + (1 - v) e^-2kappa) / kappa with v = 1 - u.x in (0, 1].
    const float v = 1.f - u.x;
    const float oneMinusCos =
        std::clamp(-std::log(v + (1.f - v) * std::exp(-2.f * kappa)) / kappa, 0.f, 2.f);
    const float cosTheta = 1.f - oneMinusCos;
    const float sinTheta = std::sqrt(std::max(0.f, oneMinusCos * (2.f - oneMinusCos)));
    const float phi = TwoPi * u.y;
    const Frame f = Frame::fromZ(mean);
    return glm::normalize(f.toWorld(
        glm::vec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta)));
}

void SpotLobes::reset(size_t regions, const SpotSettings& settings) {
    settings_ = settings;
    settings_.perRegion = std::clamp(settings.perRegion, 1, 255);
    block_.assign(regions, kNoBlock);
    lobes_.clear();
    lobes_.shrink_to_fit();
    lobeCount_.assign(regions, 0);
    active_.clear();
    active_.shrink_to_fit();
    activeCount_.assign(regions, 0);
    share_.assign(regions, 0.f);
    worth_.assign(regions, 0.f);
    silenced_ = false;
    slots_.clear();
}

void SpotLobes::setSilenced(bool silenced) {
    silenced_ = silenced;
    if (!silenced) return;
    std::fill(activeCount_.begin(), activeCount_.end(), uint8_t(0));
    std::fill(share_.begin(), share_.end(), 0.f);
    std::fill(worth_.begin(), worth_.end(), 0.f);
}

void SpotLobes::allocate(size_t region) {
    if (block_[region] != kNoBlock) return;
    block_[region] = uint32_t(lobes_.size() / size_t(settings_.perRegion));
    lobes_.resize(lobes_.size() + size_t(settings_.perRegion));
    active_.resize(active_.size() + size_t(settings_.perRegion));
}

glm::vec3 SpotLobes::lobeDirection(const Active& a, const glm::vec3& x) {
    if (!a.aimsAtPoint) return a.axis;
    const glm::vec3 d = a.axis - x;
    const float len2 = glm::dot(d, d);
    // At the point itself (or on a degenerate axis) the lobe points along +z: any fixed
    // direction keeps sample() and pdf() consistent.
    return len2 > 0.f && std::isfinite(len2) ? d * (1.f / std::sqrt(len2)) : glm::vec3(0, 0, 1);
}

glm::vec3 SpotLobes::sample(int region, const glm::vec3& x, glm::vec2 u, float uLobe) const {
    const int n = activeCount_[size_t(region)];
    if (n == 0) return glm::vec3(0.f);
    const Active* a = activeOf(size_t(region));
    int i = 0;
    while (i + 1 < n && !(uLobe < a[i].cumWeight)) ++i;
    return vmfSample(lobeDirection(a[i], x), a[i].kappa, u);
}

float SpotLobes::pdf(int region, const glm::vec3& x, const glm::vec3& w) const {
    if (region < 0 || size_t(region) >= activeCount_.size()) return 0.f;
    const int n = activeCount_[size_t(region)];
    if (n == 0) return 0.f;
    const Active* a = activeOf(size_t(region));
    float p = 0.f;
    for (int i = 0; i < n; ++i) {
        // e^(kappa (cos - 1)) below e^-kSkipExponent adds nothing to a float sum with the
        // strata's densities: skip it, and for a lobe aimed at a point skip its direction's
        // square root where the squared cosine already says so (most lobes are narrow).
        float c = glm::dot(w, a[i].axis);  // a lobe along a direction
        if (a[i].aimsAtPoint) {
            const glm::vec3 d = a[i].axis - x;
            const float len2 = glm::dot(d, d), dw = glm::dot(w, d);
            const bool regular = len2 > 0.f && std::isfinite(len2);
            if (regular && a[i].cosCut > 0.f &&
                (dw <= 0.f || dw * dw <= a[i].cosCut * a[i].cosCut * len2))
                continue;
            c = regular ? dw / std::sqrt(len2) : glm::dot(w, lobeDirection(a[i], x));
        }
        const float e = a[i].kappa * (std::min(c, 1.f) - 1.f);
        if (e > -kSkipExponent) p += a[i].norm * std::exp(e);
    }
    return p;
}

void SpotLobes::beginPass(int numSlots) {
    slots_.resize(size_t(std::max(numSlots, 0)));
    for (auto& s : slots_) s.clear();
}

void SpotLobes::record(int slot, int region, const glm::vec3& x, const glm::vec3& w,
                       const glm::vec3& hit, float light, float reference) {
    if (slot < 0 || size_t(slot) >= slots_.size() || region < 0 ||
        size_t(region) >= share_.size())
        return;
    if (!(light > float(settings_.outlier) * std::max(reference, 0.f)) || !std::isfinite(light))
        return;
    if (!std::isfinite(hit.x + hit.y + hit.z + x.x + x.y + x.z + w.x + w.y + w.z)) return;
    slots_[size_t(slot)].push_back(Candidate{uint32_t(region), x, w, hit, light});
}

void SpotLobes::mergeCandidates() {
    const int k = settings_.perRegion;
    for (auto& slot : slots_) {
        for (const Candidate& c : slot) {
            allocate(c.region);
            Lobe* l = lobesOf(c.region);
            uint8_t& n = lobeCount_[c.region];
            int best = -1;
            float bestErr = 0.f;
            float errP = 0.f, errD = 0.f;
            for (int i = 0; i < n; ++i) {
                const glm::vec3 dp = l[i].point - c.x;
                const float len = glm::length(dp);
                const float ep = len > 0.f ? 1.f - glm::dot(c.w, dp / len) : 2.f;
                const float ed = 1.f - glm::dot(c.w, l[i].dir);
                const float e = std::min(ep, ed);
                const float kappa = l[i].kappa > 0.f ? l[i].kappa : kInitKappa;
                if (e < std::max(kMatch / kappa, kMatchFloor) && (best < 0 || e < bestErr)) {
                    best = i;
                    bestErr = e;
                    errP = ep;
                    errD = ed;
                }
            }
            if (best < 0) {
                if (n < k) {
                    best = n++;
                } else {
                    // Replace the faintest lobe seen once, if this candidate is brighter.
                    for (int i = 0; i < n; ++i)
                        if (l[i].hits <= 1 && (best < 0 || l[i].sumLight < l[best].sumLight))
                            best = i;
                    if (best < 0 || !(double(c.light) > l[best].sumLight)) continue;
                }
                l[best] = Lobe();
                l[best].point = c.hit;
                l[best].dir = c.w;
                errP = errD = 0.f;
            }
            Lobe& lobe = l[best];
            const double t = c.light;
            lobe.sumLight += t;
            lobe.sumPoint += t * glm::dvec3(c.hit);
            lobe.sumDir += t * glm::dvec3(c.w);
            lobe.sumErrPoint += t * double(std::max(errP, 0.f));
            lobe.sumErrDir += t * double(std::max(errD, 0.f));
            ++lobe.hits;
        }
        slot.clear();
    }
}

void SpotLobes::refit(size_t region, double regionTotal) {
    Lobe* l = lobesOf(region);
    Active* act = activeOf(region);
    const int n = lobeCount_[region];
    double active = 0.0, lightKappa = 0.0;  // the active lobes' light, and light x kappa
    int m = 0;
    for (int i = 0; i < n; ++i) {
        Lobe& lobe = l[i];
        lobe.kappa = 0.f;
        if (lobe.hits < 2 || !(lobe.sumLight > 0.0)) continue;
        const glm::dvec3 d = lobe.sumDir;
        const double len = glm::length(d);
        if (!(len > 0.0)) continue;
        lobe.point = glm::vec3(lobe.sumPoint / lobe.sumLight);
        lobe.dir = glm::vec3(d / len);
        const double errP = lobe.sumErrPoint / lobe.sumLight;
        const double errD = lobe.sumErrDir / lobe.sumLight;
        const double err = std::max(std::min(errP, errD), 1e-9);
        lobe.kappa = float(std::clamp(1.0 / (kWiden * err), double(kMinKappa), double(kMaxKappa)));
        if (lobe.kappa < settings_.minKappa) continue;  // (still learning: it may narrow)
        Active& a = act[m++];
        a.aimsAtPoint = errP <= errD;
        a.axis = a.aimsAtPoint ? lobe.point : lobe.dir;
        a.kappa = lobe.kappa;
        a.norm = float(lobe.sumLight);  // normalised below
        active += lobe.sumLight;
        lightKappa += lobe.sumLight * double(lobe.kappa);
    }
    const double share = regionTotal > 0.0 ? active / regionTotal : settings_.maxShare;
    worth_[region] = 0.f;
    if (m == 0 || share < kMinActiveShare || silenced_) {
        activeCount_[region] = 0;
        share_[region] = 0.f;
        return;
    }
    if (regionTotal > 0.0)
        worth_[region] =
            float(lightKappa / (regionTotal * double(std::max(settings_.minKappa, 1.f))));
    activeCount_[region] = uint8_t(m);
    double cum = 0.0;
    for (int i = 0; i < m; ++i) {
        const double w = double(act[i].norm) / active;
        cum += w;
        act[i].cumWeight = i + 1 < m ? float(cum) : 1.f;
        act[i].norm = float(w) * vmfPdf(act[i].kappa, 1.f);
        act[i].cosCut = 1.f - kSkipExponent / act[i].kappa;
    }
    share_[region] = float(std::clamp(share, kMinShare, settings_.maxShare));
}

std::string SpotLobes::takeCandidates() {
    fieldio::Writer w;
    for (size_t slot = 0; slot < slots_.size(); ++slot) {
        for (const Candidate& c : slots_[slot]) {
            w.u32(uint32_t(slot));
            w.u32(c.region);
            w.vec3(c.x);
            w.vec3(c.w);
            w.vec3(c.hit);
            w.f32(c.light);
        }
        slots_[slot].clear();
    }
    return std::move(w.data);
}

bool SpotLobes::putCandidates(const std::string& bytes) {
    constexpr size_t kBytes = 4 + 4 + 10 * 4;
    if (bytes.size() % kBytes != 0) return false;
    // Checked whole before anything is added.
    std::vector<std::pair<uint32_t, Candidate>> all(bytes.size() / kBytes);
    fieldio::Reader r(bytes);
    for (auto& [slot, c] : all) {
        slot = r.u32();
        c.region = r.u32();
        c.x = r.vec3();
        c.w = r.vec3();
        c.hit = r.vec3();
        c.light = r.f32();
        if (slot > (1u << 20) || c.region >= share_.size()) return false;
    }
    if (!r.ok()) return false;
    for (auto& [slot, c] : all) {
        if (slot >= slots_.size()) slots_.resize(size_t(slot) + 1);
        slots_[slot].push_back(c);
    }
    return true;
}

std::string SpotLobes::write() const {
    fieldio::Writer w;
    w.u32(uint32_t(settings_.perRegion));
    w.u64(uint64_t(lobeCount_.size()));
    for (size_t r = 0; r < lobeCount_.size(); ++r) {
        w.u32(lobeCount_[r]);
        if (lobeCount_[r] == 0) continue;
        const Lobe* l = lobesOf(r);
        for (int i = 0; i < lobeCount_[r]; ++i) {
            w.vec3(l[i].point);
            w.vec3(l[i].dir);
            w.f32(l[i].kappa);
            w.f64(l[i].sumLight);
            for (int k = 0; k < 3; ++k) w.f64(l[i].sumPoint[k]);
            for (int k = 0; k < 3; ++k) w.f64(l[i].sumDir[k]);
            w.f64(l[i].sumErrPoint);
            w.f64(l[i].sumErrDir);
            w.u32(l[i].hits);
        }
    }
    return std::move(w.data);
}

bool SpotLobes::read(const std::string& bytes, std::string* why) {
    const size_t regions = lobeCount_.size();
    reset(regions, settings_);
    auto fail = [&](const std::string& what) {
        reset(regions, settings_);
        *why = what;
        return false;
    };
    fieldio::Reader r(bytes);
    const uint32_t perRegion = r.u32();
    const uint64_t savedRegions = r.u64();
    if (!r.ok()) return fail("truncated spot lobes");
    if (perRegion != uint32_t(settings_.perRegion))
        return fail("made with spots=" + std::to_string(perRegion) + ", this field has spots=" +
                    std::to_string(settings_.perRegion));
    if (savedRegions != regions) return fail("spot lobes of another number of regions");
    for (size_t reg = 0; reg < regions; ++reg) {
        const uint32_t n = r.u32();
        if (!r.ok() || n > perRegion) return fail("corrupt spot lobes");
        if (n == 0) continue;
        allocate(reg);
        Lobe* l = lobesOf(reg);
        for (uint32_t i = 0; i < n; ++i) {
            l[i].point = r.vec3();
            l[i].dir = r.vec3();
            l[i].kappa = r.f32();
            l[i].sumLight = r.f64();
            for (int k = 0; k < 3; ++k) l[i].sumPoint[k] = r.f64();
            for (int k = 0; k < 3; ++k) l[i].sumDir[k] = r.f64();
            l[i].sumErrPoint = r.f64();
            l[i].sumErrDir = r.f64();
            l[i].hits = r.u32();
            const double sums = l[i].sumLight + l[i].sumPoint.x + l[i].sumPoint.y +
                                l[i].sumPoint.z + l[i].sumDir.x + l[i].sumDir.y + l[i].sumDir.z +
                                l[i].sumErrPoint + l[i].sumErrDir;
            if (!r.ok() || !std::isfinite(sums) || !(l[i].sumLight >= 0.0) ||
                !(l[i].kappa >= 0.f) || !std::isfinite(l[i].kappa) ||
                !std::isfinite(l[i].point.x + l[i].point.y + l[i].point.z + l[i].dir.x +
                               l[i].dir.y + l[i].dir.z))
                return fail("corrupt spot lobes");
        }
        lobeCount_[reg] = uint8_t(n);
    }
    if (r.remaining() != 0) return fail("corrupt spot lobes");
    return true;
}

size_t SpotLobes::bytes() const {
    return lobes_.capacity() * sizeof(Lobe) + lobeCount_.capacity() + share_.capacity() * 4 +
           active_.capacity() * sizeof(Active) + activeCount_.capacity() +
           block_.capacity() * sizeof(uint32_t);
}

size_t SpotLobes::activeRegions() const {
    size_t n = 0;
    for (float s : share_) n += s > 0.f;
    return n;
}

size_t SpotLobes::activeLobes() const {
    size_t n = 0;
    for (uint8_t c : activeCount_) n += c;
    return n;
}

}  // namespace rlpbrt::guiding
