// Image files through OpenImageIO (reading: any format OIIO knows; writing: EXR, PNG, PFM,
// HDR), plus the sRGB transfer functions.
//
// What pbrt-v3 does with 8-bit images (core/imageio.cpp, textures/imagemap.{h,cpp}), so that
// texture and light code can reproduce it on top of readImage():
//  - At read time pbrt-v3 only divides 8-bit values by 255 (PNG via lodepng decoded to 8-bit
//    RGB: grey expanded, alpha dropped without compositing, 16-bit reduced to 8; TGA the
//    same). No colour-space conversion happens at read time. EXR and PFM values are used as
//    stored. readImage() matches this (16-bit PNGs keep their full precision).
//  - The "imagemap" texture has a bool parameter "gamma" whose default is true exactly when
//    the file name ends in ".png" or ".tga" (case-insensitive), whatever the bit depth
//    (see pbrtDefaultGamma()); an explicit "gamma" overrides it, for any format.
//  - With gamma true the texture converts each texel when it builds its MIP map, before
//    filtering: spectrum textures: c = scale * srgbToLinear(c) per channel; float textures:
//    f = scale * srgbToLinear(luminance(c)), i.e. the curve is applied to the luminance of
//    the stored (still encoded) RGB. With gamma false: c = scale * c, f = scale *
//    luminance(c). (luminance() = pbrt-v3's y() weights, see math.h.)
//  - pbrt-v3 then flips the image in y so that texture coordinate t=0 is the bottom row
//    (readImage() keeps the file's top row first).
//  - The "infinite" light's "mapname" gets no gamma conversion at all: its texels are the
//    values as read (times "L" and "scale").
//  - An unreadable texture makes pbrt-v3 warn and use a 1x1 image of grey 0.5 instead
//    (then converted like any texel).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "render/image.h"

namespace rlpbrt {

// Facts about the file that readImage() read.
struct ImageFileInfo {
    std::string format;    // OIIO format name: "png", "openexr", "targa", "pnm", "hdr", ...
    int fileChannels = 0;  // channels in the file (before grey expansion / alpha removal)
    bool eightBit = false; // true when the file stores 8-bit unsigned integer channels
};

// Largest image readImage() accepts (width * height; 1.5 GiB as float RGB): bounds the
// memory an absurd header can claim. The OpenImageIO module applies the same limit.
constexpr long long MaxImagePixels = 1ll << 27;

// Reads the first subimage of an image file into *out as float RGB (channels = 3, top row
// first). One- and two-channel (grey, grey+alpha) files are expanded to RGB; channels after
// the third are dropped (alpha is dropped, never multiplied in). Integer formats are mapped
// to [0,1] (v / 255 for 8-bit); values are as stored, with no colour-space conversion.
// Returns false with a message in *error (if non-null) on failure. *info is optional.
bool readImage(const std::string& path, Image* out, std::string* error,
               ImageFileInfo* info = nullptr);

// pbrt-v3's default for the imagemap "gamma" parameter: true when the file name ends in
// ".png" or ".tga" (case-insensitive).
bool pbrtDefaultGamma(const std::string& path);

// Writes an RGB image (img.channels must be 3), choosing the format by the (case-insensitive)
// extension of path:
//  - .exr: 32-bit float RGB; each metadata (name, value) pair is stored as a string
//    attribute (ZIP compression);
//  - .png: 8-bit RGB, sRGB-encoded: byte = floor(255 * linearToSrgb(clamp(v, 0, 1)) + 0.5);
//    metadata go into PNG text chunks;
//  - .pfm: 32-bit float RGB, little-endian, rows stored bottom to top (metadata ignored);
//  - .hdr: Radiance RGBE (metadata ignored by the format);
//  - anything else: error.
// The file is written atomically: to a temporary file in the same directory that is then
// renamed over path; on any failure the temporary is removed and nothing is left behind
// (an existing file at path is untouched). Non-finite pixels are a caller bug (asserted in
// debug builds) and are written as 0 in release builds. Returns false with a message in
// *error (if non-null) on failure.
bool writeImage(const std::string& path, const Image& img,
                const std::vector<std::pair<std::string, std::string>>& metadata,
                std::string* error);

// Writes `content` to path atomically (temporary file in the same directory, then rename);
// nothing is left behind on failure.
bool writeFileAtomically(const std::string& path, const std::string& content,
                         std::string* error);

// Checks, before a render, that writeImage(path, ...) can succeed as far as can be known
// without writing: a known extension and an existing, writable directory. False with a
// message in *error otherwise (so that no render is wasted on an unwritable output).
bool checkOutputPath(const std::string& path, std::string* error);

// sRGB decoding (IEC 61966-2-1), as pbrt-v3's InverseGammaCorrect: v <= 0.04045 ? v / 12.92
// : ((v + 0.055) / 1.055)^2.4. Encoded value in, linear value out.
float srgbToLinear(float v);
// sRGB encoding, as pbrt-v3's GammaCorrect: v <= 0.0031308 ? 12.92 v :
// 1.055 v^(1/2.4) - 0.055. Linear value in, encoded value out (not clamped).
float linearToSrgb(float v);

}  // namespace rlpbrt
