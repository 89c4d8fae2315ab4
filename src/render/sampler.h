// Pixel samplers (pbrt-v4 style): stateless per sample. startPixelSample(pixel, index, dim)
// positions the sampler; get1D/get2D/getPixel2D then return dimension dim, dim+1, ... of that
// sample. Every value is a pure function of (seed, pixel, sampleIndex, dimension), so images
// do not depend on thread scheduling. Use one clone() per thread.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "parser/params.h"
#include "render/math.h"

namespace rlpbrt {

class Sampler {
public:
    virtual ~Sampler() = default;
    // Samples per pixel that the renderer should take (after pbrt-v3's rounding).
    int samplesPerPixel() const { return spp_; }
    // Begin sample `sampleIndex` (>= 0; indices >= spp continue with fresh, equally well
    // stratified sets of spp samples) of pixel (px, py); the next get*() call gives
    // dimension `dim`.
    virtual void startPixelSample(int px, int py, int sampleIndex, int dim = 0) = 0;
    // One sample value in [0, 1); consumes one dimension.
    virtual float get1D() = 0;
    // Two sample values in [0, 1)^2, stratified jointly; consumes two dimensions.
    virtual Vec2 get2D() = 0;
    // Film position offset inside the pixel, in [0, 1)^2 (pixel units); two dimensions.
    virtual Vec2 getPixel2D() = 0;
    // An independent copy with the same configuration (one per thread).
    virtual std::unique_ptr<Sampler> clone() const = 0;
    // A sampler of the same kind for pass `pass` of a guided render: sets of setSize samples
    // per pixel whose values are independent of every other pass's (a seed derived from this
    // sampler's and the pass index). A learned policy depends on earlier passes; if a pass's
    // samples were stratified against earlier ones (one long sequence per pixel), the samples
    // would be correlated with the policy and the image biased (measured: +0.5% on a white
    // furnace with hemi and one Sobol' sequence).
    virtual std::unique_ptr<Sampler> passSampler(int setSize, int pass) const = 0;

protected:
    explicit Sampler(int spp) : spp_(spp) {}
    int spp_;
};

// "random": independent uniform values from a counter-based hash of
// (seed, pixel, sampleIndex, dimension).
class IndependentSampler final : public Sampler {
public:
    // spp >= 1 samples per pixel; seed selects the random stream.
    IndependentSampler(int spp, uint64_t seed) : Sampler(spp), seed_(seed) {}
    void startPixelSample(int px, int py, int sampleIndex, int dim = 0) override;
    float get1D() override;
    Vec2 get2D() override;
    Vec2 getPixel2D() override { return get2D(); }
    std::unique_ptr<Sampler> clone() const override;
    std::unique_ptr<Sampler> passSampler(int setSize, int pass) const override;

private:
    uint64_t seed_;
    uint64_t key_ = 0;  // hash of (seed, pixel, sampleIndex)
    uint32_t dim_ = 0;
};

// "stratified": per dimension, the spp samples of a pixel fall one per stratum (spp strata
// for get1D, an xSamples x ySamples grid for get2D), jittered inside the stratum (or at its
// centre without jitter); strata are assigned to sample indices by a per-dimension random
// permutation.
class StratifiedSampler final : public Sampler {
public:
    // xSamples, ySamples >= 1; spp = xSamples * ySamples.
    StratifiedSampler(int xSamples, int ySamples, bool jitter, uint64_t seed)
        : Sampler(xSamples * ySamples), xSamples_(xSamples), ySamples_(ySamples),
          jitter_(jitter), seed_(seed) {}
    void startPixelSample(int px, int py, int sampleIndex, int dim = 0) override;
    float get1D() override;
    Vec2 get2D() override;
    Vec2 getPixel2D() override { return get2D(); }
    std::unique_ptr<Sampler> clone() const override;
    std::unique_ptr<Sampler> passSampler(int setSize, int pass) const override;

private:
    int xSamples_, ySamples_;
    bool jitter_;
    uint64_t seed_;
    uint64_t key_ = 0;   // hash of (seed, pixel, sampleIndex / spp)
    uint32_t index_ = 0; // sampleIndex % spp
    uint32_t dim_ = 0;
};

// Owen-scrambled Sobol' (0,2)-sequence, padded per dimension: each get1D/get2D takes the
// first one/two Sobol' dimensions at an index shuffled by a per-(pixel, dimension, block of
// spp samples) random permutation of the block's indices, Owen-scrambled with per-(pixel,
// dimension) seeds (the same for all blocks, so consecutive blocks continue one scrambled
// sequence). For power-of-two spp each 2D pair of a pixel's spp samples is a (0,m,2)-net and
// each 1D dimension has one sample per 1/spp interval; other spp take the first spp points
// of the (0,2)-sequence. Serves "sobol", "02sequence", "maxmindist" and "halton".
// For power-of-two spp above 16 the shuffle keeps prefixes stratified
// (progressivePermutationElement): the first 16 2^k samples of a block are a (0,k+4,2)-net
// too, so a `--time` render that stops inside a block of the scene's pixelsamples keeps the
// stratification of what it took.
class PaddedSobolSampler final : public Sampler {
public:
    // spp >= 1; pixelCenter makes getPixel2D return (0.5, 0.5) (halton "samplepixelcenter").
    PaddedSobolSampler(int spp, uint64_t seed, bool pixelCenter = false)
        : Sampler(spp),
          seed_(seed),
          pixelCenter_(pixelCenter),
          powerOfTwo_(spp > 0 && (spp & (spp - 1)) == 0) {}
    void startPixelSample(int px, int py, int sampleIndex, int dim = 0) override;
    float get1D() override;
    Vec2 get2D() override;
    Vec2 getPixel2D() override;
    std::unique_ptr<Sampler> clone() const override;
    std::unique_ptr<Sampler> passSampler(int setSize, int pass) const override;

private:
    // The block's index of this sample in dimension hash h (index_ shuffled).
    uint32_t shuffled(uint64_t h) const;
    uint64_t seed_;
    bool pixelCenter_;
    bool powerOfTwo_;       // spp is a power of two: blocks shuffled progressively
    uint64_t key_ = 0;      // hash of (seed, pixel)
    uint32_t base_ = 0;     // (sampleIndex / spp) * spp: first Sobol' index of the block
    uint32_t index_ = 0;    // sampleIndex % spp
    uint64_t blockSeed_ = 0;  // varies the permutations per block (0 for the first)
    uint32_t dim_ = 0;
};

// Creates a sampler from a pbrt-v3 Sampler directive: name (random, stratified, halton,
// sobol, 02sequence, lowdiscrepancy, zerotwosequence, maxmindist) and its parameters
// ("integer pixelsamples", stratified's xsamples/ysamples/jitter, halton's
// samplepixelcenter, ...; all pbrt-v3 parameters are read so none is reported unused).
// sppOverride > 0 replaces pixelsamples (stratified: factored into a near-square grid).
// The sample count follows pbrt-v3 (sobol, 02sequence and maxmindist round up to a power of
// two); such adjustments are described in *note (may be null; "" when none). Unknown names
// and invalid counts return nullptr with *error set (may be null).
std::unique_ptr<Sampler> createSampler(const std::string& name, const ParamList& params,
                                       int sppOverride, uint64_t seed, std::string* error,
                                       std::string* note);

}  // namespace rlpbrt
