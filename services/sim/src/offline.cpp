// The offline run of the sim service's World (mannequin-simulate, mannequin-batch): see offline.hpp.
#include "mannequin/simservice/offline.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>

#include "mannequin/collision/scene.hpp"
#include "mannequin/core/paths.hpp"
#include "mannequin/core/text.hpp"
#include "mannequin/mocap/bvh_source.hpp"
#include "mannequin/mocap/c3d_source.hpp"
#include "mannequin/proto/schema.hpp"
#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/recording/mcap_writer.hpp"
#include "mannequin/sim/step_driver.hpp"
#include "mannequin/simservice/messages.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/topics.hpp"
#include "mannequin/transport/validate.hpp"
#include "mannequin/v1/mocap.pb.h"

namespace mannequin::simservice {

namespace {

bool endsWith(std::string s, const std::string& suffix) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

/// A progress bar with ETA on stderr, redrawn at most every 0.1 s.
class Progress {
 public:
  Progress(bool on, double total, std::string label) : on_(on), total_(total), label_(std::move(label)) {}
  void update(double sim_time, double wall) {
    if (!on_ || wall - last_ < 0.1) return;
    last_ = wall;
    const double f = total_ > 0 ? std::min(1.0, sim_time / total_) : 0.0;
    const int width = 30, filled = static_cast<int>(f * width);
    const double rate = wall > 0 ? sim_time / wall : 0.0;
    const double eta = rate > 0 && total_ > 0 ? std::max(0.0, total_ - sim_time) / rate : 0.0;
    std::fprintf(stderr, "\r%s[%s%s] %5.1f%%  %.2f / %.2f s  %.1fx real time  ETA %.0f s ", label_.c_str(),
                 std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(), 100 * f, sim_time, total_, rate,
                 eta);
    std::fflush(stderr);
  }
  void done() {
    if (on_) std::fprintf(stderr, "\r%*s\r", 100, "");
  }

