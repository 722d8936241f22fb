#pragma once
// mannequin-batch: pictures of the worst postures, rendered off-screen with the render library (the
// headless EGL context of libs/render, as `mannequin-render --from F.mcap --headless`) from the sim.world
// messages of a run's MCAP recording. docs/ergonomics.md, "Snapshots of the worst postures".
#include <memory>
#include <string>
#include <vector>

#include "mannequin/render/renderer.hpp"
#include "mannequin/render/scene.hpp"
#include "mannequin/render/view.hpp"

namespace mannequin::batch {

/// One scored world sample (the worse side's scores).
struct ScoredSample {
  double time_s = 0;
  int rula = 0, reba = 0;
};

/// Up to n samples to picture: the highest RULA grand score first, then the highest REBA score, then the
/// earliest; a sample closer than min_gap_s in time to one already picked is skipped (so that n pictures
/// are n different moments, not n neighbouring samples of one). Returned in that order.
std::vector<ScoredSample> pickWorst(std::vector<ScoredSample> samples, int n, double min_gap_s);

/// One picture: the sample it shows and its PNG file.
struct Snapshot {
  ScoredSample sample;
  std::string file;  ///< relative to the output directory ("snapshots/male_50th_1.png")
  std::string png;   ///< the file's bytes
};

/// Renders sim.world states of a recording with one view into width × height PNG files.
class SnapshotRenderer {
 public:
  /// Makes the off-screen OpenGL context. \throws render::RenderError saying why there is none.
  SnapshotRenderer(const render::ViewConfig& view, int width, int height);
  ~SnapshotRenderer();
  SnapshotRenderer(const SnapshotRenderer&) = delete;
  SnapshotRenderer& operator=(const SnapshotRenderer&) = delete;

  /// GL_RENDERER | GL_VERSION of the context.
  const std::string& description() const { return description_; }

  /// The states of `mcap` (its sim.world messages) at the times of `samples` (sim_time within 1 µs),
  /// drawn with `assets` (the scene and the mannequins' models) into dir/<file_stem>_<k>.png, k = 1, 2, ...
  /// in the order of `samples`. `relative_dir` is dir relative to the output directory (Snapshot::file).
  /// \throws std::runtime_error naming the file when a sample has no state in the recording.
  std::vector<Snapshot> render(const std::string& mcap, const std::vector<ScoredSample>& samples,
                               const render::SceneAssets& assets, const std::string& dir, const std::string& relative_dir,
                               const std::string& file_stem);

 private:
  render::ViewConfig view_;
  int width_, height_;
  std::unique_ptr<render::HeadlessContext> context_;
  std::unique_ptr<render::Renderer> renderer_;
  std::string description_;
};

/// RFC 4648 base64 (with '=' padding) of bytes.
std::string base64(const std::string& bytes);

}  // namespace mannequin::batch
