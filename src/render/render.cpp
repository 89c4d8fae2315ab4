#include "render/render.h"

#include <algorithm>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <mutex>
#include <optional>
#include <thread>
#include <unistd.h>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "render/efficiency.h"

namespace rlpbrt {

namespace {

double now() {
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
}

// CPU seconds of the process (all threads): the auto trial's cost of a pass, which other
// processes on the machine then affect less than wall time.
double cpuNow() {
    timespec ts{};
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return now();
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void printProgress(int pass, int spp, int totalSpp, double elapsed, double budget,
                   double samplesPerSec) {
    double frac = budget > 0 ? std::min(1.0, elapsed / budget)
                             : (totalSpp > 0 ? double(spp) / totalSpp : 0.0);
    int width = 30, filled = int(frac * width + 0.5);
    std::string bar(size_t(filled), '=');
    bar.resize(size_t(width), ' ');
    double eta = frac > 0 ? elapsed / frac - elapsed : 0.0;
    std::fprintf(stderr, "\r[%s] pass %d, %d spp, %.2f Msamples/s, %.1fs elapsed, ETA %.1fs   ",
                 bar.c_str(), pass, spp, samplesPerSec * 1e-6, elapsed, eta);
    std::fflush(stderr);
}

// Adjoint-driven roulette's pixel estimates: the luminance of the image so far, averaged
// over 3x3 pixels (fewer outliers), in the radiance units of Li (without the film's scale).
// 0 (unknown) until the first refresh.
class PixelEstimates {
public:
    explicit PixelEstimates(const Bounds2i& bounds)
        : bounds_(bounds), w_(bounds.pMax.x - bounds.pMin.x), h_(bounds.pMax.y - bounds.pMin.y) {}

    void refresh(const Film& film) {
        const Image img = film.toImage();
        const float scale = film.params().scale;
        if (img.width != w_ || img.height != h_ || w_ <= 0 || h_ <= 0 || !(scale > 0.f)) return;
        std::vector<float> lum(size_t(w_) * size_t(h_));
        for (int y = 0; y < h_; ++y)
            for (int x = 0; x < w_; ++x)
                lum[index(x, y)] = std::max(0.f, luminance(Spectrum(img.at(x, y, 0),
                                                                    img.at(x, y, 1),
                                                                    img.at(x, y, 2)))) /
                                   scale;
        values_.assign(lum.size(), 0.f);
        for (int y = 0; y < h_; ++y)
            for (int x = 0; x < w_; ++x) {
                float sum = 0.f;
                int n = 0;
                for (int yy = std::max(y - 1, 0); yy <= std::min(y + 1, h_ - 1); ++yy)
                    for (int xx = std::max(x - 1, 0); xx <= std::min(x + 1, w_ - 1); ++xx, ++n)
                        sum += lum[index(xx, yy)];
                const float e = sum / float(n);
                values_[index(x, y)] = std::isfinite(e) ? e : 0.f;
            }
    }
    // The estimate at a sample pixel (full-image coordinates; outside the stored pixels, the
    // nearest stored one).
    float at(int x, int y) const {
        if (values_.empty()) return 0.f;
        return values_[index(std::clamp(x - bounds_.pMin.x, 0, w_ - 1),
                             std::clamp(y - bounds_.pMin.y, 0, h_ - 1))];
    }

    // The estimates as they stand (empty until the first refresh), and their restoring
    // (a resumed render's; ignored if the size does not match).
    const std::vector<float>& values() const { return values_; }
    void setValues(const std::vector<float>& v) {
        if (v.empty() || v.size() == size_t(w_) * size_t(h_)) values_ = v;
    }

private:
    size_t index(int x, int y) const { return size_t(y) * size_t(w_) + size_t(x); }
    Bounds2i bounds_;
    int w_, h_;
    std::vector<float> values_;
};

}  // namespace

RenderResult render(const Scene& scene, const RenderOptions& options) {
    RenderResult result;
    Film film(scene.filmParams, scene.filter);
    std::vector<Bounds2i> tiles = film.sampleTiles(16);
    int nThreads = options.nThreads > 0 ? options.nThreads
                                        : int(std::max(1u, std::thread::hardware_concurrency()));
    result.threads = nThreads;
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(nThreads));
    tbb::task_arena arena(nThreads);