 private:
  bool on_;
  double total_, last_ = -1.0;
  std::string label_;
};

/// A capture opened for an offline run: the source (unpaced, once), its length (0: unknown) and file.
struct Capture {
  std::unique_ptr<mocap::Source> source;
  double length_s = 0;
  std::string file;
};

/// Opens the mocap config at `mocap_path` (a BVH capture, or a scripted one: source synthetic with a duration);
/// `bvh_file` (when not empty) replaces its BVH file. \throws core::ConfigError naming FILE:LINE.
Capture openCapture(const std::string& mocap_path, const std::string& bvh_file) {
  YAML::Node raw;
  try {
    raw = YAML::LoadFile(mocap_path);
  } catch (const YAML::Exception& e) {
    throw core::ConfigError(fmt::format("{}:{}: {}", mocap_path, e.mark.line + 1, e.msg));
  }
  if (!raw.IsMap()) throw core::ConfigError(mocap_path + ":1: a mocap config (a map with `source: bvh` and a `bvh` section)");
  Capture cap;
  const bool scripted = raw["source"] && raw["source"].as<std::string>("") == "synthetic" && raw["synthetic"] && bvh_file.empty();
  if (scripted) {
    // a scripted capture (source: synthetic, e.g. configs/sim/mocap_lean.yaml): its `duration` once, unpaced
    const double duration = raw["synthetic"]["duration"].as<double>(0.0);
    if (!(duration > 0))
      throw core::ConfigError(fmt::format("{}:{}: field 'synthetic.duration': mannequin-simulate needs a scripted capture of "
                                          "finite length (duration > 0 s)", mocap_path, raw["synthetic"].Mark().line + 1));
    raw["synthetic"]["paced"] = false;
    cap.file = mocap_path;
    cap.source = mocap::makeSource(core::ConfigNode(raw, mocap_path));
    cap.length_s = duration;
    return cap;
  }
  if (!raw["source"] || raw["source"].as<std::string>("") != "bvh" || !raw["bvh"]) {
    const YAML::Mark at = raw["source"] ? raw["source"].Mark() : raw.Mark();
    throw core::ConfigError(
        fmt::format("{}:{}: field 'source': mannequin-simulate plays BVH captures (source: bvh with a bvh section) "
                    "and scripted ones (source: synthetic with a duration)",
                    mocap_path, at.line + 1));
  }
  if (!bvh_file.empty()) raw["bvh"]["file"] = bvh_file;
  raw["bvh"]["loop"] = false;   // the capture once
  raw["bvh"]["paced"] = false;  // as fast as asked for
  cap.file = raw["bvh"]["file"].as<std::string>("");
  cap.source = mocap::makeSource(core::ConfigNode(raw, mocap_path));
  if (const auto* b = dynamic_cast<const mocap::BvhSource*>(cap.source.get()))
    cap.length_s = b->bvh().num_frames * b->bvh().frame_time / raw["bvh"]["rate"].as<double>(1.0);
  return cap;
}

/// The mocap.frame messages of an MCAP recording (mannequin-record of a deployment, or any writer of the v1
/// messages), in log-time order, once, unpaced: a capture replayed as the tracker streamed it.
class RecordedCapture : public mocap::Source {
 public:
  /// \throws OfflineInputError naming the file (and the message) for an unreadable recording, one without
  /// mocap.frame, a message that does not parse or is not a valid frame (NaN, ...), or several sources.
  explicit RecordedCapture(const std::string& path) : path_(path) {
    try {
      const recording::McapReader reader = recording::McapReader::open(path);
      bool has_topic = false;
      std::string topics;
      for (const auto& [id, ch] : reader.channels()) {
        has_topic = has_topic || ch.topic == transport::topics::kMocapFrame.name;
        topics += (topics.empty() ? "" : ", ") + ch.topic;
      }
      if (!has_topic)
        throw OfflineInputError(fmt::format("{}: no {} messages (its topics: {})", path, transport::topics::kMocapFrame.name, topics.empty() ? "none" : topics));
      recording::ReadFilter filter;
      filter.topics = {std::string(transport::topics::kMocapFrame.name)};
      recording::MessageCursor cursor = reader.messages(filter);
      recording::Message m;
      std::size_t index = 0;
      std::set<std::string> sources;
      v1::MocapFrame msg;
      while (cursor.next(m)) {
        if (!msg.ParseFromString(m.data))
          throw OfflineInputError(fmt::format("{}: {} message {} (log time {} ns): not a mannequin.v1.MocapFrame", path,
                                              transport::topics::kMocapFrame.name, index, m.log_time));
        if (const std::string why = transport::validateMocapFrame(msg); !why.empty())
          throw OfflineInputError(fmt::format("{}: {} message {} (log time {} ns): {}", path, transport::topics::kMocapFrame.name, index, m.log_time, why));
        sources.insert(msg.header().source());
        frames_.push_back(transport::fromMsg(msg));
        ++index;
      }
      if (frames_.empty()) throw OfflineInputError(fmt::format("{}: the {} channel holds no message", path, transport::topics::kMocapFrame.name));
      if (sources.size() > 1) {
        std::string list;
        for (const std::string& n : sources) list += (list.empty() ? "" : ", ") + n;
        throw OfflineInputError(fmt::format("{}: mocap.frame of {} sources ({}); the offline run plays one capture", path, sources.size(), list));
      }
      source_name_ = *sources.begin();
    } catch (const recording::McapError& e) {
      throw OfflineInputError(e.what());
    }
  }
  std::optional<mocap::Frame> next(std::chrono::microseconds) override {
    if (next_ >= frames_.size()) return std::nullopt;
    return frames_[next_++];
  }
  bool finished() const override { return next_ >= frames_.size(); }
  std::string kind() const override { return "mcap"; }
  std::string describe() const override {
    return fmt::format("{}: {} recorded mocap.frame of '{}', {:.3f} s", path_, frames_.size(), source_name_, lengthS());
  }
  double lengthS() const { return static_cast<double>(frames_.back().stamp_ns - frames_.front().stamp_ns) * 1e-9; }

