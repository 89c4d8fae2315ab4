// Tabulated BSDFs in pbrt-v3's ".bsdf" format (the "fourier" material): the table, its
// reader and writer, and the Catmull-Rom and Fourier-series helpers of its lobe.
//
// File format (little-endian, as pbrt-v3's FourierBSDFTable::Read):
//   char[8] "SCATFUN\x01"; int32 flags (1), nMu, nCoeffs, mMax, nChannels (1 or 3), nBases (1),
//   3 x int32 unused; float eta; 4 x int32 unused                       (64 bytes in all)
//   float mu[nMu]                 increasing cosines in [-1, 1]
//   float cdf[nMu * nMu]          per mu_o row o: integral of the a0 spline over mu_i
//   int32 offsetAndLength[nMu * nMu * 2]   per (o, i) at o * nMu + i: offset into a, order m
//   float a[nCoeffs]              per (o, i): nChannels blocks of m Fourier coefficients
// The coefficients expand f(wo, wi) |mu_i| in cos(k phi), with mu_i = cos theta of -wi, mu_o
// = cos theta of wo and phi the azimuth between -wi and wo; channel 0 is luminance (Y), 1 and 2
// red and blue (green follows from Y).
#pragma once

#include <string>
#include <vector>

#include "render/math.h"

namespace rlpbrt {

struct FourierTable {
    float eta = 1.f;  // relative IOR, bottom over top
    int mMax = 0, nChannels = 0, nMu = 0;
    std::vector<float> mu, cdf, a, a0;  // a0: each entry's first luminance coefficient
    std::vector<int> aOffset, m;
    // The coefficients of entry (offsetI, offsetO) and their count.
    const float* coefficients(int offsetI, int offsetO, int* order) const {
        size_t k = size_t(offsetO) * nMu + offsetI;
        *order = m[k];
        return a.data() + aOffset[k];
    }
};

// Reads a .bsdf file; false with *error (a file that cannot be read or is not this format).
bool readFourierTable(const std::string& path, FourierTable* table, std::string* error);
// Writes `table` in the same format (cdf and a0 as given); false with *error.
bool writeFourierTable(const std::string& path, const FourierTable& table, std::string* error);

// Catmull-Rom spline helpers with pbrt-v3's conventions (finite-difference derivatives,
// one-sided at the ends): the weights of the 4 nodes around x (false outside the nodes), the
// running integral of a spline (cdf[0] = 0; returns the total), sampling the 2D spline table
// values[alpha node][x node] at `alpha` proportionally to its value along x (with *pdf).
bool catmullRomWeights(int size, const float* nodes, float x, int* offset, float weights[4]);
float integrateCatmullRom(int n, const float* x, const float* values, float* cdf);
float sampleCatmullRom2D(int size1, int size2, const float* nodes1, const float* nodes2,
                         const float* values, const float* cdf, float alpha, float u,
                         float* pdf);
// sum_k a[k] cos(k phi); and sampling phi in [0, 2 pi) proportionally to it (returns its value,
// *pdf = value / (2 pi a[0])).
float fourierSeries(const float* a, int m, double cosPhi);
float sampleFourier(const float* a, int m, float u, float* pdf, float* phi);

// The lobe itself is FourierBSDF in bxdfs.h (implemented in fourier_bsdf.cpp).

}  // namespace rlpbrt
