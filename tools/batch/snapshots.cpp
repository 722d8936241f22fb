#include "snapshots.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/v1/world.pb.h"

namespace mannequin::batch {

namespace fs = std::filesystem;

std::vector<ScoredSample> pickWorst(std::vector<ScoredSample> samples, int n, double min_gap_s) {
  std::stable_sort(samples.begin(), samples.end(), [](const ScoredSample& a, const ScoredSample& b) {
    if (a.rula != b.rula) return a.rula > b.rula;
    if (a.reba != b.reba) return a.reba > b.reba;
    return a.time_s < b.time_s;
  });
  std::vector<ScoredSample> out;
  for (const ScoredSample& s : samples) {
    if (static_cast<int>(out.size()) >= n) break;
    if (std::any_of(out.begin(), out.end(), [&](const ScoredSample& p) { return std::abs(p.time_s - s.time_s) < min_gap_s; })) continue;
    out.push_back(s);
  }
  return out;
}

SnapshotRenderer::SnapshotRenderer(const render::ViewConfig& view, int width, int height)
    : view_(view), width_(width), height_(height) {
  context_ = std::make_unique<render::HeadlessContext>(width, height);
  renderer_ = std::make_unique<render::Renderer>();
  description_ = render::Renderer::describeContext();
}

SnapshotRenderer::~SnapshotRenderer() {
  if (context_) context_->makeCurrent();  // the renderer's GL objects go with its context current
  renderer_.reset();
  context_.reset();
}

std::vector<Snapshot> SnapshotRenderer::render(const std::string& mcap, const std::vector<ScoredSample>& samples,
                                               const render::SceneAssets& assets, const std::string& dir,
                                               const std::string& relative_dir, const std::string& file_stem) {
  // the states at the samples' times, in one pass over the recording
  std::vector<v1::WorldState> states(samples.size());
  std::vector<bool> found(samples.size(), false);
  const recording::McapReader reader = recording::McapReader::open(mcap);
  recording::ReadFilter filter;
  filter.topics = {"sim.world"};
  recording::MessageCursor cursor = reader.messages(filter);
  recording::Message msg;
  v1::WorldState ws;
  long long index = 0;
  while (cursor.next(msg)) {
    if (!ws.ParseFromString(msg.data))
      throw std::runtime_error(mcap + ": sim.world message " + std::to_string(index) + " is not a WorldState");
    ++index;
    for (std::size_t i = 0; i < samples.size(); ++i)
      if (!found[i] && std::abs(ws.sim_time() - samples[i].time_s) < 1e-6) {
        states[i] = ws;
        found[i] = true;
      }
  }
  for (std::size_t i = 0; i < samples.size(); ++i)
    if (!found[i])
      throw std::runtime_error(mcap + ": no sim.world state at t = " + std::to_string(samples[i].time_s) + " s");

  context_->makeCurrent();
  fs::create_directories(dir);
  std::vector<Snapshot> out;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    render::ViewConfig v = view_;
    if (v.type == render::ViewConfig::Type::kDesktop && !v.follow.empty()) v.orbit = render::followed(v.orbit, states[i], v.follow);
    render::RenderScene scene = render::buildScene(states[i], assets, v.style);
    render::applyLayers(scene, v.layers);
    renderer_->draw(scene, v.eyes(width_, height_), height_, v.background);
    const std::string name = file_stem + "_" + std::to_string(i + 1) + ".png";
    const fs::path path = fs::path(dir) / name;
    render::writePng(path.string(), context_->read());
    std::ifstream in(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) throw std::runtime_error("cannot read back " + path.string());
    out.push_back({samples[i], (fs::path(relative_dir) / name).generic_string(), std::move(bytes)});
  }
  return out;
}

std::string base64(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (two ? static_cast<unsigned char>(bytes[i + 1]) << 8 : 0u);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

}  // namespace mannequin::batch
