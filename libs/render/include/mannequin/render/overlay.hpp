#pragma once
/// \file overlay.hpp
/// \brief The text overlay without a font library: a stroke font of our own (digits, A–Z, ". : - / % _ ,"
/// on a 2 × 4 grid, polylines), laid out into line segments in pixels (rows from the top), which
/// Renderer::drawOverlay draws on top of the frame; and what the overlay says about a WorldState.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mannequin/render/scene.hpp"

namespace mannequin::v1 {
class WorldState;
}

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

/// One line of the overlay and its colour.
struct OverlayLine {
  std::string text;
  Colour colour;
};

/// The overlay's colours: the status line, the stale-contact warning, the scenario line.
struct OverlayStyle {
  Colour text{1.0f, 1.0f, 1.0f, 1.0f};
  Colour warning{1.0f, 0.45f, 0.10f, 1.0f};   ///< orange: no other overlay text and no force arrow is this hue at full brightness
  Colour scenario{0.75f, 0.90f, 1.0f, 1.0f};  ///< pale blue
};

/// What a live node measures (a recording shows neither, so its frames stay deterministic).
struct OverlayLive {
  double fps = 0;      ///< frames drawn per second, smoothed
  double late_ms = 0;  ///< now − the state's header.send_time_ns (ms)
};

/// The overlay's lines for a state (docs/render.md, "The text overlay"):
/// 1. "FRAME <step>  T <sim_time> S" (recording, live == nullptr) or "FRAME <step>  FPS <fps>  LATE <ms> MS" (live),
///    then "  SIM LAG <ms> MS" when the state has a send time and a mocap frame with one: header.send_time_ns −
///    mocap.send_time_ns, how long after the newest mocap frame it used was sent the sim sent this state;
/// 2. when contacts_stale: "CONTACTS STALE  <step − contacts_step> STEPS OLD", in style.warning;
/// 3. when there is any: the scenario as sim.world carries it (it has no scenario field): "MECHANISMS <names>" of
///    active_mechanisms, then per control-frame mode other than "free" the mode and its frames (e.g.
///    "CONSTRAINED HAND_L"), then "OCCLUDED <frames>" (mocap-driven, not tracked); frames carry their
///    mannequin's name ("OPERATOR/HAND_L") when the state has several mannequins. In style.scenario.
std::vector<OverlayLine> overlayLines(const v1::WorldState& ws, const OverlayLive* live, const OverlayStyle& style = {});

/// The lines laid out for an image `image_height` pixels high: capital height max(8, height/40), top-left
/// corner of line i at (h, h + 1.75·h·i). One segment list and colour per line.
std::vector<std::pair<std::vector<Segment2>, Colour>> layoutOverlay(const std::vector<OverlayLine>& lines,
                                                                    int image_height);

}  // namespace mannequin::render