 private:
  std::string path_, source_name_;
  std::vector<mocap::Frame> frames_;
  std::size_t next_ = 0;
};

}  // namespace

double groundReactionOverWeight(const OfflineSummary& s) {
  double force = 0, weight = 0;
  for (const sim::MannequinKinetics& mk : s.kinetics) {
    if (mk.summary.frames <= 0) continue;
    force += mk.summary.grf_mean_over_weight * mk.summary.weight_n;
    weight += mk.summary.weight_n;
  }
  return weight > 0 ? force / weight : std::numeric_limits<double>::quiet_NaN();
}

std::string summaryJsonMembers(const OfflineSummary& s) {
  const auto num = [](double v) { return std::isfinite(v) ? fmt::format("{:.17g}", v) : std::string("null"); };
  return fmt::format(
      "\"frames\": {}, \"steps\": {}, \"sim_time_s\": {}, \"wall_s\": {}, \"realtime_factor\": {}, \"nan_steps\": {}, "
      "\"lcp_failures\": {}, \"max_penetration_m\": {}, \"max_contacts\": {}, \"mean_contacts\": {}, "
      "\"foot_contact_fraction\": {}, \"min_balance_distance_m\": {}, \"min_force_margin_n\": {}, "
      "\"grf_mean_over_weight\": {}",
      s.frames, s.steps, num(s.sim_time_s), num(s.wall_s), num(s.realtimeFactor()), s.nan_steps, s.lcp_failures,
      num(s.max_penetration_m), s.max_contacts, num(s.meanContacts()), num(s.footContactFraction()),
      num(s.min_balance_distance_m), num(s.min_force_margin_n), num(groundReactionOverWeight(s)));
}

std::string kineticsJson(const sim::MannequinKinetics& mk) {
  const auto num = [](double v) { return std::isfinite(v) ? fmt::format("{:.17g}", v) : std::string("null"); };
  const kinetics::KineticsSummary& k = mk.summary;
  const bool any = k.frames > 0;
  return fmt::format(
      "{{\"mannequin\": {}, \"samples\": {}, \"weight_n\": {}, \"grf_mean_over_weight\": {}, \"residual_force_mean_n\": {}, "
      "\"residual_force_peak_n\": {}, \"residual_moment_peak_nm\": {}, \"peak_external_force_n\": {}}}",
      core::jsonString(mk.mannequin), k.frames, num(k.weight_n), any ? num(k.grf_mean_over_weight) : "null",
      any ? num(k.residual_force_mean_n) : "null", any ? num(k.residual_force_peak_n) : "null",
      any ? num(k.residual_moment_peak_nm) : "null", any ? num(k.peak_external_force_n) : "null");
}

OfflineRun::OfflineRun(const OfflineOptions& options) : options_(options) {
  try {
    config_ = loadSimConfig(core::findData(options.config));
    SimServiceConfig& c = config_;
    c.world.interpolation_delay = 0.0;  // frames fed up to each capture time (replay semantics)
    c.mode = Mode::kReplay;
    if (!options.mannequin.empty())
      for (MannequinEntry& e : c.mannequins) {
        e.config = core::findData(options.mannequin);
        e.where.clear();
      }
    if (!options.scene.empty()) {
      c.world.physics.scene = collision::loadScene(core::findData(options.scene));
      c.world.physics.enabled = true;
    }
    if (c.collision.mode == CollisionMode::kService)
      spdlog::info("collision: mode service needs mannequin-collision on the network: not used here{}",
                   c.world.physics.enabled ? " (the physics queries its own collision world)" : "");

    // the main capture drives the default source and every mocap source without its own `mocap`
    bool needs_main = false;
    for (const MannequinEntry& e : c.mannequins) {
      bool own_capture = false;
      for (const MocapSourceEntry& s : c.mocap_sources) own_capture = own_capture || (s.name == e.mocap_source && !s.mocap.empty());
      needs_main = needs_main || !own_capture;
    }
    const bool c3d = !options.mocap.empty() && endsWith(options.mocap, ".c3d");
    const bool mcap = !options.mocap.empty() && endsWith(options.mocap, ".mcap");
    if (mcap && needs_main) {
      auto recorded = std::make_unique<RecordedCapture>(options.mocap);
      capture_length_s_ = recorded->lengthS();
      capture_file_ = options.mocap;
      source_ = std::move(recorded);
    } else if (c3d && needs_main) {
      // a C3D lab capture: the mocap library's `source: c3d`, its marker clusters as rigid bodies; the
      // mannequins driven by the control frames whose bodies the mapping has
      YAML::Node raw;
      raw["source"] = "c3d";
      raw["c3d"]["file"] = options.mocap;
      raw["c3d"]["mapping"] = options.c3d_mapping;
      raw["c3d"]["loop"] = false;
      raw["c3d"]["paced"] = false;
      try {
        source_ = mocap::makeSource(core::ConfigNode(raw, "--mocap"));
      } catch (const std::exception& e) {  // the C3D file's (or the mapping's) own message, not the in-memory config's
        std::string what = e.what();
        if (what.rfind("--mocap:", 0) == 0) {
          const std::size_t field = what.find("': ");
          what = field == std::string::npos ? what : what.substr(field + 3);
        }
        throw OfflineInputError(what);
      }
      const auto* cs = dynamic_cast<const mocap::C3dSource*>(source_.get());
      std::set<std::string> bodies;
      for (const mocap::C3dCluster& b : mocap::loadC3dMapping(core::findData(options.c3d_mapping)).bodies) bodies.insert(b.body);
      for (MannequinEntry& e : c.mannequins) {
        std::vector<sim::ControlFrameSpec> kept;
        for (const sim::ControlFrameSpec& f : e.frames)
          if (bodies.count(f.body)) kept.push_back(f);
        if (kept.empty())
          throw OfflineInputError(fmt::format("{}: mannequin '{}': none of its control frames' bodies is in the C3D mapping {}",
                                              options.config, e.name, options.c3d_mapping));
        e.frames = std::move(kept);
      }
      if (cs && cs->c3d().rate > 0) capture_length_s_ = cs->c3d().frames_present / cs->c3d().rate;
      capture_file_ = options.mocap;
    } else if (needs_main) {
      // the sim config's `mocap` (a mocap service config), --mocap replacing its BVH file
      const std::string mocap_path = c.mocap.empty() ? core::findData("configs/sim/mocap_demo.yaml") : c.mocap;
      Capture cap = openCapture(mocap_path, options.mocap);
      source_ = std::move(cap.source);
      capture_length_s_ = cap.length_s;
      capture_file_ = cap.file;
    } else if (!options.mocap.empty()) {
      throw OfflineInputError(fmt::format("--mocap {}: no mannequin plays the main capture (every mocap source in {} has its own `mocap`)",
                                          options.mocap, options.config));
    }
    // the mocap sources with their own capture (`mocap_sources[i].mocap`)
    std::vector<Feed> own;
    for (const MocapSourceEntry& e : c.mocap_sources) {
      if (e.mocap.empty()) continue;
      Capture cap = openCapture(e.mocap, "");
      own.push_back({std::move(cap.source), {e.name}, cap.file, cap.length_s, std::nullopt});
    }
    if (!options.scenario.empty()) replaceScenario(c, options.scenario);
    world_ = std::make_unique<sim::World>(buildMannequins(c), c.world);
    setupScenario(*world_, c);
    const std::vector<std::string> names = world_->mocapSources();  // "" first
    if (source_) {
      Feed main{std::move(source_), {}, capture_file_, capture_length_s_, std::nullopt};
      for (const std::string& n : names) {
        bool own_capture = false;
        for (const Feed& f : own) own_capture = own_capture || f.names.front() == n;
        if (!own_capture) main.names.push_back(n);
      }
      feeds_.push_back(std::move(main));
    }
    for (Feed& f : own)  // those a mannequin names
      if (std::find(names.begin(), names.end(), f.names.front()) != names.end()) feeds_.push_back(std::move(f));
    capture_length_s_ = feeds_.front().length_s;  // the clock's
    capture_file_ = feeds_.front().file;
  } catch (const OfflineInputError&) {
    throw;
  } catch (const std::exception& e) {  // a bad file: its FILE:LINE message
    throw OfflineInputError(e.what());
  }
  for (int m = 0; m < world_->numMannequins(); ++m) {
    try {
      evaluators_.emplace_back(world_->model(m));
    } catch (const std::invalid_argument& e) {  // a model without the mannequin's joints (not buildMannequin's)
      throw OfflineInputError(fmt::format("{}: no ergonomic scores: {}", world_->name(m), e.what()));
    }
  }
}

OfflineRun::~OfflineRun() = default;

OfflineSummary OfflineRun::run(const SampleHook& on_sample, const StepHook& on_step) {
  sim::World& world = *world_;
  const SimServiceConfig& config = config_;
  OfflineSummary s;
  s.reset(world.numMannequins());
  s.physics = world.physics();
  s.balance_controller = world.physics() && world.config().physics.balance_controller.enabled;
  for (int m = 0; m < world.numMannequins(); ++m) s.ergonomics.push_back({world.name(m)});

  std::unique_ptr<recording::McapWriter> writer;
  std::uint16_t channel = 0, state_channel = 0;
  std::string payload;
  if (!options_.out.empty()) {
    writer = std::make_unique<recording::McapWriter>(options_.out);
    const std::uint16_t schema = writer->addSchema("mannequin.v1.WorldState", "protobuf",
                                                   proto::fileDescriptorSet(v1::WorldState::descriptor()));
    channel = writer->addChannel(std::string(transport::topics::kSimWorld.name), schema, "protobuf");
    if (world.scenarioEngine() != nullptr) {
      const std::uint16_t sc_schema = writer->addSchema("mannequin.v1.ScenarioState", "protobuf",
                                                        proto::fileDescriptorSet(v1::ScenarioState::descriptor()));
      state_channel = writer->addChannel(std::string(transport::topics::kScenarioState.name), sc_schema, "protobuf");
    }
  }
  // the scenario: its timeline, and scenario.state in the recording (at state_rate and at every switch)
  TriggerSchedule triggers(config.scenario.triggers);
  v1::ScenarioState state_msg;
  std::uint32_t state_seq = 0;
  ScenarioWatch watch(config.scenario.state_rate, config.world.step);
  const auto scenarioAfterStep = [&] {
    const ScenarioWatch::Tick tick = watch.after(world);
    if (tick.engine == nullptr) return;
    const scenario::Engine& e = *tick.engine;
    if (tick.switched) s.scenario_timeline.push_back({world.time(), e.stateName(), tick.first ? "" : ScenarioWatch::events(e)});
    if (!writer || !tick.publish) return;
    toScenarioState(e, world.time(), state_msg);
    v1::Header* h = state_msg.mutable_header();
    transport::stampHeader(*h, ++state_seq, config.name, 0);
    state_msg.SerializeToString(&payload);
    const auto t = static_cast<recording::Timestamp>(h->stamp_ns());
    writer->write(state_channel, state_seq, t, t, payload);
  };
  v1::WorldState msg;
  sim::RateDivider world_rate(config.world_rate, config.world.step);
  std::vector<ergonomics::Assessment> assessments(static_cast<std::size_t>(world.numMannequins()));
  std::vector<const ergonomics::Assessment*> sampled(static_cast<std::size_t>(world.numMannequins()), nullptr);
  const double dt = 1.0 / config.world_rate;
  const auto sampleErgonomics = [&] {
    for (int m = 0; m < world.numMannequins(); ++m) {
      const auto i = static_cast<std::size_t>(m);
      sampled[i] = nullptr;
      if (!world.calibrated(m)) continue;
      ErgonomicsSummary& e = s.ergonomics[i];
      try {
        // the loads in the hands (physics on): what they hold and push, in kilograms-force, per side
        const std::array<math::Vector3, 2> hands = world.physics() ? world.handForces(m) : std::array<math::Vector3, 2>{};
        ergonomics::Assessment& a = assessments[i];
        a.angles = evaluators_[i].measure(world.q(m));
        for (const ergonomics::Side side : {ergonomics::Side::kLeft, ergonomics::Side::kRight}) {
          const auto k = static_cast<std::size_t>(side);
          ergonomics::TaskInput input;
          const double load = handLoadKg(hands[k]);
          input.load_kg = std::isfinite(load) ? load : 0.0;
          a.rula[k] = ergonomics::scoreRula(a.angles, side, input);
          a.reba[k] = ergonomics::scoreReba(a.angles, side, input);
          if (world.physics()) {
            const double n = hands[k].norm();
            e.hand_force_sum_n[k] += n;
            e.hand_force_max_n[k] = std::max(e.hand_force_max_n[k], n);
            e.hand_load_max_kg[k] = std::max(e.hand_load_max_kg[k], input.load_kg);
          }
        }
        if (world.physics()) ++e.hand_force_samples;
        const int rula = std::max(a.rula[0].grand, a.rula[1].grand), reba = std::max(a.reba[0].score, a.reba[1].score);
        e.rula_max = std::max(e.rula_max, rula);
        e.reba_max = std::max(e.reba_max, reba);
        e.rula_time_s[static_cast<std::size_t>(ergonomics::rulaActionLevel(rula) - 1)] += dt;
        e.reba_time_s[static_cast<std::size_t>(ergonomics::rebaActionLevel(reba))] += dt;
        ++e.samples;
        sampled[i] = &assessments[i];
      } catch (const std::invalid_argument&) {
        ++e.failures;
      }
    }
  };
  sim::KineticsRecorder kinetics(world);
  const auto publish = [&] {
    if (!world_rate.tick()) return;
    sampleErgonomics();
    if (on_sample) on_sample(world, sampled);
    if (!writer) return;
    toWorldState(world, nullptr, false, true, msg);
    v1::Header* h = msg.mutable_header();
    transport::stampHeader(*h, static_cast<std::uint64_t>(++s.worlds), config.name, 0);  // send time 0: deterministic
    msg.SerializeToString(&payload);
    const auto t = static_cast<recording::Timestamp>(h->stamp_ns());
    writer->write(channel, static_cast<std::uint32_t>(s.worlds), t, t, payload);
  };

  const double total = options_.duration > 0 ? options_.duration : std::numeric_limits<double>::infinity();
  Progress progress(options_.progress, std::isfinite(total) ? std::min(total, capture_length_s_ > 0 ? capture_length_s_ : total)
                                                            : capture_length_s_,
                    options_.progress_label);
  const auto t0 = std::chrono::steady_clock::now();
  const auto wall = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  bool done = false;
  sim::StepDriver driver(world);
  double step_started = 0.0;
  driver.setHooks({[&] {
                     if (world.time() + 0.5 * config.world.step < total) return true;
                     done = true;
                     return false;
                   },
                   [&] {
                     s.scenario_triggers += triggers.due(world);
                     step_started = on_step ? wall() : 0.0;
                   },
                   [&](bool ok) {
                     if (on_step) on_step(world, wall() - step_started);
                     s.add(world, ok);
                     kinetics.sample(world);
                     scenarioAfterStep();
                     publish();
                     progress.update(world.time(), wall());
                   }});
  try {
    // the captures merged in time order (ties: the clock's frame last), the World stepped up to each of the clock's
    Feed& clock = feeds_.front();
    const std::string& clock_name = clock.names.front();
    while (!done) {
      for (Feed& fd : feeds_)
        while (!fd.pending && !fd.source->finished()) fd.pending = fd.source->next(std::chrono::microseconds(0));
      if (!clock.pending) break;  // the clock's capture is over
      Feed* next = &clock;
      for (Feed& fd : feeds_)
        if (&fd != &clock && fd.pending &&
            (fd.pending->stamp_ns < next->pending->stamp_ns || (next == &clock && fd.pending->stamp_ns == next->pending->stamp_ns)))
          next = &fd;
      const mocap::Frame f = std::move(*next->pending);
      next->pending.reset();
      ++s.frames;
      for (const mocap::Body& b : f.bodies)  // a NaN sample: the file and its frame, not a NaN world
        if (b.tracked && !(b.pose.p.allFinite() && b.pose.R.allFinite()))
          throw OfflineInputError(fmt::format("{}: frame {}: body '{}': non-finite sample", next->file, f.frame_number, b.name));
      // a capture drives the mocap sources it was given: the main one every source without its own `mocap`
      for (const std::string& src : next->names) driver.addFrame(f, src);
      if (next != &clock) continue;
      driver.stepTo(f.stamp_ns, clock_name);
    }
  } catch (...) {
    progress.done();
    if (writer) {
      writer.reset();
      std::error_code ec;
      std::filesystem::remove(options_.out, ec);
    }
    throw;
  }
  s.wall_s = wall();
  if (world.physics())
    for (int m = 0; m < world.numMannequins(); ++m) {
      s.balance_solves += world.mannequinDiagnostics(m).balance_solves;
      s.balance_failures += world.mannequinDiagnostics(m).balance_failures;
    }
  progress.done();
  s.sim_time_s = world.time();
  if (const scenario::Engine* e = world.scenarioEngine()) {
    s.scenario = e->scenario().name;
    s.scenario_states = static_cast<long long>(e->scenario().states.size());
    s.scenario_state = e->state() >= 0 ? e->stateName() : "";
    s.scenario_unapplied_actions = world.scenarioUnappliedActions();
  }
  if (const constraints::ConstraintSolver* cs = world.constraintSolver()) s.lcp_failures = cs->failures();
  // sampled every step, solved at the world rate
  if (world.physics())
    s.kinetics = kinetics.solve(world, config.world.step, std::max(1, static_cast<int>(std::lround(1.0 / (config.world_rate * config.world.step)))));
  if (writer) writer->close();
  return s;
}

}  // namespace mannequin::simservice
