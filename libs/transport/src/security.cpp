#include "mannequin/transport/security.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <zmq.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <stdexcept>

#include "zap.hpp"

namespace mannequin::transport {

bool isZ85Key(std::string_view key) {
  if (key.size() != 40) return false;
  const std::string text(key);
  std::array<std::uint8_t, 32> out{};
  return zmq_z85_decode(out.data(), text.c_str()) != nullptr;
}

bool hasCurve() { return zmq_has("curve") != 0; }

CurveKeyPair generateCurveKeyPair() {
  std::array<char, 41> pub{}, sec{};
  if (zmq_curve_keypair(pub.data(), sec.data()) != 0)
    throw std::runtime_error(std::string("zmq_curve_keypair failed: ") + zmq_strerror(zmq_errno()) +
                             " (libzmq built without CURVE?)");
  return {std::string(pub.data()), std::string(sec.data())};
}

std::string curvePublicKey(const std::string& secret_z85) {
  if (!isZ85Key(secret_z85)) throw std::invalid_argument("not a Z85 CURVE key (40 characters of the Z85 alphabet)");
  std::array<char, 41> pub{};
  if (zmq_curve_public(pub.data(), secret_z85.c_str()) != 0)
    throw std::invalid_argument(std::string("zmq_curve_public failed: ") + zmq_strerror(zmq_errno()));
  return std::string(pub.data());
}

std::string z85Encode(std::string_view binary32) {
  if (binary32.size() != 32) return fmt::format("<{} bytes, not a CURVE key>", binary32.size());
  std::array<char, 41> out{};
  zmq_z85_encode(out.data(), reinterpret_cast<const std::uint8_t*>(binary32.data()), 32);
  return std::string(out.data());
}

std::string readKeyFile(const std::string& path, bool secret) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw std::runtime_error(path + ": cannot read key file: " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw std::runtime_error(path + ": not a regular file");
  if (secret && (st.st_mode & 077) != 0)
    throw std::runtime_error(fmt::format("{}: secret key file is readable by others (mode {:04o}; chmod 600 it)", path,
                                         st.st_mode & 07777));
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read key file: " + std::strerror(errno));
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto b = line.find_first_not_of(" \t\r");
    if (b == std::string::npos || line[b] == '#') continue;
    const auto e = line.find_last_not_of(" \t\r");
    const std::string key = line.substr(b, e - b + 1);
    if (!isZ85Key(key))
      throw std::runtime_error(key.size() == 40 ? fmt::format("{}:{}: not a Z85 CURVE key (40 characters that do not decode)", path, number)
                                                : fmt::format("{}:{}: not a Z85 CURVE key (expected 40 characters, got {})", path,
                                                              number, key.size()));
    return key;
  }
  throw std::runtime_error(path + ": no key in the file");
}

void writeKeyFile(const std::string& path, const std::string& key, const std::string& comment, unsigned mode) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, static_cast<mode_t>(mode));
  if (fd < 0) {
    if (errno == EEXIST) throw std::runtime_error(path + ": already exists (refusing to overwrite)");
    throw std::runtime_error(path + ": cannot create: " + std::strerror(errno));
  }
  ::fchmod(fd, static_cast<mode_t>(mode));  // whatever the umask
  const std::string text = "# " + comment + "\n" + key + "\n";
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  const bool closed = ::close(fd) == 0;
  if (!ok || !closed) throw std::runtime_error(path + ": cannot write: " + std::strerror(errno));
}

namespace detail {

namespace {
std::mutex registry_mutex;
std::map<void*, std::weak_ptr<ZapHandler>>& registry() {
  static std::map<void*, std::weak_ptr<ZapHandler>> r;
  return r;
}
}  // namespace

std::shared_ptr<ZapHandler> ZapHandler::of(zmq::context_t& context) {
  std::lock_guard lock(registry_mutex);
  auto& r = registry();
  if (auto it = r.find(context.handle()); it != r.end())
    if (auto existing = it->second.lock()) return existing;
  std::shared_ptr<ZapHandler> h(new ZapHandler(context));
  r[context.handle()] = h;
  return h;
}

ZapHandler::ZapHandler(zmq::context_t& context) : context_handle_(context.handle()), socket_(context, zmq::socket_type::rep) {
  socket_.set(zmq::sockopt::linger, 0);
  try {
    socket_.bind("inproc://zeromq.zap.01");  // bound before any CURVE server socket binds
  } catch (const zmq::error_t& e) {
    throw std::runtime_error(std::string("cannot start the ZAP handler (inproc://zeromq.zap.01): ") + e.what());
  }
  thread_ = std::thread([this] { run(); });
}

ZapHandler::~ZapHandler() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(registry_mutex);
  auto& r = registry();
  if (auto it = r.find(context_handle_); it != r.end() && it->second.expired()) r.erase(it);
}