    PathIntegrator integrator(scene, options.guide);
    guiding::GuidingField* field = options.guide.field;
    const int totalSpp = scene.sampler->samplesPerPixel();
    const bool timed = options.timeBudget > 0.0;
    // Passes sized half the samples so far (1, 1, 1, 1, 2, 3, 4, 6, 9, ...; at most 64, and
    // fewer for a large image: below), each pass's samples the next of one sequence per
    // pixel. A guided render learns between passes: frequent updates early; its samples may
    // instead (samples=independent, GuideSettings::independentPasses) come from a set of the
    // pass's own (Sampler::passSampler). Halves learned better than doubling pass sizes
    // (docs/BENCHMARKS_HISTORY.md). Plain path tracing took one sample per pixel per pass
    // until session 37: each pass ends in a wait for the last tile and for the worker to
    // wake, about 3.5 ms of wall time per pass on a 256x160 image; the larger passes take
    // 0.81 of the time on killeroo-simple, 0.95 on metal-spheres, 0.98 on cornell-box
    // (docs/BENCHMARKS_HISTORY.md, session 37).
    bool guided = field != nullptr;
    // The auto trial (GuideSettings::autoSpp): the first guided pass of at least 2 samples
    // that reaches autoSpp (or a quarter of a time budget) is measured, then a plain pass of
    // the same size; the rest is rendered plain if the guided pass cost more than kAutoMargin
    // times the plain one (render/efficiency.h): per unit of variance with a time budget
    // (relative variance per sample times CPU seconds per sample), per sample with a sample
    // count (relative variance alone: the spp are fixed, and the verdict, like the image,
    // then depends on the seed only).
    enum class Trial { Pending, MeasureGuided, MeasurePlain, MeasurePlainRest, Done };
    // The plain pass is as large as the guided one: a quarter of it (7 spp after 64) reads too
    // little of plain's variance where rare paths carry it (breakfast's trial then measured
    // 0.49-1.32 instead of 0.12-0.16; docs/BENCHMARKS_HISTORY.md, session 29). But it is
    // measured in two parts, a quarter first: too little variance read makes plain look
    // better, never worse, so if guiding wins by kAutoEarly already after the quarter, it
    // stays, and the plain samples that would cost the winners most are never drawn.
    constexpr double kAutoMargin = 1.0;
    constexpr double kAutoEarly = 0.85;
    // The first part: a guided pass of kAutoPartsFrom spp or more is followed by a plain one
    // of 1/kAutoFirstPart its size (a smaller one by a plain pass of its whole size).
    constexpr int kAutoPartsFrom = 8;
    constexpr int kAutoFirstPart = 4;

    Trial trial = guided && options.guide.autoSpp > 0 ? Trial::Pending : Trial::Done;
    // Distributed (docs/DISTRIBUTED.md): this rank renders its tiles of every pass. The auto
    // trial's moments hold this rank's pixels until it decides (then they are summed over the
    // ranks: every rank takes the same decision), its CPU seconds are summed over the ranks.
    Ranks* const ranks = options.ranks;
    // A pass's training records wait in memory until it ends (about 110 bytes per camera
    // path on cornell-box): a pass also takes at most options.maxPassPaths paths per process
    // (4M: about 0.45 GB), so a large image takes fewer samples per pass. Without it a
    // 400x400 cornell-box held 1.2 GB of records at 64 spp per pass (0.44 GB with it, at 25
    // spp, in the same time); a 1920x1080 image would hold 15 GB. Each of several ranks traces
    // its share of the pixels (the same cap on every rank: they render the same passes).
    const long long pixelsPerProcess =
        std::max<long long>(1, film.sampleBounds().area() / (ranks ? ranks->size() : 1));
    const int maxPass = int(std::clamp<long long>(
        std::max(options.maxPassPaths, 1ll) / pixelsPerProcess, 1, 64));
    std::unique_ptr<PathIntegrator> plainIntegrator;
    std::unique_ptr<PassMoments> guidedMoments, plainMoments;
    // The pixel means of the passes before the trial: the trial's reference values.
    std::unique_ptr<PassMoments> history =
        trial == Trial::Pending ? std::make_unique<PassMoments>(film.sampleBounds()) : nullptr;
    // The trial over (decided, no room for it, or a resumed state that does not fit).
    auto endTrial = [&] {
        trial = Trial::Done;
        guidedMoments.reset();
        plainMoments.reset();
        history.reset();
    };
    double guidedSecondsPerSample = 0.0;
    int guidedCount = 0;
    double plainSeconds = 0.0;  // CPU seconds of the plain pass's parts so far
    int plainCount = 0;         // ... and their spp
    // learn=N (GuideSettings::learnSpp): guided passes learn until N samples per pixel, then
    // sample from the guide as it is with an integrator that records nothing.
    const int learnSpp = options.guide.learnSpp;
    std::unique_ptr<PathIntegrator> frozenIntegrator;

