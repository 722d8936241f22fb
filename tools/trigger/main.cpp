// mannequin-trigger: publishes one operator trigger (scenario.trigger, thesis 4.1.2's operator events) to a
// running sim: binds a publisher endpoint the sim connects to, waits until the sim has subscribed, sends
// Trigger{name, value} once and exits (docs/scenario.md, "Operator triggers on a live deployment").
#include <spdlog/spdlog.h>

#include <chrono>
#include <thread>

#include "mannequin/core/main.hpp"
#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/topics.hpp"
#include "mannequin/transport/validate.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  CLI::App app{"mannequin-trigger: sends one operator trigger (topic scenario.trigger) to a running sim, whose\n"
               "scenario listens to it (its `triggers:` list). The sim must connect to the endpoint this tool\n"
               "binds (its config's `connect` list, or the deployment's); the tool waits until it has\n"
               "subscribed, sends the trigger once and exits: 0 sent, 1 nobody subscribed within --wait,\n"
               "2 a bad command line or trigger."};
  std::string name, value, endpoint = "ipc:///tmp/mannequin-trigger", source = "trigger";
  double wait_s = 5.0;
  app.add_option("name", name, "the trigger's name, as the scenario declares it")->required();
  app.add_option("--value", value, "the trigger's value (events `trigger: {name, value}` match it)");
  app.add_option("--publish", endpoint, "endpoint to bind (the sim connects to it)")->capture_default_str();
  app.add_option("--wait", wait_s, "seconds to wait for the sim to subscribe")->check(CLI::Range(0.0, 3600.0))->capture_default_str();
  app.add_option("--source", source, "Header.source of the message")->capture_default_str();
  return core::runMain(app, argc, argv, [&] {
    v1::Trigger trigger;
    trigger.set_name(name);
    trigger.set_value(value);
    if (const std::string why = transport::validateTrigger(trigger); !why.empty())
      throw CLI::ValidationError("name/--value", why);
    zmq::context_t context(1);
    transport::PublisherOptions po;
    po.source = source;
    po.endpoints = {endpoint};
    po.linger_ms = 2000;  // the trigger still goes out after the socket closes
    transport::Publisher pub(context, po);
    const std::string topic(transport::topics::kScenarioTrigger.name);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
    for (;;) {
      pub.poll();
      if (pub.subscribed(topic)) break;
      if (std::chrono::steady_clock::now() >= deadline) {
        spdlog::error("nobody subscribed to {} on {} within {} s: is the sim running and connecting to it?", topic,
                      pub.boundEndpoints().front(), wait_s);
        return core::kExitFailure;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    pub.publish(transport::topics::kScenarioTrigger, trigger);
    spdlog::info("sent trigger '{}'{} on {}", name, value.empty() ? "" : " (value '" + value + "')", pub.boundEndpoints().front());
    return core::kExitOk;
  });
}
