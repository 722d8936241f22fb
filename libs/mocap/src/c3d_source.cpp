#include "mannequin/mocap/c3d_source.hpp"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "mannequin/core/clock.hpp"
#include "mannequin/core/config.hpp"

namespace mannequin::mocap {

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

C3dMapping parseMapping(const core::ConfigNode& root) {
  root.allowOnly({"name", "unit", "markers"});
  C3dMapping m;
  m.name = root.get("name", std::string());
  if (const auto unit = root.find("unit")) {
    m.unit_scale_to_m = c3dUnitScale(unit->str());
    if (m.unit_scale_to_m == 0.0) unit->fail("expected mm, cm or m, got '" + unit->str() + "'");
  }
  const core::ConfigNode markers = root["markers"];
  if (!markers.isMap()) markers.fail("expected a map body: [marker labels]");
  for (const std::string& body : markers.keys()) {
    const core::ConfigNode entry = markers[body];
    C3dCluster c;
    c.body = body;
    c.markers = entry.strings();
    c.where = entry.where();
    if (c.markers.size() < 3) entry.fail("a rigid body needs at least 3 markers, got " + std::to_string(c.markers.size()));
    for (std::size_t i = 0; i < c.markers.size(); ++i) {
      for (std::size_t j = 0; j < i; ++j) {
        if (c.markers[i] == c.markers[j]) entry.fail("marker '" + c.markers[i] + "' listed twice");
      }
    }
    m.bodies.push_back(std::move(c));
  }
  if (m.bodies.empty()) markers.fail("no bodies");
  return m;
}

}  // namespace

double c3dUnitScale(const std::string& units) {
  const std::string u = lower(units);
  if (u == "mm") return 0.001;
  if (u == "cm") return 0.01;
  if (u == "m") return 1.0;
  return 0.0;
}

C3dMapping parseC3dMapping(const std::string& yaml_text, const std::string& source) {
  return parseMapping(core::ConfigNode::parse(yaml_text, source));
}

C3dMapping loadC3dMapping(const std::string& path) { return parseMapping(core::ConfigNode::load(path)); }

