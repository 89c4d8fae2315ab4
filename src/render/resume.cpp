#include "render/resume.h"

#include <cmath>
#include <cstring>

#include "guiding/field_io.h"

namespace rlpbrt {

namespace {

constexpr char kMagic[8] = {'R', 'L', 'P', 'B', 'R', 'S', 'U', 'M'};
// 2: the auto trial's plain pass in two parts (session 29).
constexpr uint32_t kVersion = 2;
// Bounds on what a reader accepts (a corrupt count must not allocate without limit).
constexpr uint64_t kMaxEntries = 4096;
constexpr uint64_t kMaxFilmDoubles = uint64_t(1) << 30;

// Arrays of doubles or floats, little-endian: copied as they are on a little-endian machine
// (the film's sums are most of a state's bytes), value by value elsewhere.
constexpr bool kLittleEndian = __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__;

template <class T>
void writeArray(guiding::fieldio::Writer& w, const std::vector<T>& v) {
    static_assert(sizeof(T) == 4 || sizeof(T) == 8, "floats or doubles");
    w.u64(v.size());
    if (kLittleEndian) {
        w.raw(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
        return;
    }
    for (T x : v) {
        if constexpr (sizeof(T) == 8) w.f64(x);
        else w.f32(x);
    }
}

// false if the count runs past the end or above maxCount.
template <class T>
bool readArray(guiding::fieldio::Reader& r, const std::string& data, std::vector<T>* v,
               uint64_t maxCount) {
    const uint64_t n = r.u64();
    if (!r.ok() || n > maxCount || n * sizeof(T) > r.remaining()) return false;
    v->resize(size_t(n));
    if (kLittleEndian) {
        const size_t at = data.size() - r.remaining();
        if (n > 0) std::memcpy(v->data(), data.data() + at, size_t(n) * sizeof(T));
        return r.skip(size_t(n) * sizeof(T));
    }
    for (T& x : *v) {
        if constexpr (sizeof(T) == 8) x = r.f64();
        else x = r.f32();
    }
    return r.ok();
}

}  // namespace

uint64_t fnv1a(const std::string& bytes, uint64_t hash) {
    for (unsigned char c : bytes) {
        hash ^= c;
        hash *= 0x100000001b3ull;
    }
    return hash;
}

bool writeResumeFile(const std::string& path, const ResumeFingerprint& fingerprint,
                     const RenderSnapshot& s, std::string* error) {
    guiding::fieldio::Writer w;
    w.data.reserve(64 + s.film.size() * 8 + s.estimates.size() * 4 + s.guide.size());
    w.raw(kMagic, 8);
    w.u32(kVersion);
    w.u64(fingerprint.size());
    for (const auto& [key, value] : fingerprint) {
        w.blob(key);
        w.blob(value);
    }
    w.u32(uint32_t(s.passes));
    w.u32(uint32_t(s.spp));
    w.f64(s.seconds);
    w.f64(s.guideEndPassSeconds);
    for (const uint64_t* c : s.stats.counters()) w.u64(*c);
    w.u32(uint32_t(s.ranks));
    w.u32((s.guided ? 1u : 0u) | (s.autoRan ? 2u : 0u) | (s.autoKept ? 4u : 0u) |
          (s.frozen ? 8u : 0u));
    w.u32(uint32_t(s.autoGuidedSpp));
    w.f64(s.autoGuidedCost);
    w.f64(s.autoPlainCost);
    w.u32(uint32_t(s.learningSpp));
    w.u32(uint32_t(s.trial));
    w.blob(s.trialHistory);
    w.blob(s.trialGuided);
    w.f64(s.trialGuidedSecondsPerSample);
    w.u32(uint32_t(s.trialGuidedCount));
    w.blob(s.trialPlain);
    w.f64(s.trialPlainSeconds);
    w.u32(uint32_t(s.trialPlainCount));
    w.u32(uint32_t(s.autoPlainSpp));
    writeArray(w, s.film);
    writeArray(w, s.estimates);
    w.blob(s.guide);
    w.u64(fnv1a(w.data));
    return guiding::fieldio::writeFile(path, w.data, error);
}

bool readResumeFile(const std::string& path, ResumeFingerprint* fingerprint,
                    RenderSnapshot* out, std::string* error) {
    std::string data;
    std::string err;
    if (!guiding::fieldio::readFile(path, &data, &err)) {
        *error = "cannot read the resume file (" + err + ")";
        return false;
    }
    auto fail = [&](const std::string& why) {
        *error = why;
        return false;
    };
    if (data.size() < 12 || std::memcmp(data.data(), kMagic, 8) != 0)
        return fail("not an rlpbrt resume file");
    guiding::fieldio::Reader r(data);
    r.skip(8);
    const uint32_t version = r.u32();
    if (version != kVersion)
        return fail("resume file version " + std::to_string(version) + ", this rlpbrt reads " +
                    std::to_string(kVersion));
    if (data.size() < 20) return fail("truncated resume file");
    {
        const std::string body = data.substr(0, data.size() - 8);
        guiding::fieldio::Reader tail(data);
        tail.skip(data.size() - 8);
        if (tail.u64() != fnv1a(body))
            return fail("truncated or corrupt resume file (checksum mismatch)");
    }
    ResumeFingerprint fp;
    const uint64_t entries = r.u64();
    if (!r.ok() || entries > kMaxEntries) return fail("corrupt resume file (fingerprint)");
    for (uint64_t i = 0; i < entries; ++i) {
        std::string key = r.blob(), value = r.blob();
        fp.emplace_back(std::move(key), std::move(value));
    }
    RenderSnapshot s;
    s.passes = int(r.u32());
    s.spp = int(r.u32());
    s.seconds = r.f64();
    s.guideEndPassSeconds = r.f64();
    for (uint64_t* c : s.stats.counters()) *c = r.u64();
    s.ranks = int(r.u32());
    const uint32_t flags = r.u32();
    s.guided = flags & 1u, s.autoRan = flags & 2u, s.autoKept = flags & 4u, s.frozen = flags & 8u;
    s.autoGuidedSpp = int(r.u32());
    s.autoGuidedCost = r.f64();
    s.autoPlainCost = r.f64();
    s.learningSpp = int(r.u32());
    s.trial = int(r.u32());
    s.trialHistory = r.blob();
    s.trialGuided = r.blob();
    s.trialGuidedSecondsPerSample = r.f64();
    s.trialGuidedCount = int(r.u32());
    s.trialPlain = r.blob();
    s.trialPlainSeconds = r.f64();
    s.trialPlainCount = int(r.u32());
    s.autoPlainSpp = int(r.u32());
    if (!r.ok() || s.trial < 0 || s.trial > 3)
        return fail("corrupt resume file (auto trial)");
    if (!readArray(r, data, &s.film, kMaxFilmDoubles) || s.film.size() % 4 != 0)
        return fail("corrupt resume file (film)");
    if (!readArray(r, data, &s.estimates, kMaxFilmDoubles / 4))
        return fail("corrupt resume file (estimates)");
    s.guide = r.blob();
    if (!r.ok() || r.remaining() != 8) return fail("corrupt resume file (sizes)");
    if (s.passes < 0 || s.spp < 0 || s.ranks < 1 || !(s.seconds >= 0.0) ||
        !std::isfinite(s.seconds))
        return fail("corrupt resume file (counters)");
    *fingerprint = std::move(fp);
    *out = std::move(s);
    return true;
}

std::string fingerprintMismatch(const ResumeFingerprint& saved, const ResumeFingerprint& now) {
    std::string out;
    auto add = [&](const std::string& what) { out += (out.empty() ? "" : "; ") + what; };
    for (const auto& [key, value] : now) {
        const std::string* old = nullptr;
        for (const auto& kv : saved)
            if (kv.first == key) old = &kv.second;
        if (!old)
            add(key + " is not in the file");
        else if (*old != value)
            add(key + " is " + (value.empty() ? "(none)" : value) + " here, " +
                (old->empty() ? "(none)" : *old) + " in the file");
    }
    for (const auto& kv : saved) {
        bool found = false;
        for (const auto& n : now) found = found || n.first == kv.first;
        if (!found) add(kv.first + " is in the file, not here");
    }
    return out;
}

}  // namespace rlpbrt
