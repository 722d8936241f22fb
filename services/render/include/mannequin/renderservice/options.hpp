#pragma once
/// \file options.hpp
/// \brief The render node's own command-line options (mannequin-render; the network ones — --name,
/// --publish, --connect, --security, --duration — are the service kit's CommonOptions).
#include <string>

namespace mannequin::renderservice {

struct NodeOptions {
  std::string view = "configs/views/desktop.yaml";  ///< --view: the view file
  std::string sim;      ///< --sim: sim config whose scene and mannequin models to draw
  std::string scene;    ///< --scene: scene file (overrides the sim config's)
  std::string from;     ///< --from: an MCAP recording's sim.world
  std::string out;      ///< --out: directory of the PNG frames (a window: of swaps.log with sync)
  std::string size;     ///< --size WIDTHxHEIGHT: headless image size (empty: the view's)
  bool headless = false;
  bool overlay = false;  ///< --overlay: the text line (frame, render fps, sim lateness)
  int every = 1;         ///< --every: every Nth message (headless)
  long long frames = 0;  ///< --frames: at most K frames (0: all)
  int sheet = 0;         ///< --sheet COLS: the frames also tiled into DIR/sheet.png (0: no sheet)
};

/// A contact sheet holds every frame in memory: --sheet needs --frames K <= this.
inline constexpr long long kMaxSheetFrames = 64;

}  // namespace mannequin::renderservice
