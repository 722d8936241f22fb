// mannequin-replay: publishes the messages of an MCAP recording back onto the cluster, with the
// original timing (or a rate factor), looped, ranged, filtered by topic, paused/stepped from the
// terminal, or in lockstep with a consumer (docs/recording.md).
#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <set>
#include <thread>

#include "cluster_io.hpp"
#include "mannequin/core/main.hpp"
#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/recording/replay.hpp"
#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/subscriber.hpp"
#include "terminal.hpp"

using namespace mannequin;

namespace {

void printInfo(const recording::McapReader& r, const std::string& file) {
  const recording::Statistics& s = r.statistics();
  std::printf("file       %s\n", file.c_str());
  std::printf("read       %s\n", r.indexed() ? "indexed (summary)" : r.recovered() ? "RECOVERED by linear scan" : "linear scan");
  if (!r.note().empty()) std::printf("note       %s\n", r.note().c_str());
  std::printf("library    %s\n", r.library().c_str());
  const double dur = s.message_count > 0 ? (s.message_end_time - s.message_start_time) / 1e9 : 0.0;
  std::printf("messages   %llu in %u chunks, %.3f s (log_time %llu .. %llu ns)\n",
              static_cast<unsigned long long>(s.message_count), s.chunk_count, dur,
              static_cast<unsigned long long>(s.message_start_time), static_cast<unsigned long long>(s.message_end_time));
  for (const auto& [id, c] : r.channels()) {
    const auto it = s.channel_message_counts.find(id);
    const auto sc = r.schemas().find(c.schema_id);
    std::printf("topic      %-20s %8llu  %s\n", c.topic.c_str(),
                static_cast<unsigned long long>(it == s.channel_message_counts.end() ? 0 : it->second),
                sc == r.schemas().end() ? "(no schema)" : (sc->second.name + " [" + sc->second.encoding + "]").c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mannequin-replay: publishes an MCAP recording onto the cluster. Keys (when stdin is a terminal):\n"
               "space = pause/resume, n or s = step one message, q = quit."};
  std::string ack_rule = "any";
  std::string file, deployment, run_dir, as_services, ack_from, topics_arg, lockstep_after = "mocap.frame", ack_topic, log_level = "info";
  std::vector<std::string> publish, ack_connect;
  double linger = 1.0;
  double rate = 1.0, start = 0, end = -1, ack_timeout = 2.0, wait_subscribers = 1.0, progress = 5.0;
  bool loop = false, paused = false, no_keys = false, info = false, fast = false;
  std::uint64_t max_loops = 0, ack_every = 1;
  app.add_option("file", file, "MCAP recording")->required()->check(CLI::ExistingFile);
  app.add_option("--publish", publish, "endpoint to bind the replay publisher to (repeatable): where the consumers "
                                       "expect the publisher that the replay stands in for");
  app.add_option("--deployment", deployment, "deployment file: with --as, publish where those services would")
      ->check(CLI::ExistingFile);
  app.add_option("--as", as_services, "comma-separated services of --deployment the replay stands in for (they must "
                                      "not be running): binds their publish endpoints");
  app.add_option("--run-dir", run_dir, "${RUN_DIR} of the deployment's endpoints (default: as mannequin-launch)");
  app.add_option("--rate", rate, "rate factor of the original timing (2 = twice as fast)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_flag("--fast", fast, "ignore timing: publish as fast as possible");
  app.add_flag("--loop", loop, "start again at the end");
  app.add_option("--max-loops", max_loops, "with --loop: stop after this many passes (0 = forever)")->capture_default_str();
  app.add_option("--start", start, "first message: seconds after the recording's first message")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--end", end, "last message: seconds after the recording's first message (<0 = to the end)")
      ->capture_default_str();
  app.add_option("--topics", topics_arg, "comma-separated topics to replay (default: all)");
  app.add_flag("--paused", paused, "start paused (space or n to go on)");
  app.add_flag("--no-keys", no_keys, "do not read keys from the terminal");
  app.add_option("--lockstep", ack_topic, "lockstep: after each --lockstep-after message, wait for the consumer's ack: "
                                          "a message on this topic (from --ack-connect / --ack-from), see --ack-rule");
  app.add_option("--ack-rule", ack_rule, "any: any new ack-topic message acknowledges; stamp: one whose Header.stamp_ns "
                                         "reaches the replayed message's (consumers that keep the input clock)")
      ->check(CLI::IsMember({"any", "stamp"}))->capture_default_str();
  app.add_option("--lockstep-after", lockstep_after, "comma-separated topics that wait for the consumer's ack")
      ->capture_default_str();
  app.add_option("--ack-connect", ack_connect, "endpoint of the consumer's publisher (repeatable)");
  app.add_option("--ack-from", ack_from, "with --deployment: the consumer service whose endpoint gives the acks");
  app.add_option("--ack-every", ack_every, "wait for an ack after every N-th --lockstep-after message")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--ack-timeout", ack_timeout, "seconds to wait for an ack before going on (counted, warned)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--wait-subscribers", wait_subscribers, "wait up to this many seconds for a first subscriber")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--linger", linger, "seconds to keep the publisher open after the last message, so that queued "
                                     "messages reach slow subscribers")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_flag("--info", info, "print what the file holds and exit");
  app.add_option("--progress", progress, "log progress every this many seconds (0 = never)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")->capture_default_str()->check(core::logLevelCheck());
  return core::runMain(app, argc, argv, [&] {
    if ((!as_services.empty() || !ack_from.empty()) && deployment.empty()) {
      throw CLI::ValidationError("--as and --ack-from need --deployment FILE");
    }
    if (!info && publish.empty() && as_services.empty()) {
      throw CLI::ValidationError("give --publish ENDPOINT or --deployment FILE --as SERVICE (unless --info)");
    }
    if (!ack_topic.empty() && ack_connect.empty() && ack_from.empty()) {
      throw CLI::ValidationError("--lockstep needs --ack-connect ENDPOINT or --ack-from SERVICE");
    }
    if (end >= 0 && end < start) throw CLI::ValidationError("--end is before --start");
    core::setupLogging(log_level);
    spdlog::set_pattern("[%H:%M:%S.%e] [replay] %^%l%$ %v");
    const recording::McapReader reader = recording::McapReader::open(file);
    if (info) {
      printInfo(reader, file);
      return 0;
    }
    if (reader.recovered()) spdlog::warn("{}", reader.note());
    const recording::Statistics& stats = reader.statistics();

    recording::PlayerOptions po;
    po.rate = rate;
    po.loop = loop;
    po.max_loops = max_loops;
    po.start_paused = paused;
    po.as_fast_as_possible = fast || !ack_topic.empty();
    po.filter.topics = tools::splitList(topics_arg);
    const recording::Timestamp t0 = stats.message_start_time;
    po.filter.start = t0 + static_cast<recording::Timestamp>(start * 1e9);
    if (end >= 0) po.filter.end = t0 + static_cast<recording::Timestamp>(end * 1e9);
    recording::Player player(reader, po);  // validates topics and rate

    if (!as_services.empty()) {
      for (const std::string& e : tools::publishEndpoints(deployment, run_dir, tools::splitList(as_services), true)) publish.push_back(e);
    }
    if (!ack_from.empty()) {
      for (const std::string& e : tools::publishEndpoints(deployment, run_dir, {ack_from})) ack_connect.push_back(e);
    }
    const auto& stop = core::installStopSignals();
    zmq::context_t context;
    transport::Publisher pub(context, {"replay", publish});
    spdlog::info("{}: {} messages, {:.1f} s; publishing on {}", file, stats.message_count,
                 (stats.message_end_time - stats.message_start_time) / 1e9, fmt::format("{}", fmt::join(pub.boundEndpoints(), ", ")));

    // lockstep acks
    std::unique_ptr<transport::Subscriber> acks;
    std::int64_t acked_stamp = std::numeric_limits<std::int64_t>::min();
    std::uint64_t acks_received = 0;
    std::uint64_t ack_timeouts = 0, waited = 0, gated = 0;
    const std::vector<std::string> after_list = tools::splitList(lockstep_after);
    const std::set<std::string> after(after_list.begin(), after_list.end());
    if (!ack_topic.empty()) {
      acks = std::make_unique<transport::Subscriber>(context, transport::SubscriberOptions{"replay-ack", ack_connect});
      acks->subscribeRaw(ack_topic, [&](std::string_view topic, std::string_view payload, const transport::Received&) {
        if (topic != ack_topic) return;
        ++acks_received;
        if (const auto h = tools::parseHeader(payload)) acked_stamp = std::max(acked_stamp, h->stamp_ns);
      });
    }

    // late joiners: wait a moment for the first subscription (ZeroMQ drops what is sent before)
    const auto wait_until = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_subscribers);
    while (pub.subscriptions() == 0 && std::chrono::steady_clock::now() < wait_until && !stop.load()) {
      pub.poll();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (pub.subscriptions() == 0) spdlog::warn("no subscriber yet; replaying anyway");

    const bool keys = !no_keys && ::isatty(STDIN_FILENO) == 1;
    tools::TerminalControl control(stop, keys, [&] { pub.poll(); }, paused);
    if (keys) spdlog::info("keys: space = pause/resume, n = step, q = quit");

    auto last_progress = std::chrono::steady_clock::now();
    std::uint64_t count = 0;
    const recording::PlayerStats result = player.run(control, [&](const recording::Message& m, const recording::Channel& c) {
      const bool gate = acks && after.count(c.topic) > 0 && (++gated % ack_every) == 0;
      if (gate) acks->poll(std::chrono::microseconds(0));  // acks of earlier messages do not count
      const std::uint64_t acks_before = acks_received;
      pub.publishRaw(c.topic, m.data);
      ++count;
      if (gate) {
        const auto h = tools::parseHeader(m.data);
        const bool by_stamp = ack_rule == "stamp";
        if (h || !by_stamp) {
          ++waited;
          const std::int64_t want = h ? h->stamp_ns : 0;
          const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(ack_timeout);
          while ((by_stamp ? acked_stamp < want : acks_received == acks_before) && !stop.load()) {
            acks->poll(std::chrono::milliseconds(5));
            pub.poll();
            if (std::chrono::steady_clock::now() > deadline) {
              ++ack_timeouts;
              spdlog::warn("lockstep: no ack on '{}' for message {} within {} s; going on", ack_topic, count, ack_timeout);
              break;
            }
          }
        }
      }
      const auto now = std::chrono::steady_clock::now();
      if (progress > 0 && std::chrono::duration<double>(now - last_progress).count() >= progress) {
        spdlog::info("{:.1f} s of {:.1f} s, {} messages published", (m.log_time - t0) / 1e9,
                     (stats.message_end_time - t0) / 1e9, count);
        last_progress = now;
      }
    });
    // the transport closes sockets without linger: give queued messages time to leave
    const auto linger_end = std::chrono::steady_clock::now() + std::chrono::duration<double>(result.quit ? 0.0 : linger);
    while (std::chrono::steady_clock::now() < linger_end && !stop.load()) {
      pub.poll();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    spdlog::info("done: {} messages published, {} pass(es){}{}", result.published, result.passes,
                 result.quit ? ", stopped by the user" : "",
                 acks ? fmt::format(", lockstep: {} waits, {} timeouts", waited, ack_timeouts) : std::string());
    return 0;
  });
}