C3dSource::C3dSource(C3dSourceOptions options) : options_(std::move(options)) {
  if (!(options_.rate > 0) || !std::isfinite(options_.rate)) throw std::invalid_argument("c3d: rate must be > 0");
  if (!(options_.max_marker_error_m > 0)) throw std::invalid_argument("c3d: max_marker_error_m must be > 0");
  c3d_ = readC3dFile(options_.file);
  if (c3d_.frames_present == 0) throw std::invalid_argument(options_.file + ": the capture has no whole frame");
  if (!(c3d_.rate > 0)) throw std::invalid_argument(options_.file + ": the capture has no frame rate");
  scale_ = options_.mapping.unit_scale_to_m > 0 ? options_.mapping.unit_scale_to_m : c3dUnitScale(c3d_.units);
  if (scale_ == 0.0) {
    throw std::invalid_argument(fmt::format("{}: unknown POINT:UNITS '{}' (mm, cm or m; or set unit: in the mapping)",
                                            options_.file, c3d_.units));
  }
  try {
    first_ = resolveC3dFrame(c3d_, options_.start_frame);
    last_ = resolveC3dFrame(c3d_, options_.end_frame);
  } catch (const std::out_of_range&) {
    throw std::invalid_argument(fmt::format("{}: frame range {}..{} outside the {} frames", options_.file,
                                            options_.start_frame, options_.end_frame, c3d_.frames_present));
  }
  if (last_ < first_)
    throw std::invalid_argument(fmt::format("{}: end frame {} before start frame {}", options_.file, last_, first_));

  for (const C3dCluster& cluster : options_.mapping.bodies) {
    std::vector<int> idx;
    for (const std::string& label : cluster.markers) {
      const int i = c3d_.pointIndex(label);
      if (i < 0) {
        core::failAt(cluster.where, "markers." + cluster.body,
                     "marker '" + label + "' is not in " + options_.file + " (" + std::to_string(c3d_.points) +
                         " labels from POINT:LABELS)");
      }
      idx.push_back(i);
    }
    // the reference frame: among the frames with the most markers valid (at least 3, not collinear),
    // the first whose marker-to-marker distances are within 0.1 mm of the closest to their medians
    // over the played range (max deviation), so that a mislabelled marker in a few frames does not
    // become the body's shape
    const std::size_t n = idx.size();
    auto at = [&](int f, std::size_t k) -> std::optional<math::Vector3> {
      const auto p = c3d_.point(f, idx[k]);
      if (!p) return std::nullopt;
      return math::Vector3((*p)[0], (*p)[1], (*p)[2]) * scale_;
    };
    std::vector<double> median(n * n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        std::vector<double> d;
        for (int f = first_; f <= last_; ++f) {
          const auto a = at(f, i);
          const auto b = at(f, j);
          if (a && b) d.push_back((*a - *b).norm());
        }
        if (d.empty()) continue;
        std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
        median[i * n + j] = d[d.size() / 2];
      }
    }
    int best = -1, best_count = 0;
    double best_score = std::numeric_limits<double>::infinity();
    struct Candidate {
      int frame, count;
      double score;
    };
    std::vector<Candidate> scores;
    for (int f = first_; f <= last_; ++f) {
      int count = 0;
      for (std::size_t k = 0; k < n; ++k) count += at(f, k) ? 1 : 0;
      if (count < 3 || count < best_count) continue;
      math::Vector3 c = math::Vector3::Zero();
      for (std::size_t k = 0; k < n; ++k) {
        if (const auto p = at(f, k)) c += *p;
      }
      c /= static_cast<double>(count);
      math::Matrix3 S = math::Matrix3::Zero();
      for (std::size_t k = 0; k < n; ++k) {
        if (const auto p = at(f, k)) S += (*p - c) * (*p - c).transpose();
      }
      const Eigen::JacobiSVD<math::Matrix3> svd(S);
      if (!(svd.singularValues()(1) > 1e-8)) continue;  // collinear: no orientation (spread < 0.1 mm)
      double score = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j) {
          const auto a = at(f, i);
          const auto b = at(f, j);
          if (a && b) score = std::max(score, std::abs((*a - *b).norm() - median[i * n + j]));
        }
      }
      scores.push_back({f, count, score});
      if (count > best_count || score < best_score) {
        best_count = count;
        best_score = score;
      }
    }
    for (const Candidate& cand : scores) {
      if (cand.count == best_count && cand.score <= best_score + 1e-4) {
        best = cand.frame;
        break;
      }
    }
    if (best < 0) {
      throw std::invalid_argument(fmt::format("{}: body '{}' ({}): never three of its markers visible and not collinear "
                                              "in frames {}..{}",
                                              options_.file, cluster.body, cluster.where, first_, last_));
    }
    math::Vector3 c = math::Vector3::Zero();
    for (const int i : idx) {
      if (const auto p = c3d_.point(best, i)) c += math::Vector3((*p)[0], (*p)[1], (*p)[2]) * scale_;
    }
    c /= static_cast<double>(best_count);
    std::vector<math::Vector3> local;
    for (const int i : idx) {
      const auto p = c3d_.point(best, i);
      local.push_back(p ? math::Vector3(math::Vector3((*p)[0], (*p)[1], (*p)[2]) * scale_ - c)
                        : math::Vector3(math::Vector3::Constant(std::numeric_limits<double>::quiet_NaN())));
    }
    marker_index_.push_back(std::move(idx));
    body_markers_.push_back(std::move(local));
    ref_frame_.push_back(best);
  }
  frame_ = first_;
  last_pose_.assign(body_markers_.size(), math::SE3::Identity());
}

std::string C3dSource::describe() const {
  return fmt::format("C3D {} ({} points, {} frames at {:.1f} Hz{}, playing {}..{} at rate {}{}, {} bodies from mapping '{}')",
                     options_.file, c3d_.points, c3d_.frames_present, c3d_.rate, c3d_.truncated ? ", truncated" : "",
                     first_, last_, options_.rate, options_.loop ? ", looped" : "", body_markers_.size(),
                     options_.mapping.name);
}