    tbb::enumerable_thread_specific<std::unique_ptr<Sampler>> samplers(
        [&] { return scene.sampler->clone(); });
    tbb::enumerable_thread_specific<PathStats> stats;
    std::vector<std::unique_ptr<FilmTile>> tileFilms(tiles.size());
    for (size_t i = 0; i < tiles.size(); ++i) tileFilms[i] = film.makeTile(tiles[i]);

    // Adjoint-driven roulette's pixel estimates (PathIntegrator::wantsPixelEstimate),
    // refreshed after every guided pass once they average kRouletteMinSpp samples per pixel
    // (until then they stay 0 and the integrator plays pbrt-v3's roulette). Estimates from
    // fewer samples made the roulette cost time on short renders (docs/GUIDING.md, `rr`).
    constexpr int kRouletteMinSpp = 8;
    PixelEstimates estimates(film.pixelBounds());
    // The tiles' sums exchanged after each pass: every rank needs the whole film when the
    // integrator reads the image so far (the pixel estimates), else rank 0 alone.
    const bool everyoneNeedsFilm = field && integrator.wantsPixelEstimate();
    std::vector<float> exchange;
    const double exchangeBefore = ranks ? ranks->secondsExchanging() : 0.0;
    const double waitingBefore = ranks ? ranks->secondsWaiting() : 0.0;
    if (ranks) {
        size_t n = 0;
        for (const auto& t : tileFilms) n += t->floatCount();
        exchange.resize(n);
    }
    // The guide's pass statistics: summed over the ranks, the same on every rank.
    const guiding::SumAcrossProcesses sumAcross{
        [ranks](std::vector<double>& v) { ranks->sumDoubles(v.data(), v.size()); },
        [ranks](std::vector<uint32_t>& v) { ranks->sumCounts(v.data(), v.size()); },
        guiding::SumAcrossProcesses().countLimit,
        [ranks](std::string& bytes) { ranks->gatherBytes(bytes); }};