std::string ZapHandler::addDomain(const std::string& label, const std::vector<std::string>& keys) {
  std::lock_guard lock(mutex_);
  const std::string domain = "mannequin-" + std::to_string(++next_domain_);
  Domain d;
  d.label = label;
  d.keys.insert(keys.begin(), keys.end());
  domains_[domain] = std::move(d);
  return domain;
}

void ZapHandler::removeDomain(const std::string& domain) {
  std::lock_guard lock(mutex_);
  domains_.erase(domain);
}

std::uint64_t ZapHandler::refusals(const std::string& domain) const {
  std::lock_guard lock(mutex_);
  auto it = domains_.find(domain);
  return it == domains_.end() ? 0 : it->second.refused;
}

std::uint64_t ZapHandler::accepted(const std::string& domain) const {
  std::lock_guard lock(mutex_);
  auto it = domains_.find(domain);
  return it == domains_.end() ? 0 : it->second.accepted;
}

void ZapHandler::run() {
  while (!stop_.load()) {
    zmq::pollitem_t item{socket_.handle(), 0, ZMQ_POLLIN, 0};
    try {
      zmq::poll(&item, 1, std::chrono::milliseconds(50));
      if ((item.revents & ZMQ_POLLIN) != 0) answer(socket_);
    } catch (const zmq::error_t& e) {
      if (e.num() == EINTR) continue;
      if (e.num() == ETERM) break;
      spdlog::error("ZAP handler: {}", e.what());
    }
  }
  socket_.close();
}

// RFC 27: request [version, request id, domain, address, identity, mechanism, credentials...],
// reply [version, request id, status code, status text, user id, metadata].
void ZapHandler::answer(zmq::socket_t& socket) {
  std::vector<zmq::message_t> parts;
  for (;;) {
    zmq::message_t part;
    if (!socket.recv(part, zmq::recv_flags::dontwait)) break;
    const bool more = part.more();
    parts.push_back(std::move(part));
    if (!more) break;
  }
  if (parts.empty()) return;
  auto text = [&](std::size_t i) { return i < parts.size() ? parts[i].to_string() : std::string(); };
  const std::string version = text(0), request_id = text(1), domain = text(2), address = text(3), mechanism = text(5);
  const std::string key = parts.size() > 6 ? z85Encode(parts[6].to_string_view()) : std::string("<none>");
  bool ok = false;
  std::string label = "?";
  {
    std::lock_guard lock(mutex_);
    auto it = domains_.find(domain);
    if (it == domains_.end()) {
      // not a domain of ours: a plaintext socket of this context (libzmq may ask ZAP for NULL too once
      // a handler exists) is admitted as if no handler ran; anything else is refused
      ok = mechanism == "NULL";
    } else {
      label = it->second.label;
      ok = version == "1.0" && mechanism == "CURVE" && it->second.keys.count(key) > 0;
      ++(ok ? it->second.accepted : it->second.refused);
    }
  }
  if (ok && mechanism == "NULL") {
    // nothing to log
  } else if (ok) {
    spdlog::debug("publisher '{}': admitted CURVE client {} from {}", label, key, address);
  } else {
    log_.warn("refused|" + domain + "|" + address,  // bounded by peers, not by the keys they try
              fmt::format("publisher '{}': refused {} client key {} from {} (not in authorized_keys)", label,
                          mechanism.empty() ? "?" : mechanism, key, address.empty() ? "?" : address));
  }
  const char* status = ok ? "200" : "400";
  const char* status_text = ok ? "OK" : "key not authorized";
  socket.send(zmq::buffer(std::string("1.0")), zmq::send_flags::sndmore);
  socket.send(zmq::buffer(request_id), zmq::send_flags::sndmore);
  socket.send(zmq::buffer(std::string_view(status)), zmq::send_flags::sndmore);
  socket.send(zmq::buffer(std::string_view(status_text)), zmq::send_flags::sndmore);
  socket.send(zmq::buffer(ok ? key : std::string()), zmq::send_flags::sndmore);
  socket.send(zmq::str_buffer(""), zmq::send_flags::none);
}

}  // namespace detail
}  // namespace mannequin::transport
