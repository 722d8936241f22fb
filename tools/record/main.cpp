// mannequin-record: subscribes to the cluster's topics (endpoints from the deployment file) and
// writes every message, as received, into an MCAP file (docs/recording.md).
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <map>
#include <optional>
#include <set>

#include "cluster_io.hpp"
#include "mannequin/deploy/deployment.hpp"
#include "mannequin/core/main.hpp"
#include "mannequin/proto/schema.hpp"
#include "mannequin/recording/mcap_writer.hpp"
#include "mannequin/transport/clock.hpp"
#include "mannequin/transport/subscriber.hpp"
#include "mannequin/transport/topics.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  CLI::App app{"mannequin-record: records the cluster's topics into an MCAP file (protobuf schemas, zstd\n"
               "chunks, index and summary). Stops on Ctrl-C/SIGTERM or after --duration; a killed recorder\n"
               "loses at most the last --flush-interval of messages."};
  std::string deployment, run_dir, out, topics_arg, compression = "zstd", log_level = "info", client_key;
  std::vector<std::string> connect;
  double duration = 0, flush_interval = 1.0, progress = 5.0;
  std::uint64_t chunk_size = 1 << 20;
  int zstd_level = 3;
  app.add_option("deployment", deployment, "deployment file: the recorder connects to the publish endpoint of every service")
      ->check(CLI::ExistingFile);
  app.add_option("--run-dir", run_dir, "${RUN_DIR} of the deployment's endpoints (default: as mannequin-launch)");
  app.add_option("--out,-o", out, "MCAP file to write")->required();
  app.add_option("--topics", topics_arg, "comma-separated topics to record (default: every topic)");
  app.add_option("--duration", duration, "stop after this many seconds (0 = until Ctrl-C)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--connect", connect, "publisher endpoint to connect to (repeatable; instead of or besides the deployment file)");
  app.add_option("--client-key", client_key,
                 "deployment with security (CURVE): this recorder's secret key file, a key the deployment admits "
                 "(security.clients: KEY_DIR/NAME.key_secret)")
      ->check(CLI::ExistingFile);
  app.add_option("--compression", compression, "chunk compression")->check(CLI::IsMember({"zstd", "none"}))->capture_default_str();
  app.add_option("--zstd-level", zstd_level, "zstd level")->check(CLI::Range(1, 19))->capture_default_str();
  app.add_option("--chunk-size", chunk_size, "bytes of messages per chunk before it is written")
      ->check(CLI::Range(std::uint64_t{1024}, std::uint64_t{1} << 30))->capture_default_str();
  app.add_option("--flush-interval", flush_interval, "write the open chunk at least this often, s (bounds the loss on a kill)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--progress", progress, "log progress every this many seconds (0 = never)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")->capture_default_str()->check(core::logLevelCheck());
  return core::runMain(app, argc, argv, [&] {
    if (deployment.empty() && connect.empty()) throw CLI::ValidationError("give a deployment file or --connect ENDPOINT");
    core::setupLogging(log_level);
    spdlog::set_pattern("[%H:%M:%S.%e] [record] %^%l%$ %v");
    const auto& stop = core::installStopSignals();
    std::vector<std::string> endpoints = connect;
    std::optional<transport::CurveClientOptions> curve;
    if (!deployment.empty()) {
      for (const std::string& e : tools::publishEndpoints(deployment, run_dir)) endpoints.push_back(e);
      const deploy::Deployment d = deploy::loadDeployment(deployment, run_dir);
      if (d.security && client_key.empty())
        throw CLI::ValidationError(deployment + " uses CURVE (security): give --client-key NAME.key_secret of one of its clients");
      if (d.security) curve = d.clientKeys(client_key);  // each service's public key by its address
    }
    if (!client_key.empty() && !curve) throw CLI::ValidationError("--client-key needs a deployment file with security");
    const std::vector<std::string> wanted = tools::splitList(topics_arg);
    const std::set<std::string> wanted_set(wanted.begin(), wanted.end());
    for (const std::string& t : wanted) {
      if (transport::topics::find(t) == nullptr) {
        spdlog::warn("topic '{}' is not a mannequin.v1 topic: recorded without a schema if it appears", t);
      }
    }

    recording::McapWriterOptions wo;
    wo.compression = compression == "zstd" ? recording::Compression::kZstd : recording::Compression::kNone;
    wo.zstd_level = zstd_level;
    wo.chunk_size = chunk_size;
    wo.library = "mannequin-record";
    recording::McapWriter writer(out, wo);

    zmq::context_t context;
    transport::Subscriber sub(context, {"record", endpoints, 1000, 10000, curve});
    std::map<std::string, std::uint16_t, std::less<>> channels;
    std::map<std::string, std::uint16_t> schemas;
    std::uint64_t bytes = 0, unparsed = 0;
    std::string error;  // a write error stops the recording
    auto channelFor = [&](std::string_view topic) -> std::uint16_t {
      auto it = channels.find(topic);
      if (it != channels.end()) return it->second;
      const auto* info = transport::topics::find(topic);
      std::uint16_t schema = 0;
      if (info != nullptr) {
        const std::string type(info->type);
        auto s = schemas.find(type);
        if (s == schemas.end()) {
          s = schemas.emplace(type, writer.addSchema(type, "protobuf", proto::fileDescriptorSet(type))).first;
        }
        schema = s->second;
      }
      const std::uint16_t id = writer.addChannel(std::string(topic), schema, "protobuf");
      channels.emplace(std::string(topic), id);
      spdlog::info("recording '{}' ({})", topic, info ? std::string(info->type) : std::string("no schema"));
      return id;
    };
    sub.subscribeRaw("", [&](std::string_view topic, std::string_view payload, const transport::Received& r) {
      if (!error.empty()) return;
      if (!wanted_set.empty() && wanted_set.count(std::string(topic)) == 0) return;
      try {
        const std::uint16_t ch = channelFor(topic);
        const auto log_time = static_cast<recording::Timestamp>(r.receive_time_ns > 0 ? r.receive_time_ns : transport::wallNs());
        recording::Timestamp publish_time = log_time;
        std::uint32_t sequence = 0;
        if (const auto h = tools::parseHeader(payload)) {
          sequence = static_cast<std::uint32_t>(h->sequence);
          if (h->send_time_ns > 0) publish_time = static_cast<recording::Timestamp>(h->send_time_ns);
        } else {
          ++unparsed;
        }
        writer.write(ch, sequence, log_time, publish_time, payload);
        bytes += payload.size();
      } catch (const std::exception& e) {
        error = e.what();
      }
    });
    spdlog::info("connected to {} endpoint(s); writing {} ({} chunks)", endpoints.size(), out, compression);
    for (const std::string& e : endpoints) spdlog::debug("  {}", e);

    const auto t0 = std::chrono::steady_clock::now();
    auto last_flush = t0, last_progress = t0;
    while (!stop.load() && error.empty()) {
      sub.poll(std::chrono::milliseconds(50));
      const auto now = std::chrono::steady_clock::now();
      const double elapsed = std::chrono::duration<double>(now - t0).count();
      if (std::chrono::duration<double>(now - last_flush).count() >= flush_interval) {
        writer.flushChunk();
        last_flush = now;
      }
      if (progress > 0 && std::chrono::duration<double>(now - last_progress).count() >= progress) {
        spdlog::info("{:.0f} s: {} messages, {:.2f} MB of payload, {:.2f} MB written, {} chunks", elapsed,
                     writer.messageCount(), bytes / 1e6, writer.bytesWritten() / 1e6, writer.chunkCount());
        last_progress = now;
      }
      if (duration > 0 && elapsed >= duration) break;
    }
    writer.close();
    if (!error.empty()) {
      spdlog::error("stopped: {}", error);
      return 1;
    }
    if (unparsed > 0) spdlog::warn("{} messages had no mannequin.v1 Header (recorded as received)", unparsed);
    spdlog::info("done: {} messages on {} topics, {:.2f} MB in {}", writer.messageCount(), channels.size(),
                 writer.bytesWritten() / 1e6, out);
    return 0;
  });
}
