// Captions drawn into images with a built-in 5x7 pixel font (rlpbrt-imgtool side-by-side):
// letters, digits, space and . , : ; = + - ( ) % / * '. Letters are drawn as capitals, except
// a lower-case x, which is a small times sign ("2.5x"); any other character is a hollow box.
#pragma once

#include <string>

#include "render/image.h"

namespace rlpbrt {

// Glyph cell at scale 1: 5x7 pixels plus one pixel of spacing after each character and
// two between lines.
constexpr int CaptionGlyphWidth = 6, CaptionLineHeight = 9;

// Width in pixels of `text` drawn at `scale` (the longest line; '\n' separates lines).
int captionWidth(const std::string& text, int scale);
// Number of lines of `text`.
int captionLines(const std::string& text);

// Draws `text` into img (RGB) with its top-left corner at (x, y), each font pixel a
// scale x scale square of `value` in every channel; pixels outside the image are clipped.
void drawCaption(Image* img, int x, int y, const std::string& text, int scale, float value);

}  // namespace rlpbrt
