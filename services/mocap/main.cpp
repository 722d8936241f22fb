// mannequin-mocap: publishes mocap.frame from a capture source (libs/mocap), with heartbeats.
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <thread>

#include "mannequin/mocap/source.hpp"
#include "mannequin/service/runtime.hpp"
#include "mannequin/transport/convert.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  service::Cli cli{"mannequin-mocap: motion-capture service. Reads a source (BVH file, C3D lab capture, synthetic trajectories,\n"
                   "ART DTrack2 UDP ASCII) and publishes mocap.frame (rigid bodies in the room frame, capture\n"
                   "timestamps) and health.heartbeat."};
  service::CommonOptions& common = cli.options;
  std::string source_kind, bvh;
  double rate = 0;
  bool loop = false, no_loop = false, exit_at_end = false;
  cli.app.add_option("--source", source_kind, "override the config's source (bvh, synthetic, dtrack2)");
  cli.app.add_option("--bvh", bvh, "override bvh.file")->check(CLI::ExistingFile);
  cli.app.add_option("--rate", rate, "override bvh.rate (playback rate factor)")->check(CLI::PositiveNumber);
  cli.app.add_flag("--loop", loop, "loop the BVH file");
  cli.app.add_flag("--no-loop", no_loop, "play the BVH file once");
  cli.app.add_flag("--exit-at-end", exit_at_end, "exit when a file source ends (default: keep heartbeating, state FINISHED)");
  return cli.run(argc, argv, [&](const std::atomic<bool>& stop) {
    const core::ConfigNode config = service::loadConfig(common, [&](YAML::Node& raw) {
      if (!source_kind.empty()) raw["source"] = source_kind;
      if (!bvh.empty()) raw["bvh"]["file"] = bvh;
      if (rate > 0) raw["bvh"]["rate"] = rate;
      if (loop || no_loop) raw["bvh"]["loop"] = !no_loop;
    });
    config.allowOnly({"name", "publish", "security", "source", "bvh", "c3d", "synthetic", "dtrack2"});
    const service::Endpoints ep = service::resolveEndpoints(common, config, "mocap");
    std::unique_ptr<mocap::Source> source = mocap::makeSource(config);
    zmq::context_t context(common.io_threads);
    transport::Publisher pub(context, service::publisherOptions(ep));
    transport::HealthReporter health(pub, ep.name, nullptr, common.heartbeat_period);
    spdlog::info("{}: {} → mocap.frame on {}", ep.name, source->describe(), fmt::join(pub.boundEndpoints(), ", "));
    std::uint64_t frames = 0;
    v1::MocapFrame msg;
    service::ServiceLoop(health, stop, common.duration).run([&] {
      pub.poll();
      if (auto frame = source->next(std::chrono::milliseconds(20))) {
        transport::toMsg(*frame, source->kind(), msg);
        pub.publish(transport::topics::kMocapFrame, msg);
        health.loopIteration();
        int tracked = 0;
        for (const auto& b : frame->bodies) tracked += b.tracked;
        health.setStat("frames", static_cast<double>(++frames));
        health.setStat("capture_time_s", static_cast<double>(frame->stamp_ns) * 1e-9);
        health.setStat("tracked_bodies", tracked);
      } else if (source->finished()) {
        if (health.state() != v1::SERVICE_STATE_FINISHED) {
          spdlog::info("{}: source finished after {} frames", ep.name, frames);
          health.setState(v1::SERVICE_STATE_FINISHED, "source finished");
          health.tick(true);
        }
        if (exit_at_end) return false;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      return true;
    });
    spdlog::info("{}: stopped after {} frames", ep.name, frames);
    return 0;
  });
}
