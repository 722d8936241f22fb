#include "mannequin/transport/subscriber.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <stdexcept>

#include "mannequin/transport/clock.hpp"

namespace mannequin::transport {

namespace {
// Every mannequin.v1 top-level message has its Header as field 1.
const v1::Header* headerOf(const google::protobuf::Message& m) {
  const auto* field = m.GetDescriptor()->FindFieldByNumber(1);
  if (field == nullptr || field->message_type() != v1::Header::descriptor()) return nullptr;
  if (!m.GetReflection()->HasField(m, field)) return nullptr;
  return static_cast<const v1::Header*>(&m.GetReflection()->GetMessage(m, field));
}
}  // namespace

Subscriber::Subscriber(zmq::context_t& context, SubscriberOptions options)
    : options_(std::move(options)), socket_(context, zmq::socket_type::sub) {
  socket_.set(zmq::sockopt::rcvhwm, options_.receive_hwm);
  socket_.set(zmq::sockopt::linger, 0);
  if (options_.curve) {
    const CurveClientOptions& c = *options_.curve;
    const std::string who = "subscriber '" + options_.name + "': CURVE ";
    if (!isZ85Key(c.public_key)) throw std::invalid_argument(who + "public key is not a Z85 key (40 characters)");
    if (!isZ85Key(c.secret_key)) throw std::invalid_argument(who + "secret key is not a Z85 key (40 characters)");
    if (!c.server_public_key.empty() && !isZ85Key(c.server_public_key))
      throw std::invalid_argument(who + "server public key is not a Z85 key (40 characters)");
    for (const auto& [endpoint, key] : c.server_keys)
      if (!isZ85Key(key)) throw std::invalid_argument(who + "server public key of '" + endpoint + "' is not a Z85 key (40 characters)");
    if (!c.server_public_key.empty()) socket_.set(zmq::sockopt::curve_serverkey, c.server_public_key);
    socket_.set(zmq::sockopt::curve_publickey, c.public_key);
    socket_.set(zmq::sockopt::curve_secretkey, c.secret_key);
  }
  const auto eps = options_.endpoints;
  for (const std::string& ep : eps) connect(ep);
}

void Subscriber::connect(const std::string& endpoint) {
  std::string ep = endpoint;
  if (options_.curve) {
    // the server key is taken per connection (libzmq copies the options into each session at connect)
    const CurveClientOptions& c = *options_.curve;
    const auto key = c.server_keys.find(endpoint);
    if (key == c.server_keys.end() && c.server_public_key.empty())
      throw std::invalid_argument("subscriber '" + options_.name + "': CURVE: no server public key for '" + endpoint + "'");
    socket_.set(zmq::sockopt::curve_serverkey, key != c.server_keys.end() ? key->second : c.server_public_key);
  }
  try {
    socket_.connect(ep);
  } catch (const zmq::error_t& e) {
    throw std::runtime_error("subscriber '" + options_.name + "': cannot connect to '" + endpoint + "': " + e.what());
  }
  endpoints_.push_back(ep);
}

void Subscriber::add(std::string_view topic, std::unique_ptr<Entry> entry) {
  entry->counters.topic = std::string(topic);
  const bool known = entries_.count(std::string(topic)) > 0;
  entries_[std::string(topic)] = std::move(entry);
  if (!known) socket_.set(zmq::sockopt::subscribe, topic);
}

void Subscriber::subscribeRaw(const std::string& prefix, RawHandler handler) {
  raw_.emplace_back(prefix, std::move(handler));
  socket_.set(zmq::sockopt::subscribe, prefix);
}

void Subscriber::malformed(Entry& entry, std::string_view topic, const std::string& reason, std::size_t size) {
  ++entry.counters.malformed;
  log_.warn(fmt::format("{}|{}|{}", topic, reason.substr(0, reason.find(':')), options_.name),
            fmt::format("{}: dropped a malformed message on '{}' ({} bytes): {}", options_.name, topic, size, reason));
}

bool Subscriber::accept(Entry& entry, std::string_view topic, const zmq::message_t& payload) {
  ++entry.counters.received;
  google::protobuf::Message& m = *entry.prototype;
  m.Clear();
  if (!m.ParseFromArray(payload.data(), static_cast<int>(payload.size()))) {
    malformed(entry, topic, "payload does not parse as " + m.GetTypeName(), payload.size());
    return false;
  }
  const v1::Header* h = headerOf(m);
  if (h == nullptr) {
    malformed(entry, topic, "no header", payload.size());
    return false;
  }
  if (h->schema_version() != kSchemaVersion) {
    malformed(entry, topic, fmt::format("schema version {} (expected {})", h->schema_version(), kSchemaVersion), payload.size());
    return false;
  }
  if (h->source().empty()) {
    malformed(entry, topic, "header without source", payload.size());
    return false;
  }
  if (h->sequence() == 0) {
    malformed(entry, topic, "header sequence 0", payload.size());
    return false;
  }
  if (entry.validate) {
    std::string why;
    try {
      why = entry.validate(m);
    } catch (const std::exception& e) {
      why = std::string("validator threw: ") + e.what();
    }
    if (!why.empty()) {
      malformed(entry, topic, why, payload.size());
      return false;
    }
  }
  std::uint64_t& last = entry.last_sequence[h->source()];
  const std::uint64_t seq = h->sequence();
  if (seq == last) {  // a late-joiner resend of a value we already have
    ++entry.counters.duplicates;
    return false;
  }
  if (last != 0 && seq > last + 1) entry.counters.dropped += seq - last - 1;
  if (last != 0 && seq < last)
    spdlog::info("{}: '{}' from '{}' restarted its sequence ({} after {})", options_.name, topic, h->source(), seq, last);
  last = seq;
  return true;
}

void Subscriber::dispatch(Entry& entry, const google::protobuf::Message& m, const Received& r) {
  ++entry.counters.delivered;
  ++delivered_in_poll_;
  try {
    entry.handler(m, r);
  } catch (const std::exception& e) {
    ++handler_errors_;
    log_.warn(fmt::format("handler|{}", r.topic),
              fmt::format("{}: handler of '{}' failed: {}", options_.name, r.topic, e.what()));
  }
}

int Subscriber::poll(std::chrono::microseconds timeout) {
  try {
    return pollImpl(timeout);
  } catch (const zmq::error_t& e) {
    if (e.num() != EINTR) throw;
    return delivered_in_poll_;  // a signal arrived (the caller checks its stop flag)
  }
}

int Subscriber::pollImpl(std::chrono::microseconds timeout) {
  delivered_in_poll_ = 0;
  if (timeout.count() > 0) {
    // wait on the socket's file descriptor with a nanosecond timeout (zmq_poll has millisecond
    // resolution): ZMQ_FD only signals that ZMQ_EVENTS may have changed, so re-check it after each wake
    const int fd = socket_.get(zmq::sockopt::fd);
    const std::int64_t until = steadyNs() + timeout.count() * 1000;
    while ((socket_.get(zmq::sockopt::events) & ZMQ_POLLIN) == 0) {
      const std::int64_t left = until - steadyNs();
      if (left <= 0) break;
      pollfd p{fd, POLLIN, 0};
      const timespec ts{static_cast<time_t>(left / 1000000000), static_cast<long>(left % 1000000000)};
      ppoll(&p, 1, &ts, nullptr);
    }
  }
  zmq::message_t topic_msg, payload;
  int read = 0;
  while (read < options_.max_drain) {
    if (!socket_.recv(topic_msg, zmq::recv_flags::dontwait)) break;
    ++read;
    const std::int64_t now = wallNs();
    if (!topic_msg.more()) {
      ++bad_framing_;
      log_.warn("framing", fmt::format("{}: dropped a single-part message ({} bytes)", options_.name, topic_msg.size()));
      continue;
    }
    if (!socket_.recv(payload, zmq::recv_flags::dontwait)) {
      ++bad_framing_;
      continue;
    }
    int extra = 0;
    while (payload.more()) {  // drain and reject any further parts
      zmq::message_t rest;
      if (!socket_.recv(rest, zmq::recv_flags::dontwait)) break;
      ++extra;
      if (!rest.more()) break;
    }
    topic_buffer_.assign(static_cast<const char*>(topic_msg.data()), topic_msg.size());
    const Received received{topic_buffer_, now};
    if (extra > 0) {
      ++bad_framing_;
      log_.warn("framing", fmt::format("{}: dropped a {}-part message on '{}'", options_.name, 2 + extra, topic_buffer_));
      continue;
    }
    bool handled = false;
    for (auto& [prefix, handler] : raw_) {
      if (topic_buffer_.compare(0, prefix.size(), prefix) != 0) continue;
      handled = true;
      ++delivered_in_poll_;
      try {
        handler(topic_buffer_, std::string_view(static_cast<const char*>(payload.data()), payload.size()), received);
      } catch (const std::exception& e) {
        ++handler_errors_;
        log_.warn("raw-handler", fmt::format("{}: raw handler failed on '{}': {}", options_.name, topic_buffer_, e.what()));
      }
    }
    auto it = entries_.find(topic_buffer_);
    if (it == entries_.end()) {
      if (!handled) {
        ++unknown_topics_;
        log_.warn("unknown-topic", fmt::format("{}: dropped a message on unknown topic '{}' ({} bytes)", options_.name,
                                               topic_buffer_.substr(0, 64), payload.size()));
      }
      continue;
    }
    Entry& entry = *it->second;
    if (!accept(entry, topic_buffer_, payload)) continue;
    if (entry.delivery == Delivery::kQueue) {
      dispatch(entry, *entry.prototype, received);
    } else {
      Entry::Pending& pending = entry.latest[headerOf(*entry.prototype)->source()];
      if (pending.has) ++entry.counters.superseded;
      if (!pending.message) pending.message.reset(entry.prototype->New());
      pending.message.swap(entry.prototype);
      pending.has = true;
      pending.received = Received{it->first, now};
    }
  }
  for (auto& [name, entry] : entries_)
    for (auto& [source, pending] : entry->latest) {
      if (!pending.has) continue;
      pending.has = false;
      dispatch(*entry, *pending.message, pending.received);
    }
  return delivered_in_poll_;
}

std::vector<TopicCounters> Subscriber::counters() const {
  std::vector<TopicCounters> out;
  for (const auto& [name, e] : entries_) out.push_back(e->counters);
  return out;
}

TopicCounters Subscriber::counters(std::string_view topic) const {
  auto it = entries_.find(std::string(topic));
  if (it == entries_.end()) return TopicCounters{std::string(topic)};
  return it->second->counters;
}

}  // namespace mannequin::transport
