#pragma once
// The ZAP handler (RFC 27) of one ZeroMQ context: a thread with a REP socket bound to
// inproc://zeromq.zap.01 answering each CURVE handshake with 200 (key listed for the request's domain)
// or 400 (anything else, logged and counted). Shared by the publishers of the context (one domain each).
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include <zmq.hpp>

#include "mannequin/transport/log_limiter.hpp"

namespace mannequin::transport::detail {

class ZapHandler {
 public:
  /// The handler of `context`, started on first use; it stops when its last user lets it go.
  static std::shared_ptr<ZapHandler> of(zmq::context_t& context);
  ~ZapHandler();
  ZapHandler(const ZapHandler&) = delete;
  ZapHandler& operator=(const ZapHandler&) = delete;

  /// A new domain (unique in the context) admitting `keys` (Z85); `label` names it in logs.
  std::string addDomain(const std::string& label, const std::vector<std::string>& keys);
  void removeDomain(const std::string& domain);
  std::uint64_t refusals(const std::string& domain) const;
  std::uint64_t accepted(const std::string& domain) const;

 private:
  explicit ZapHandler(zmq::context_t& context);
  void run();
  void answer(zmq::socket_t& socket);

  struct Domain {
    std::string label;
    std::set<std::string> keys;  // Z85
    std::uint64_t refused = 0, accepted = 0;
  };
  void* context_handle_;
  zmq::socket_t socket_;
  mutable std::mutex mutex_;
  std::unordered_map<std::string, Domain> domains_;
  std::uint64_t next_domain_ = 0;
  LogLimiter log_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// A publisher's domain in its context's handler, removed when the publisher goes.
struct ZapDomain {
  ZapDomain(std::shared_ptr<ZapHandler> h, std::string n) : handler(std::move(h)), name(std::move(n)) {}
  ~ZapDomain() { handler->removeDomain(name); }
  ZapDomain(const ZapDomain&) = delete;
  ZapDomain& operator=(const ZapDomain&) = delete;
  std::shared_ptr<ZapHandler> handler;
  std::string name;
};

}  // namespace mannequin::transport::detail
