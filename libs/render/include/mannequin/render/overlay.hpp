#pragma once
/// \file overlay.hpp
/// \brief The text overlay without a font library: a stroke font of our own (digits, A–Z, ". : - / %"
/// on a 2 × 4 grid, polylines), laid out into line segments in pixels (rows from the top), which
/// Renderer::drawOverlay draws on top of the frame.
#include <string_view>
#include <vector>

namespace mannequin::render {

/// A line segment in pixels: x right, y down from the top of the image.
struct Segment2 {
  float x0, y0, x1, y1;
};

/// The segments of `text` with its top-left corner at (x, y) and capital height `height` pixels.
/// Lower case is drawn as upper case; a character without a glyph (and space) only advances.
/// Advance per character: 0.75 · height.
std::vector<Segment2> strokeText(std::string_view text, float x, float y, float height);
/// True when `c` has a glyph (space and characters without one draw nothing).
bool hasGlyph(char c);

}  // namespace mannequin::render
