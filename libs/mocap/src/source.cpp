#include "mannequin/mocap/source.hpp"

#include <cmath>
#include <thread>

#include "mannequin/core/paths.hpp"
#include "mannequin/math/so3.hpp"
#include "mannequin/mocap/bvh_source.hpp"
#include "mannequin/mocap/c3d_source.hpp"
#include "mannequin/mocap/dtrack2.hpp"
#include "mannequin/mocap/synthetic_source.hpp"
#include "mannequin/skeleton/bvh_drive.hpp"
#include "mannequin/core/clock.hpp"

namespace mannequin::mocap {

using core::ConfigNode;

bool sleepUntil(std::int64_t deadline_ns, std::chrono::microseconds max_wait) {
  const std::int64_t now = core::steadyNs();
  const std::int64_t wait = deadline_ns - now;
  if (wait <= 0) return true;
  if (wait > max_wait.count() * 1000) {
    std::this_thread::sleep_for(max_wait);
    return false;
  }
  std::this_thread::sleep_for(std::chrono::nanoseconds(wait));
  return true;
}

namespace {

std::unique_ptr<Source> makeBvh(const ConfigNode& c) {
  c.allowOnly({"file", "map", "unit_scale_to_m", "bodies", "rate", "loop", "start_frame", "end_frame", "paced",
               "mark_calibration", "skip_tpose"});
  BvhSourceOptions o;
  try {
    o.file = core::findData(c["file"].str());
  } catch (const core::ConfigError& e) {
    c["file"].fail(e.what());
  }
  skeleton::BvhDriveMap map;
  const auto map_node = c.find("map");
  if (map_node) {
    try {
      map = skeleton::loadBvhDriveMap(core::findData(map_node->str()));
    } catch (const std::exception& e) {
      map_node->fail(e.what());
    }
    o.unit_scale_to_m = map.unit_scale_to_m;
  }
  o.unit_scale_to_m = c.getIn("unit_scale_to_m", o.unit_scale_to_m, 1e-6, 1e3);
  // bodies: names looked up in the map, or {name: joint} pairs
  const ConfigNode bodies = c["bodies"];
  if (bodies.isMap()) {
    for (const std::string& k : bodies.keys()) o.bodies.emplace_back(k, bodies[k].str());
  } else {
    for (const ConfigNode& b : bodies.items()) {
      const std::string name = b.str();
      std::string joint;
      for (const auto& [seg, j] : map.segments)
        if (seg == name) joint = j;
      if (joint.empty()) b.fail("body '" + name + "' is not a segment of the map (give a map, or bodies as name: joint)");
      o.bodies.emplace_back(name, joint);
    }
  }
  if (o.bodies.empty()) bodies.fail("no body to publish");
  o.rate = c.getIn("rate", 1.0, 1e-3, 1e3);
  o.loop = c.get("loop", false);
  o.start_frame = c.get("start_frame", 0LL);
  o.end_frame = c.get("end_frame", -1LL);
  o.paced = c.get("paced", true);
  o.mark_calibration = c.get("mark_calibration", true);
  o.skip_tpose = c.get("skip_tpose", true);
  try {
    return std::make_unique<BvhSource>(o);
  } catch (const std::exception& e) {
    c.fail(e.what());
  }
}

std::unique_ptr<Source> makeC3d(const ConfigNode& c) {
  c.allowOnly({"file", "mapping", "rate", "loop", "start_frame", "end_frame", "paced", "mark_calibration", "max_marker_error_m"});
  C3dSourceOptions o;
  try {
    o.file = core::findData(c["file"].str());
  } catch (const core::ConfigError& e) {
    c["file"].fail(e.what());
  }
  std::string mapping;
  try {
    mapping = core::findData(c["mapping"].str());
  } catch (const core::ConfigError& e) {
    c["mapping"].fail(e.what());
  }
  o.mapping = loadC3dMapping(mapping);  // its own FILE:LINE errors
  o.rate = c.getIn("rate", 1.0, 1e-3, 1e3);
  o.loop = c.get("loop", false);
  o.start_frame = c.get("start_frame", 0LL);
  o.end_frame = c.get("end_frame", -1LL);
  o.paced = c.get("paced", true);
  o.mark_calibration = c.get("mark_calibration", true);
  o.max_marker_error_m = c.getIn("max_marker_error_m", o.max_marker_error_m, 1e-4, 1.0);
  try {
    return std::make_unique<C3dSource>(std::move(o));
  } catch (const core::ConfigError&) {
    throw;  // the mapping's FILE:LINE
  } catch (const std::exception& e) {
    c.fail(e.what());
  }
}

math::Matrix3 orientationOf(const ConfigNode& b) {
  auto r = b.find("rotation_vector");
  return r ? math::expSO3(r->vec3()) : math::Matrix3::Identity();
}

std::unique_ptr<Source> makeSynthetic(const ConfigNode& c) {
  c.allowOnly({"rate_hz", "duration", "paced", "bodies", "occlusions"});
  SyntheticOptions o;
  o.rate_hz = c.getIn("rate_hz", 120.0, 1.0, 10000.0);
  o.duration = c.getIn("duration", 0.0, 0.0, 1e7);
  o.paced = c.get("paced", true);
  for (const ConfigNode& b : c["bodies"].items()) {
    b.allowOnly({"name", "center", "amplitude", "frequency", "phase", "waypoints", "rotation_vector", "yaw_rate"});
    SyntheticBody s;
    s.name = b["name"].str();
    if (const auto wp = b.find("waypoints")) {
      for (const char* k : {"center", "amplitude", "frequency", "phase"})
        if (b.has(k)) b[k].fail(std::string("'") + k + "' and 'waypoints' exclude each other");
      const auto items = wp->items();
      if (items.empty()) wp->fail("expected at least one waypoint {t, xyz}");
      for (const ConfigNode& w : items) {
        w.allowOnly({"t", "xyz", "rotation_vector"});
        // orientation: its own, else the previous waypoint's, else the body's
        const math::Matrix3 R = w.has("rotation_vector") ? orientationOf(w)
                                : s.waypoints.empty()    ? orientationOf(b)
                                                         : s.waypoints.back().R;
        const Waypoint p{w["t"].num(), w["xyz"].vec3(), R};
        if (!s.waypoints.empty() && !(p.t > s.waypoints.back().t)) w["t"].fail("waypoint times must increase");
        if (!(p.t >= 0)) w["t"].fail("must be >= 0 s");
        s.waypoints.push_back(p);
      }
    }
    if (b.has("center")) s.center = b["center"].vec3();
    if (b.has("amplitude")) s.amplitude = b["amplitude"].vec3();
    s.frequency = b.getIn("frequency", 0.0, 0.0, 1000.0);
    s.phase = b.get("phase", 0.0);
    s.orientation = orientationOf(b);
    s.yaw_rate = b.get("yaw_rate", 0.0);
    o.bodies.push_back(s);
  }
  if (auto occ = c.find("occlusions"))
    for (const ConfigNode& b : occ->items()) {
      b.allowOnly({"body", "from", "to"});
      Occlusion x{b["body"].str(), b["from"].num(), b["to"].num()};
      if (x.to < x.from) b.fail("'to' is before 'from'");
      o.occlusions.push_back(x);
    }
  try {
    return std::make_unique<SyntheticSource>(o);
  } catch (const std::exception& e) {
    c.fail(e.what());
  }
}

std::unique_ptr<Source> makeDTrack(const ConfigNode& c) {
  c.allowOnly({"bind", "port", "unit_to_m", "up", "bodies"});
  DTrackOptions o;
  o.bind_address = c.get("bind", o.bind_address);
  const long long port = c.get("port", 5000LL);
  if (port < 0 || port > 65535) c["port"].fail("not a UDP port");
  o.port = static_cast<int>(port);
  o.unit_to_m = c.getIn("unit_to_m", 0.001, 1e-9, 1e3);
  const std::string up = c.get("up", std::string("z"));
  if (up == "y") {
    // room calibrated y up (x right, z towards the viewer): ours is z up, x forward = −z_room... use x_ours = x, y_ours = −z, z_ours = y
    o.room_rotation << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  } else if (up != "z") {
    c["up"].fail("expected z or y");
  }
  const ConfigNode bodies = c["bodies"];
  for (const std::string& k : bodies.keys()) {
    long long id = 0;
    try {
      id = std::stoll(k);
    } catch (const std::exception&) {
      bodies.fail("key '" + k + "' is not a DTrack body id");
    }
    o.bodies.emplace_back(static_cast<int>(id), bodies[k].str());
  }
  try {
    return std::make_unique<DTrackSource>(o);
  } catch (const std::exception& e) {
    c.fail(e.what());
  }
}

}  // namespace

std::unique_ptr<Source> makeSource(const ConfigNode& config) {
  const auto kind = config["source"];
  const std::string k = kind.str();
  if (k == "bvh") return makeBvh(config["bvh"]);
  if (k == "synthetic") return makeSynthetic(config["synthetic"]);
  if (k == "dtrack2") return makeDTrack(config["dtrack2"]);
  if (k == "c3d") return makeC3d(config["c3d"]);
  kind.fail("unknown source '" + k + "' (expected bvh, c3d, synthetic or dtrack2)");
}

}  // namespace mannequin::mocap
