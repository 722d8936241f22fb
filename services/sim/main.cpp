// mannequin-sim: the simulation service (see docs/cluster.md).
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "mannequin/service/runtime.hpp"
#include "mannequin/simservice/sim_service.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  CLI::App app{"mannequin-sim: steps the mannequins (calibrated mocap bodies → control frames, fixed step)\n"
               "from mocap.frame, publishes sim.world, lockstep with mannequin-collision. Live mode is paced\n"
               "by the wall clock; replay mode by the input timestamps (deterministic)."};
  service::CommonOptions common;
  service::addCommonOptions(app, common, true);
  std::string mode;
  double world_rate = 0;
  app.add_option("--mode", mode, "override the config's mode (live, replay)")->check(CLI::IsMember({"live", "replay"}));
  app.add_option("--world-rate", world_rate, "override world_rate (Hz)")->check(CLI::PositiveNumber);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    service::setupLogging(common.log_level);
    const auto& stop = service::installStopSignals();
    YAML::Node raw = YAML::LoadFile(common.config);
    if (!mode.empty()) raw["mode"] = mode;
    if (world_rate > 0) raw["world_rate"] = world_rate;
    simservice::SimServiceConfig config = simservice::parseSimConfig(core::ConfigNode(raw, common.config));
    if (!common.name.empty()) config.name = common.name;
    if (!common.publish.empty()) config.publish = common.publish;
    if (!common.connect.empty()) config.connect = common.connect;
    if (config.publish.empty()) throw core::ConfigError(common.config + ": no publish endpoint (config 'publish' or --publish)");
    zmq::context_t context;
    simservice::SimService service(config, context, common.heartbeat_period);
    return service.run(stop, common.duration);
  } catch (const YAML::Exception& e) {
    spdlog::critical("{}:{}: YAML syntax error: {}", common.config, e.mark.line + 1, e.msg);
    return 1;
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
}
