// Spectral parameters converted to RGB the way pbrt-v3's default RGB build does it
// (RGBSpectrum: FromSampled, FromXYZ, blackbody via BlackbodyNormalized). Wavelengths are
// in nanometres throughout.
#pragma once

#include "parser/params.h"
#include "render/math.h"

namespace rlpbrt {

// CIE 1931 2-degree colour matching functions, tabulated every 1 nm from 360 to 830 nm
// (the tables pbrt-v3 ships in core/spectrum.cpp).
constexpr int kCieSamples = 471;
constexpr double kCieLambdaStart = 360.0;  // nm, wavelength of sample 0
constexpr double kCieLambdaEnd = 830.0;    // nm, wavelength of the last sample
// pbrt-v3's CIE_Y_integral: the integral of y-bar (per nm), used to normalise XYZ.
constexpr double kCieYIntegral = 106.856895;
extern const float kCieX[kCieSamples];
extern const float kCieY[kCieSamples];
extern const float kCieZ[kCieSamples];
// Wavelength (nm) of CIE table sample i.
inline double cieLambda(int i) { return kCieLambdaStart + i; }

// XYZ to linear sRGB (Rec. 709 primaries, D65), with pbrt-v3's XYZToRGB coefficients.
Spectrum xyzToRGB(const Vec3& xyz);
// Linear sRGB to XYZ with pbrt-v3's RGBToXYZ coefficients (row 2 is luminance()).
Vec3 rgbToXYZ(const Spectrum& rgb);

// A sampled spectral distribution given as n (lambda [nm], value) samples, converted like
// pbrt-v3's RGBSpectrum::FromSampled: samples are sorted by wavelength if unsorted; the
// piecewise-linear interpolant (held constant beyond the first/last sample) is evaluated at
// each CIE wavelength; XYZ = sum(v * xyzbar) * (830 - 360) / (kCieYIntegral * 471); then
// xyzToRGB. n <= 0 gives black.
Spectrum rgbFromSampled(const double* lambda, const double* v, int n);

// Planck's law: emitted spectral radiance of a blackbody at temperature T (kelvin) at each
// wavelength lambda[i] (nm), in W / (m^2 sr m). All zero when T <= 0 (as pbrt-v3).
void blackbody(const double* lambda, int n, double T, double* Le);
// blackbody() divided by its value at the peak wavelength (Wien's law), so the maximum
// over all wavelengths is 1 (pbrt-v3's BlackbodyNormalized). All zero when T <= 0.
void blackbodyNormalized(const double* lambda, int n, double T, double* Le);
// RGB of pbrt-v3's "blackbody" [T scale]: BlackbodyNormalized(T) sampled at the CIE
// wavelengths, converted with rgbFromSampled, times scale.
Spectrum blackbodyRGB(double T, double scale);

// The RGB value of a spectral parameter, using only its first value:
//  - RGB: numbers[0..2] as is; XYZ: xyzToRGB(numbers[0..2]);
//  - Blackbody: blackbodyRGB(numbers[0], numbers[1]) (a missing scale counts as 1, as in
//    pbrt-v4; pbrt-v3 requires it);
//  - Spectrum: all (lambda, value) pairs in numbers (inline or read from the .spd file by
//    the parser) through rgbFromSampled; an odd trailing value is ignored; no pairs = black.
// Missing numbers count as 0; a non-spectral parameter type gives black.
Spectrum spectrumFromParam(const Param& p);

}  // namespace rlpbrt