bool C3dSource::fit(int frame, std::size_t body, math::SE3& pose, int& used) const {
  const std::vector<int>& idx = marker_index_[body];
  const std::vector<math::Vector3>& local = body_markers_[body];
  const std::size_t n = idx.size();
  std::vector<math::Vector3> now(n);
  std::vector<char> use(n, 0);
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(local[k].x())) continue;
    if (const auto p = c3d_.point(frame, idx[k])) {
      now[k] = math::Vector3((*p)[0], (*p)[1], (*p)[2]) * scale_;
      use[k] = 1;
    }
  }
  const double max_error = options_.max_marker_error_m;
  for (;;) {
    used = 0;
    math::Vector3 cb = math::Vector3::Zero(), cw = math::Vector3::Zero();
    for (std::size_t k = 0; k < n; ++k) {
      if (!use[k]) continue;
      cb += local[k];
      cw += now[k];
      ++used;
    }
    if (used < 3) return false;
    cb /= used;
    cw /= used;
    math::Matrix3 H = math::Matrix3::Zero();
    for (std::size_t k = 0; k < n; ++k) {
      if (use[k]) H += (local[k] - cb) * (now[k] - cw).transpose();
    }
    const Eigen::JacobiSVD<math::Matrix3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
    if (!(svd.singularValues()(1) > 1e-8)) return false;  // the markers used are collinear
    const math::Matrix3 U = svd.matrixU();
    const math::Matrix3 V = svd.matrixV();
    math::Matrix3 D = math::Matrix3::Identity();
    D(2, 2) = (V * U.transpose()).determinant() < 0 ? -1.0 : 1.0;
    pose.R = V * D * U.transpose();
    pose.p = cw - pose.R * cb;
    // a marker off the rigid body (mislabelled, a ghost) is a gap: drop the worst and fit again; with
    // three markers left there is no telling which one is wrong, and the body is occluded
    std::size_t worst = n;
    double worst_error = max_error;
    for (std::size_t k = 0; k < n; ++k) {
      if (!use[k]) continue;
      const double e = (pose.R * local[k] + pose.p - now[k]).norm();
      if (e > worst_error) {
        worst = k;
        worst_error = e;
      }
    }
    if (worst == n) return true;
    if (used == 3) return false;
    use[worst] = 0;
  }
}

Frame C3dSource::makeFrame(int frame, std::uint64_t loops, std::vector<math::SE3>& last) const {
  Frame s;
  const std::uint64_t span = static_cast<std::uint64_t>(last_ - first_ + 1);
  const std::uint64_t index = loops * span + static_cast<std::uint64_t>(frame - first_);
  s.frame_number = index;
  s.stamp_ns = static_cast<std::int64_t>(std::llround(static_cast<double>(index) / c3d_.rate * 1e9));
  s.calibration_pose = options_.mark_calibration && index == 0;
  for (std::size_t b = 0; b < body_markers_.size(); ++b) {
    Body body;
    body.name = options_.mapping.bodies[b].body;
    body.id = static_cast<int>(b);
    int used = 0;
    math::SE3 pose;
    if (fit(frame, b, pose, used)) {
      last[b] = pose;
      body.pose = pose;
      body.quality = static_cast<double>(used) / static_cast<double>(marker_index_[b].size());
    } else {
      body.pose = last[b];
      body.tracked = false;
      body.quality = 0.0;
    }
    s.bodies.push_back(std::move(body));
  }
  return s;
}

Frame C3dSource::frameAt(int frame, std::uint64_t loops) const {
  if (frame < first_ || frame > last_) {
    throw std::out_of_range(fmt::format("C3dSource::frameAt: frame {} outside {}..{}", frame, first_, last_));
  }
  // each occluded body: its last tracked pose before `frame` in the played range
  std::vector<math::SE3> last(body_markers_.size(), math::SE3::Identity());
  for (std::size_t b = 0; b < body_markers_.size(); ++b) {
    int used = 0;
    for (int f = frame - 1; f >= first_; --f) {
      if (fit(f, b, last[b], used)) break;
    }
  }
  return makeFrame(frame, loops, last);
}

std::optional<Frame> C3dSource::next(std::chrono::microseconds timeout) {
  if (finished_) return std::nullopt;
  const std::uint64_t span = static_cast<std::uint64_t>(last_ - first_ + 1);
  const std::uint64_t index = loops_ * span + static_cast<std::uint64_t>(frame_ - first_);
  if (options_.paced) {
    if (!started_) {
      started_ = true;
      start_ns_ = core::steadyNs();
    }
    const auto due = start_ns_ + static_cast<std::int64_t>(static_cast<double>(index) / c3d_.rate / options_.rate * 1e9);
    if (!sleepUntil(due, timeout)) return std::nullopt;
  }
  Frame s = makeFrame(frame_, loops_, last_pose_);
  if (++frame_ > last_) {
    if (options_.loop) {
      frame_ = first_;
      ++loops_;
    } else {
      finished_ = true;
    }
  }
  return s;
}

}  // namespace mannequin::mocap
