#include "mannequin/transport/publisher.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cerrno>
#include <stdexcept>

#include "mannequin/transport/clock.hpp"
#include "zap.hpp"

namespace mannequin::transport {

std::string normalizeEndpoint(const std::string& endpoint) {
  auto starts = [&](std::string_view p) { return endpoint.rfind(p, 0) == 0; };
  if (starts("ipc://") || starts("inproc://")) {
    const auto rest = endpoint.substr(endpoint.find("://") + 3);
    if (rest.empty()) throw std::invalid_argument("endpoint '" + endpoint + "': empty path");
    return endpoint;
  }
  if (starts("tcp://")) {
    const auto colon = endpoint.rfind(':');
    if (colon <= 5 || colon + 1 >= endpoint.size())
      throw std::invalid_argument("endpoint '" + endpoint + "': expected tcp://HOST:PORT");
    const std::string port = endpoint.substr(colon + 1);
    if (port == "0") return endpoint.substr(0, colon + 1) + "*";
    if (port == "*") return endpoint;
    for (char c : port)
      if (c < '0' || c > '9') throw std::invalid_argument("endpoint '" + endpoint + "': port '" + port + "' is not a number");
    if (std::stol(port) > 65535) throw std::invalid_argument("endpoint '" + endpoint + "': port out of range");
    return endpoint;
  }
  throw std::invalid_argument("endpoint '" + endpoint + "': expected tcp://HOST:PORT, ipc://PATH or inproc://NAME");
}

Publisher::Publisher(zmq::context_t& context, PublisherOptions options)
    : options_(std::move(options)), socket_(context, zmq::socket_type::xpub) {
  if (options_.endpoints.empty()) throw std::invalid_argument("publisher '" + options_.source + "': no endpoint to bind");
  socket_.set(zmq::sockopt::sndhwm, options_.send_hwm);
  if (options_.linger_ms < 0) throw std::invalid_argument("publisher '" + options_.source + "': linger_ms must be >= 0");
  socket_.set(zmq::sockopt::linger, options_.linger_ms);
  socket_.set(zmq::sockopt::xpub_verbose, 1);
  if (options_.curve) {
    const CurveServerOptions& c = *options_.curve;
    const std::string who = "publisher '" + options_.source + "': ";
    if (!isZ85Key(c.secret_key)) throw std::invalid_argument(who + "CURVE secret key is not a Z85 key (40 characters)");
    for (const std::string& k : c.authorized_keys)
      if (!isZ85Key(k)) throw std::invalid_argument(who + "authorized key '" + k + "' is not a Z85 key (40 characters)");
    auto handler = detail::ZapHandler::of(context);  // bound before this socket binds: no handshake goes unchecked
    zap_ = std::make_shared<detail::ZapDomain>(handler, handler->addDomain(options_.source, c.authorized_keys));
    socket_.set(zmq::sockopt::zap_domain, zap_->name);
    socket_.set(zmq::sockopt::curve_server, 1);
    socket_.set(zmq::sockopt::curve_secretkey, c.secret_key);
  }
  for (const std::string& ep : options_.endpoints) {
    const std::string normalized = normalizeEndpoint(ep);
    try {
      socket_.bind(normalized);
    } catch (const zmq::error_t& e) {
      throw std::runtime_error("publisher '" + options_.source + "': cannot bind '" + ep + "': " + e.what());
    }
    bound_.push_back(socket_.get(zmq::sockopt::last_endpoint));
  }
}

std::uint64_t Publisher::curveRefusals() const { return zap_ ? zap_->handler->refusals(zap_->name) : 0; }
std::uint64_t Publisher::curveAdmissions() const { return zap_ ? zap_->handler->accepted(zap_->name) : 0; }

Publisher::TopicState& Publisher::state(std::string_view topic) {
  auto it = topics_.find(std::string(topic));
  if (it != topics_.end()) return it->second;
  TopicState s;
  s.counters.topic = std::string(topic);
  const topics::TopicInfo* info = topics::find(topic);
  s.latched = info != nullptr && info->delivery == Delivery::kLatest;
  return topics_.emplace(std::string(topic), std::move(s)).first->second;
}

void stampHeader(v1::Header& header, std::uint64_t sequence, const std::string& source, std::int64_t send_time_ns) {
  header.set_schema_version(kSchemaVersion);
  header.set_sequence(sequence);
  header.set_source(source);
  header.set_send_time_ns(send_time_ns);
}

void Publisher::fillHeader(std::string_view topic, v1::Header& header) {
  TopicState& s = state(topic);
  stampHeader(header, ++s.sequence, options_.source, options_.deterministic ? 0 : wallNs());
}

void Publisher::send(std::string_view topic, std::string_view payload) {
  (void)socket_.send(zmq::buffer(topic), zmq::send_flags::sndmore | zmq::send_flags::dontwait);
  (void)socket_.send(zmq::buffer(payload), zmq::send_flags::dontwait);
}

void Publisher::publishRaw(std::string_view topic, std::string_view payload) {
  poll();
  TopicState& s = state(topic);
  send(topic, payload);
  ++s.counters.delivered;
  if (s.latched) {
    s.last.assign(payload.data(), payload.size());
    s.has_last = true;
  }
}

int Publisher::poll() {
  int n = 0;
  zmq::message_t msg;
  for (;;) {
    try {
      if (!socket_.recv(msg, zmq::recv_flags::dontwait)) break;
    } catch (const zmq::error_t& e) {
      if (e.num() == EINTR) break;  // a signal: read the rest next time
      throw;
    }
    ++n;
    const auto* data = static_cast<const char*>(msg.data());
    if (msg.size() < 1 || data[0] != 1) continue;  // unsubscribe (0) or garbage
    ++subscriptions_;
    const std::string_view prefix(data + 1, msg.size() - 1);
    if (std::find(prefixes_.begin(), prefixes_.end(), prefix) == prefixes_.end()) prefixes_.emplace_back(prefix);
    for (auto& [name, s] : topics_) {
      if (!s.latched || !s.has_last || name.compare(0, prefix.size(), prefix) != 0) continue;
      send(name, s.last);
      ++s.counters.resent;
    }
  }
  return n;
}

bool Publisher::subscribed(std::string_view topic) const {
  for (const std::string& p : prefixes_)
    if (topic.substr(0, p.size()) == p) return true;
  return false;
}

std::vector<TopicCounters> Publisher::counters() const {
  std::vector<TopicCounters> out;
  for (const auto& [name, s] : topics_) out.push_back(s.counters);
  return out;
}

}  // namespace mannequin::transport
