// mannequin-mocap: publishes mocap.frame from a BVH file, synthetic trajectories or an ART DTrack2
// UDP stream (see docs/cluster.md), with heartbeats.
#include <CLI/CLI.hpp>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <thread>

#include "mannequin/mocap/source.hpp"
#include "mannequin/service/runtime.hpp"
#include "mannequin/transport/clock.hpp"
#include "mannequin/transport/health.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  CLI::App app{"mannequin-mocap: motion-capture service. Reads a source (BVH file, synthetic trajectories,\n"
               "ART DTrack2 UDP ASCII) and publishes mocap.frame (rigid bodies in the room frame, capture\n"
               "timestamps) and health.heartbeat."};
  service::CommonOptions common;
  service::addCommonOptions(app, common, true);
  std::string source_override, bvh_override;
  double rate = 0;
  bool loop = false, no_loop = false;
  app.add_option("--source", source_override, "override the config's source (bvh, synthetic, dtrack2)");
  app.add_option("--bvh", bvh_override, "override bvh.file")->check(CLI::ExistingFile);
  app.add_option("--rate", rate, "override bvh.rate (playback rate factor)")->check(CLI::PositiveNumber);
  app.add_flag("--loop", loop, "loop the BVH file");
  app.add_flag("--no-loop", no_loop, "play the BVH file once");
  bool exit_at_end = false;
  app.add_flag("--exit-at-end", exit_at_end, "exit when a file source ends (default: keep heartbeating, state FINISHED)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    service::setupLogging(common.log_level);
    const auto& stop = service::installStopSignals();
    (void)core::ConfigNode::load(common.config);  // syntax errors with their line
    YAML::Node raw = YAML::LoadFile(common.config);  // command-line overrides are applied to the tree
    if (!source_override.empty()) raw["source"] = source_override;
    if (!bvh_override.empty()) raw["bvh"]["file"] = bvh_override;
    if (rate > 0) raw["bvh"]["rate"] = rate;
    if (loop) raw["bvh"]["loop"] = true;
    if (no_loop) raw["bvh"]["loop"] = false;
    const core::ConfigNode config(raw, common.config);
    config.allowOnly({"name", "publish", "source", "bvh", "synthetic", "dtrack2"});
    std::vector<std::string> publish = common.publish;
    if (publish.empty()) publish = config["publish"].strings();
    if (common.name.empty()) common.name = config.get("name", std::string("mocap"));

    std::unique_ptr<mocap::Source> source = mocap::makeSource(config);
    zmq::context_t context;
    transport::Publisher pub(context, {common.name, publish});
    transport::HealthReporter health(pub, common.name, nullptr, common.heartbeat_period);
    spdlog::info("{}: {} → mocap.frame on {}", common.name, source->describe(), fmt::join(pub.boundEndpoints(), ", "));
    health.setState(v1::SERVICE_STATE_RUNNING);
    health.tick(true);

    const std::int64_t start = transport::steadyNs();
    std::uint64_t frames = 0;
    std::int64_t last_stamp = 0;
    bool finished_logged = false;
    while (!stop.load()) {
      if (common.duration > 0 && (transport::steadyNs() - start) * 1e-9 >= common.duration) break;
      pub.poll();
      if (auto sample = source->next(std::chrono::milliseconds(20))) {
        v1::MocapFrame msg = mocap::toMessage(*sample, source->kind());
        pub.publish(transport::topics::kMocapFrame, msg);
        ++frames;
        health.loopIteration();
        last_stamp = sample->stamp_ns;
        int tracked = 0;
        for (const auto& b : sample->bodies) tracked += b.tracked;
        health.setStat("frames", static_cast<double>(frames));
        health.setStat("capture_time_s", last_stamp * 1e-9);
        health.setStat("tracked_bodies", tracked);
      } else if (source->finished()) {
        if (!finished_logged) {
          spdlog::info("{}: source finished after {} frames ({:.3f} s of capture)", common.name, frames, last_stamp * 1e-9);
          health.setState(v1::SERVICE_STATE_FINISHED, "source finished");
          health.tick(true);
          finished_logged = true;
        }
        if (exit_at_end) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      health.tick();
    }
    health.setState(v1::SERVICE_STATE_STOPPING);
    health.tick(true);
    spdlog::info("{}: stopped after {} frames", common.name, frames);
    return 0;
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
}