    double start = now();
    long long samplesDone = 0;
    long long pixelsPerPass = 0;
    for (const auto& t : tiles) pixelsPerPass += (long long)t.area();
    int pass = 0;
    // Resuming (render/resume.h): the state after the snapshot's last pass. The statistics
    // of the passes before are added after the ranks' sums (they are all ranks' already).
    PathStats earlierStats;
    if (const RenderSnapshot* snap = options.resume) {
        film.setSums(snap->film);
        estimates.setValues(snap->estimates);
        result.spp = snap->spp;
        pass = snap->passes;
        start -= snap->seconds;
        samplesDone = pixelsPerPass * snap->spp;
        earlierStats = snap->stats;
        result.guideEndPassSeconds = snap->guideEndPassSeconds;
        // The auto trial where it stood (a state without one, or after it: over).
        trial = snap->trial == 1   ? Trial::Pending
                : snap->trial == 2 ? Trial::MeasurePlain
                : snap->trial == 3 ? Trial::MeasurePlainRest
                                   : Trial::Done;
        if (trial == Trial::Done || !history || !history->setState(snap->trialHistory))
            endTrial();
        if (trial == Trial::MeasurePlain || trial == Trial::MeasurePlainRest) {
            guidedMoments = std::make_unique<PassMoments>(film.sampleBounds());
            guidedSecondsPerSample = snap->trialGuidedSecondsPerSample;
            guidedCount = snap->trialGuidedCount;
            if (!guidedMoments->setState(snap->trialGuided)) endTrial();
        }
        if (trial == Trial::MeasurePlainRest) {
            plainMoments = std::make_unique<PassMoments>(film.sampleBounds());
            plainSeconds = snap->trialPlainSeconds;
            plainCount = snap->trialPlainCount;
            if (!plainMoments->setState(snap->trialPlain)) endTrial();
        }
        // The state holds every rank's pixels: each rank keeps its own until the trial sums them.
        if (ranks)
            for (size_t ti = 0; ti < tiles.size(); ++ti)
                if (!ownsTile(ranks, ti))
                    for (PassMoments* m : {history.get(), guidedMoments.get(), plainMoments.get()})
                        if (m) m->clear(tiles[ti]);
        if (field) {
            guided = snap->guided;
            result.autoTrial.ran = snap->autoRan;
            result.autoTrial.keptGuiding = snap->autoKept;
            result.autoTrial.guidedSpp = snap->autoGuidedSpp;
            result.autoTrial.guidedCost = snap->autoGuidedCost;
            result.autoTrial.plainCost = snap->autoPlainCost;
            result.autoTrial.plainSpp = snap->autoPlainSpp;
            if (!guided) plainIntegrator = std::make_unique<PathIntegrator>(scene, GuideSettings());
            if (snap->frozen) {
                GuideSettings frozen = options.guide;
                frozen.learn = false;
                frozenIntegrator = std::make_unique<PathIntegrator>(scene, frozen);
                result.learningSpp = snap->learningSpp;
            }
        }
    }
    // The path statistics so far, of all ranks (a collective with ranks).
    auto statsSoFar = [&] {
        PathStats s;
        for (const auto& t : stats) s.add(t);
        if (ranks) {
            const auto counters = s.counters();
            double sums[PathStats::kCounters];
            for (size_t i = 0; i < counters.size(); ++i) sums[i] = double(*counters[i]);
            ranks->sumDoubles(sums, counters.size());
            for (size_t i = 0; i < counters.size(); ++i) *counters[i] = uint64_t(sums[i]);
        }
        s.add(earlierStats);
        return s;
    };
    // The auto trial's moments of every rank's pixels (a collective with ranks): m itself on
    // one process, else a copy summed over the ranks in `sum` (a part to come adds to each
    // rank's own).
    auto all = [&](const PassMoments& m, std::optional<PassMoments>& sum) -> const PassMoments& {
        if (!ranks) return m;
        sum.emplace(m);
        sum->sumAcross(*ranks);
        return *sum;
    };
    // The auto trial's verdict after its plain pass, or after the first part of it (partial:
    // the rest may follow); passSpp of the plain samples are in this pass's tiles, not yet
    // merged into the film.
    auto decideTrial = [&](bool partial, int passSpp) {
        std::optional<PassMoments> pastSum, guidedSum, plainSum;
        const PassMoments& past = all(*history, pastSum);
        const double rvGuided = all(*guidedMoments, guidedSum).relativeVariance(past);
        const double rvPlain = all(*plainMoments, plainSum).relativeVariance(past);
        const bool valid = rvGuided >= 0.0 && rvPlain >= 0.0;
        const double guidedCost = rvGuided * (timed ? guidedSecondsPerSample : 1.0);
        const double plainCost =
            rvPlain * (timed ? plainSeconds / (double(pixelsPerPass) * plainCount) : 1.0);
        if (partial && !(valid && guidedCost < kAutoEarly * plainCost)) {
            trial = Trial::MeasurePlainRest;
            return;
        }
        if (valid) {
            result.autoTrial.ran = true;
            result.autoTrial.guidedCost = guidedCost;
            result.autoTrial.plainCost = plainCost;
            result.autoTrial.plainSpp = plainCount;
            if (guidedCost > kAutoMargin * plainCost) {
                guided = false;
                result.autoTrial.keptGuiding = false;
                result.autoTrial.guidedSpp = result.spp + passSpp - plainCount;
            } else if (rvPlain > rvGuided) {
                // Where guiding stays, this pass's plain samples weigh as a guided sample's
                // variance against theirs (a first part's, merged already, weigh 1: it goes
                // on only where the two are close). At equal weight breakfast's plain samples,
                // with 16 times a guided sample's variance, would double the error of a
                // 320-spp render. The weight is a statistic of the whole image: its
                // correlation with any one pixel's mean is of the order of one over the pixel
                // count.
                for (auto& t : tileFilms) t->scale(float(rvGuided / rvPlain));
            }
        }
        endTrial();
    };
    for (;;) {
        int count = std::clamp(result.spp / 2, 1, maxPass);
        if (trial == Trial::MeasurePlain)
            count = guidedCount >= kAutoPartsFrom ? guidedCount / kAutoFirstPart : guidedCount;
        if (trial == Trial::MeasurePlainRest) count = guidedCount - plainCount;
        double sofar = 0.0;  // seconds so far, with a time budget
        if (timed) {
            sofar = now() - start;
            if (ranks) ranks->broadcast(&sofar, sizeof(sofar));  // rank 0's clock decides
        }
        if (!timed) {
            count = std::min(count, totalSpp - result.spp);
        } else if (pass > 0) {
            // Only what fits in the budget at the speed so far.
            const double perSpp = sofar / result.spp;
            count = std::min(count, int((options.timeBudget - sofar) / perSpp));
        }
        if (count <= 0) break;
        // A learning pass ends where learning does.
        const bool learning = guided && (learnSpp < 0 || result.spp < learnSpp);
        if (learning && learnSpp >= 0) count = std::min(count, learnSpp - result.spp);
        // The trial starts at autoSpp, or a quarter into a time budget if that comes first.
        if (trial == Trial::Pending && count >= 2 &&
            (result.spp + count >= options.guide.autoSpp ||
             (timed && sofar >= 0.25 * options.timeBudget))) {
            trial = Trial::MeasureGuided;
            guidedMoments = std::make_unique<PassMoments>(film.sampleBounds());
        } else if (trial == Trial::MeasurePlain) {
            if (count < 2) {
                endTrial();  // no room left for a plain pass to compare with
            } else {
                plainMoments = std::make_unique<PassMoments>(film.sampleBounds());
                plainSeconds = 0.0;
                plainCount = 0;
            }
        } else if (trial == Trial::MeasurePlainRest && count < 2) {
            decideTrial(false, 0);  // no room for the rest: the verdict of the first part
        }
        const bool plainTrialPass =
            trial == Trial::MeasurePlain || trial == Trial::MeasurePlainRest;
        if (plainTrialPass && !plainIntegrator)
            plainIntegrator = std::make_unique<PathIntegrator>(scene, GuideSettings());
        const bool guidedPass = guided && !plainTrialPass;
        const bool learningPass = guidedPass && learning;
        if (guidedPass && !learningPass && !frozenIntegrator) {
            GuideSettings frozen = options.guide;
            frozen.learn = false;
            frozenIntegrator = std::make_unique<PathIntegrator>(scene, frozen);
            result.learningSpp = result.spp;
        }
        // (Without a field, `integrator` is plain already.)
        const PathIntegrator& passIntegrator = learningPass      ? integrator
                                               : guidedPass      ? *frozenIntegrator
                                               : plainIntegrator ? *plainIntegrator
                                                                 : integrator;
        PassMoments* moments = trial == Trial::MeasureGuided ? guidedMoments.get()
                               : plainTrialPass              ? plainMoments.get()
                                                             : nullptr;
        const double passStart = cpuNow();
        // An independent pass: its own sample set, indices from 0; otherwise the next samples
        // of the one sequence per pixel.
        const bool ownSet = guided && options.guide.independentPasses;
        const int first = ownSet ? 0 : result.spp;
        std::unique_ptr<Sampler> passProto =
            ownSet ? scene.sampler->passSampler(count, pass) : nullptr;
        if (learningPass) field->beginPass(int(tiles.size()));
        arena.execute([&] {
            tbb::parallel_for(size_t(0), tiles.size(), [&](size_t ti) {
                if (!ownsTile(ranks, ti)) return;
                std::unique_ptr<Sampler> passSampler = passProto ? passProto->clone() : nullptr;
                Sampler& sampler = passSampler ? *passSampler : *samplers.local();
                PathStats& st = stats.local();
                FilmTile& tile = *tileFilms[ti];
                const Bounds2i& b = tiles[ti];
                for (int y = b.pMin.y; y < b.pMax.y; ++y)
                    for (int x = b.pMin.x; x < b.pMax.x; ++x) {
                        PixelMoments pixel;
                        const float estimate = estimates.at(x, y);
                        PassMoments* const into = moments ? moments : history.get();
                        const bool measured = into && into->tracked(x, y);
                        for (int s = first; s < first + count; ++s) {
                            sampler.startPixelSample(x, y, s);
                            Vec2 pFilm = Vec2(float(x), float(y)) + sampler.getPixel2D();
                            Vec2 uLens = sampler.get2D();
                            CameraRay cr = scene.camera->generateRay(pFilm, uLens);
                            Spectrum L(0.f);
                            if (cr.weight > 0.f)
                                L = passIntegrator.Li(cr.ray, sampler, st, int(ti),
                                                      estimate);
                            ++st.paths;
                            if (!isFinite(L)) {
                                ++st.nonFinite;
                                L = Spectrum(0.f);
                            } else if (isBlack(L)) {
                                ++st.zeroRadiancePaths;
                            }
                            tile.addSample(pFilm, L, cr.weight);
                            if (measured) pixel.add(L * cr.weight);
                        }
                        if (measured && moments)
                            moments->add(x, y, pixel.n, pixel.sum, pixel.sumSq);
                        else if (measured)
                            history->accumulate(x, y, pixel.n, pixel.sum);
                    }
            });
        });
        // The guide learns between passes: every pass samples from a frozen policy.
        if (learningPass) {
            const double endStart = now();
            if (ranks)
                field->endPassShared(sumAcross);
            else
                field->endPass();
            result.guideEndPassSeconds += now() - endStart;
        }
        double passCpu = cpuNow() - passStart;
        if (ranks && moments) ranks->sumDoubles(&passCpu, 1);  // (the trial's: all ranks')
        if (trial == Trial::MeasureGuided) {
            trial = Trial::MeasurePlain;
            guidedSecondsPerSample = passCpu / (double(pixelsPerPass) * double(count));
            guidedCount = count;
        } else if (plainTrialPass) {
            plainSeconds += passCpu;
            plainCount += count;
            decideTrial(plainCount < guidedCount, count);
        }
        if (ranks) {
            // Each tile was rendered by one rank: the sums are exact, and the film is then
            // merged in tile order as by one process.
            size_t off = 0;
            for (auto& t : tileFilms) {
                std::copy(t->data(), t->data() + t->floatCount(), exchange.data() + off);
                off += t->floatCount();
            }
            ranks->sumDisjointFloats(exchange.data(), exchange.size(), everyoneNeedsFilm);
            off = 0;
            for (auto& t : tileFilms) {
                std::copy(exchange.data() + off, exchange.data() + off + t->floatCount(),
                          t->data());
                off += t->floatCount();
            }
        }
        if (!ranks || everyoneNeedsFilm || ranks->rank() == 0) film.mergeTiles(tileFilms);
        for (auto& t : tileFilms) t->clear();
        if (guidedPass && passIntegrator.wantsPixelEstimate() &&
            result.spp + count >= kRouletteMinSpp)
            estimates.refresh(film);
        result.spp += count;
        ++pass;
        samplesDone += pixelsPerPass * count;
        double elapsed = now() - start;
        if (options.onPass) options.onPass(result.spp, elapsed, film);
        if (options.progress)
            printProgress(pass, result.spp, totalSpp, elapsed, options.timeBudget,
                          samplesDone / std::max(elapsed, 1e-9));
        // Rank 0 decides whether to stop, and whether to take a snapshot for resuming
        // (render/resume.h) where its hook wants one.
        bool decisions[2] = {false, false};  // stop, snapshot
        if (!ranks || ranks->rank() == 0) {
            decisions[0] = options.cancel && options.cancel->load();
            decisions[1] = options.snapshotDue &&
                           options.snapshotDue(result.spp, elapsed, decisions[0]);
        }
        if (ranks) ranks->broadcast(decisions, sizeof(decisions));
        const bool stop = decisions[0];
        if (decisions[1]) {
            RenderSnapshot snap;
            snap.stats = statsSoFar();  // (all ranks take part)
            // The trial's moments so far, of all ranks' pixels.
            auto shared = [&](const std::unique_ptr<PassMoments>& m) {
                std::optional<PassMoments> sum;
                return m ? all(*m, sum).state() : std::string();
            };
            const std::string trialHistory = shared(history);
            const std::string trialGuided = shared(guidedMoments);
            const std::string trialPlain =
                trial == Trial::MeasurePlainRest ? shared(plainMoments) : std::string();
            if ((!ranks || ranks->rank() == 0) && options.onSnapshot) {
                snap.passes = pass;
                snap.spp = result.spp;
                snap.seconds = elapsed;
                snap.guideEndPassSeconds = result.guideEndPassSeconds;
                snap.ranks = ranks ? ranks->size() : 1;
                snap.guided = guided;
                snap.autoRan = result.autoTrial.ran;
                snap.autoKept = result.autoTrial.keptGuiding;
                snap.autoGuidedSpp = result.autoTrial.guidedSpp;
                snap.autoGuidedCost = result.autoTrial.guidedCost;
                snap.autoPlainCost = result.autoTrial.plainCost;
                snap.autoPlainSpp = result.autoTrial.plainSpp;
                snap.frozen = frozenIntegrator != nullptr;
                snap.learningSpp = result.learningSpp;
                snap.trial = trial == Trial::Pending            ? 1
                             : trial == Trial::MeasurePlain     ? 2
                             : trial == Trial::MeasurePlainRest ? 3
                                                                : 0;
                snap.trialHistory = trialHistory;
                snap.trialGuided = trialGuided;
                snap.trialGuidedSecondsPerSample = guidedSecondsPerSample;
                snap.trialGuidedCount = guidedCount;
                snap.trialPlain = trialPlain;
                snap.trialPlainSeconds = plainSeconds;
                snap.trialPlainCount = plainCount;
                snap.film = film.sums();
                snap.estimates = estimates.values();
                std::string err;
                const bool resumable = !field || field->saveState(&snap.guide, &err);
                if (!resumable) snap.guide = err;  // (the reason, for the hook's message)
                options.onSnapshot(snap, resumable, film);
            }
        }
        if (stop) {
            result.cancelled = true;
            break;
        }
    }
    if (result.autoTrial.keptGuiding) result.autoTrial.guidedSpp = field ? result.spp : 0;
    if (!frozenIntegrator) result.learningSpp = result.autoTrial.guidedSpp;
    if (options.progress) std::fprintf(stderr, "\n");
    result.seconds = now() - start;
    result.stats = statsSoFar();
    result.passes = pass;
    if (ranks) {
        result.ranks = ranks->size();
        result.bytesExchanged = ranks->bytesExchanged();
        result.secondsExchanging = ranks->secondsExchanging() - exchangeBefore;
        result.secondsWaiting = ranks->secondsWaiting() - waitingBefore;
    }
    result.image = film.toImage();
    return result;
}

}  // namespace rlpbrt
