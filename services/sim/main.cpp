// mannequin-sim: the simulation service, a thin main over mannequin::simservice (see docs/cluster.md).
#include "mannequin/service/runtime.hpp"
#include "mannequin/simservice/sim_service.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  service::Cli cli{"mannequin-sim: steps the mannequins (calibrated mocap bodies → control frames, fixed step)\n"
                   "from mocap.frame, publishes sim.world, lockstep with mannequin-collision. Live mode is paced\n"
                   "by the wall clock; replay mode by the input timestamps (deterministic)."};
  service::CommonOptions& common = cli.options;
  std::string mode;
  double world_rate = 0;
  std::string scenario;
  std::string checkpoint, resume;
  double checkpoint_period = 0.1;
  cli.app.add_option("--mode", mode, "override the config's mode (live, replay)")->check(CLI::IsMember({"live", "replay"}));
  cli.app.add_option("--world-rate", world_rate, "override world_rate (Hz)")->check(CLI::PositiveNumber);
  cli.app.add_option("--checkpoint", checkpoint,
                     "keep the last published world state in FILE (written to FILE.tmp, renamed) to resume from after a restart");
  cli.app.add_option("--checkpoint-period", checkpoint_period, "s between two checkpoints at most (default 0.1)")
      ->check(CLI::Range(0.001, 3600.0));
  cli.app.add_option("--resume", resume,
                     "start from the checkpoint FILE (mannequins' configurations and calibration, objects' poses, step); "
                     "one that cannot be read or does not fit the config is refused (logged) and the sim starts fresh");
  cli.app.add_option("--scenario", scenario, "run this scenario (configs/scenarios/*.yaml), replacing the config's `scenario`")
      ->check(CLI::ExistingFile);
  return cli.run(argc, argv, [&](const std::atomic<bool>& stop) {
    const core::ConfigNode node = service::loadConfig(common, [&](YAML::Node& raw) {
      if (!mode.empty()) raw["mode"] = mode;
      if (world_rate > 0) raw["world_rate"] = world_rate;
      if (!scenario.empty()) raw["scenario"] = scenario;
    });
    simservice::SimServiceConfig config = simservice::parseSimConfig(node);
    const service::Endpoints ep = service::resolveEndpoints(common, node, "sim");
    config.name = ep.name;
    config.publish = ep.publish;
    config.connect = ep.connect;
    config.curve_server = ep.security.server;
    config.curve_client = ep.security.client;
    config.checkpoint = checkpoint;
    config.checkpoint_period = checkpoint_period;
    config.resume = resume;
    zmq::context_t context(common.io_threads);
    simservice::SimService service(config, context, common.heartbeat_period);
    return service.run(stop, common.duration);
  });
}
