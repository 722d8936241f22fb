#pragma once
/// \file subscriber.hpp
/// \brief Typed subscriber: one ZeroMQ SUB socket connected to any number of publishers' endpoints.
///
/// poll(timeout) waits up to `timeout` for traffic, then drains everything already queued (bounded),
/// and calls the handlers:
/// - kQueue topics: each valid message, in arrival order;
/// - kLatest topics: only the newest valid message of the drain from each source (Header.source; the
///   others count as superseded), so a subscriber slower than its publishers never works through a
///   backlog of stale states.
/// Every frame is checked before its handler sees it: 2 parts, a subscribed topic, a payload that parses,
/// a Header with schema_version == kSchemaVersion and a source, then the topic's validator if any.
/// Anything else is counted (TopicCounters::malformed, unknownTopics()) and logged at most once per
/// second per topic and reason — it never throws out of poll() and never reaches a handler.
/// Handlers that throw are caught, logged (rate-limited) and counted in handlerErrors().
/// CURVE (optional, `curve`): the subscriber is a CURVE client (its key pair, the publishers' public
/// key; security.hpp); a publisher with another key, or one not listing this key, sends it nothing.
/// Not thread-safe.
#include <chrono>
#include <optional>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include <google/protobuf/message.h>
#include <zmq.hpp>

#include "mannequin/transport/counters.hpp"
#include "mannequin/transport/log_limiter.hpp"
#include "mannequin/transport/security.hpp"
#include "mannequin/transport/topics.hpp"

namespace mannequin::transport {

struct SubscriberOptions {
  std::string name;                   ///< for logs ("sim", "launcher")
  std::vector<std::string> endpoints; ///< publishers to connect to (may be empty; see connect())
  int receive_hwm = 1000;             ///< messages queued before ZeroMQ drops (seen as sequence gaps)
  int max_drain = 10000;              ///< messages read per poll() at most (keeps a loop responsive)
  std::optional<CurveClientOptions> curve = std::nullopt;  ///< CURVE client keys (unset: plaintext)
};

/// Arrival information handed to handlers that want it.
struct Received {
  std::string_view topic;
  std::int64_t receive_time_ns = 0;  ///< wall clock when poll() read it
};

class Subscriber {
 public:
  /// Connects to every endpoint. \throws std::runtime_error naming an endpoint ZeroMQ rejects,
  /// std::invalid_argument for a CURVE key that is not Z85.
  Subscriber(zmq::context_t& context, SubscriberOptions options);

  /// Connects to one more publisher.
  void connect(const std::string& endpoint);

  /// Subscribes to a typed topic. `validate` (optional) returns "" for a good message or the reason
  /// it is rejected (counted as malformed).
  template <class M>
  void subscribe(const Topic<M>& topic, std::type_identity_t<std::function<void(const M&, const Received&)>> handler,
                 std::type_identity_t<std::function<std::string(const M&)>> validate = {}) {
    auto entry = std::make_unique<Entry>();
    entry->delivery = topic.delivery;
    entry->prototype = std::make_unique<M>();
    entry->handler = [handler](const google::protobuf::Message& m, const Received& r) {
      handler(static_cast<const M&>(m), r);
    };
    if (validate)
      entry->validate = [validate](const google::protobuf::Message& m) { return validate(static_cast<const M&>(m)); };
    add(topic.name, std::move(entry));
  }
  /// Same, with a handler that ignores the arrival information.
  template <class M>
  void subscribe(const Topic<M>& topic, std::type_identity_t<std::function<void(const M&)>> handler,
                 std::type_identity_t<std::function<std::string(const M&)>> validate = {}) {
    subscribe<M>(topic, std::function<void(const M&, const Received&)>([handler](const M& m, const Received&) { handler(m); }),
                 std::move(validate));
  }

  /// Raw subscription (recording): every frame whose topic starts with `prefix` ("" = all) is handed
  /// over as bytes, unparsed, in arrival order. Malformed framing (not 2 parts) is still counted.
  using RawHandler = std::function<void(std::string_view topic, std::string_view payload, const Received&)>;
  void subscribeRaw(const std::string& prefix, RawHandler handler);

  /// Waits up to `timeout` for the first frame (0 = do not wait), then drains what is queued and
  /// dispatches. Returns the number of messages handed to handlers. A signal interrupting the wait
  /// ends it early (EINTR is not an error).
  int poll(std::chrono::microseconds timeout);

  /// Counters of every typed topic subscribed.
  std::vector<TopicCounters> counters() const;
  /// Counters of one topic (zeros if not subscribed).
  TopicCounters counters(std::string_view topic) const;
  std::uint64_t unknownTopics() const { return unknown_topics_; }
  std::uint64_t badFraming() const { return bad_framing_; }
  std::uint64_t handlerErrors() const { return handler_errors_; }
  const std::vector<std::string>& endpoints() const { return endpoints_; }

 private:
  struct Entry {
    Delivery delivery = Delivery::kQueue;
    std::unique_ptr<google::protobuf::Message> prototype;  // parse buffer
    struct Pending {
      std::unique_ptr<google::protobuf::Message> message;  // kLatest: newest valid message of this drain
      bool has = false;
      Received received;
    };
    std::unordered_map<std::string, Pending> latest;  // per source
    std::function<void(const google::protobuf::Message&, const Received&)> handler;
    std::function<std::string(const google::protobuf::Message&)> validate;
    TopicCounters counters;
    std::unordered_map<std::string, std::uint64_t> last_sequence;  // per source
  };
  int pollImpl(std::chrono::microseconds timeout);
  void add(std::string_view topic, std::unique_ptr<Entry> entry);
  bool accept(Entry& entry, std::string_view topic, const zmq::message_t& payload);
  void dispatch(Entry& entry, const google::protobuf::Message& m, const Received& r);
  void malformed(Entry& entry, std::string_view topic, const std::string& reason, std::size_t size);

  SubscriberOptions options_;
  zmq::socket_t socket_;
  std::vector<std::string> endpoints_;
  std::unordered_map<std::string, std::unique_ptr<Entry>> entries_;
  std::vector<std::pair<std::string, RawHandler>> raw_;
  std::string topic_buffer_;
  std::uint64_t unknown_topics_ = 0, bad_framing_ = 0, handler_errors_ = 0;
  int delivered_in_poll_ = 0;
  LogLimiter log_;
};

}  // namespace mannequin::transport
