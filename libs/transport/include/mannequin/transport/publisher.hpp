#pragma once
/// \file publisher.hpp
/// \brief Typed publisher: one ZeroMQ XPUB socket bound to one or more endpoints, sending multipart
/// [topic][payload] frames.
///
/// - Endpoints: "tcp://HOST:PORT" (PORT 0 or * = ephemeral, see boundEndpoints()) or "ipc://PATH".
/// - Never blocks: past the send high-water mark of a slow subscriber, ZeroMQ drops for that subscriber
///   only (counted downstream as sequence gaps), the publisher goes on.
/// - Fills the Header of every message: schema_version, sequence (per topic, from 1), source, and
///   send_time_ns (wall clock; 0 in deterministic mode). The caller sets header.stamp_ns.
/// - Late joiners: the last payload of every kLatest topic is kept; when a subscription for it arrives
///   (the XPUB socket reports each one, verbose), the last payload is sent again at once. Subscribers
///   drop the repeat as a duplicate if they already had it. Subscriptions are read by poll() and at
///   every publish(); a service calls poll() in its loop.
/// - CURVE (optional, `curve`): the publisher is a CURVE server admitting only the listed client keys
///   (security.hpp); unset, nothing changes (plaintext, anyone may subscribe).
/// Not thread-safe (one thread owns a publisher, like any ZeroMQ socket).
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <zmq.hpp>

#include "mannequin/transport/counters.hpp"
#include "mannequin/transport/security.hpp"
#include "mannequin/transport/topics.hpp"

namespace mannequin::transport {

/// Stamps a message's Header as everything the project sends or records does (the Publisher live, the
/// offline run's MCAP writer): schema_version = kSchemaVersion, `sequence`, `source`, `send_time_ns`
/// (0 for deterministic output). Keeps stamp_ns (the caller's capture or simulation time).
void stampHeader(v1::Header& header, std::uint64_t sequence, const std::string& source, std::int64_t send_time_ns);

struct PublisherOptions {
  std::string source;                   ///< Header.source of everything published (service name)
  std::vector<std::string> endpoints;   ///< where to bind (at least one)
  int send_hwm = 1000;                  ///< messages queued per subscriber before dropping
  bool deterministic = false;           ///< Header.send_time_ns = 0 (byte-identical output in replay)
  std::optional<CurveServerOptions> curve = std::nullopt;  ///< CURVE server with a ZAP key check (unset: plaintext)
  /// On close, how long (ms) messages still queued may be sent: 0 drops them (services: a restart must not
  /// wait); a one-shot tool that publishes then exits sets it (mannequin-trigger).
  int linger_ms = 0;
};

namespace detail {
struct ZapDomain;
}

class Publisher {
 public:
  /// Binds every endpoint. \throws std::runtime_error naming the endpoint that cannot be bound.
  /// \throws std::invalid_argument for a CURVE key that is not Z85.
  Publisher(zmq::context_t& context, PublisherOptions options);

  /// Fills msg.header (schema version, sequence, source, send time; keeps stamp_ns) and sends it.
  template <class M>
  void publish(const Topic<M>& topic, M& message) {
    fillHeader(topic.name, *message.mutable_header());
    publishRaw(topic.name, message.SerializeAsString());
  }

  /// Sends a payload as is (replay of recorded bytes). Kept as last value when `topic` is a kLatest
  /// topic of topics::kAll.
  void publishRaw(std::string_view topic, std::string_view payload);

  /// Reads pending subscriptions and re-sends the last value of the kLatest topics they match.
  /// Returns the number of subscription messages read.
  int poll();

  /// Endpoints actually bound (tcp port resolved), in the order given.
  const std::vector<std::string>& boundEndpoints() const { return bound_; }
  const std::string& source() const { return options_.source; }
  /// Counters per topic published (delivered = sent, resent = late-joiner resends).
  std::vector<TopicCounters> counters() const;
  /// Number of subscriptions seen (subscribe messages, including repeats).
  std::uint64_t subscriptions() const { return subscriptions_; }
  /// Whether a subscription seen by poll() matches `topic` (its prefix): a subscriber would receive it.
  bool subscribed(std::string_view topic) const;
  /// CURVE: client handshakes refused (key not listed) and admitted by the ZAP handler (0 without CURVE).
  std::uint64_t curveRefusals() const;
  std::uint64_t curveAdmissions() const;
  bool curve() const { return zap_ != nullptr; }

  /// Fills a header as publish() does, without sending (for tests and tools).
  void fillHeader(std::string_view topic, v1::Header& header);

 private:
  PublisherOptions options_;
  std::shared_ptr<detail::ZapDomain> zap_;  // before socket_: outlives it (its ZAP handler too)
  zmq::socket_t socket_;
  std::vector<std::string> bound_;
  struct TopicState {
    std::uint64_t sequence = 0;
    TopicCounters counters;
    bool latched = false;
    std::string last;  // last payload of a kLatest topic
    bool has_last = false;
  };
  std::unordered_map<std::string, TopicState> topics_;
  std::uint64_t subscriptions_ = 0;
  std::vector<std::string> prefixes_;  // subscription prefixes seen (subscribed())

  TopicState& state(std::string_view topic);
  void send(std::string_view topic, std::string_view payload);
};

/// "tcp://HOST:0" → "tcp://HOST:*" (ZeroMQ's ephemeral port); others unchanged. \throws
/// std::invalid_argument for an endpoint that is not tcp://HOST:PORT, ipc://PATH or inproc://NAME.
std::string normalizeEndpoint(const std::string& endpoint);

}  // namespace mannequin::transport
