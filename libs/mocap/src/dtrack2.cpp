#include "mannequin/mocap/dtrack2.hpp"

#include <fmt/format.h>
#include <poll.h>

#include <asio.hpp>
#include <charconv>
#include <cmath>
#include <set>

#include <spdlog/spdlog.h>

#include "mannequin/core/clock.hpp"

namespace mannequin::mocap {

namespace {

// A cursor over one line.
struct Cursor {
  std::string_view s;
  std::size_t i = 0;
  void skipSpace() {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
  }
  bool number(double& v) {
    skipSpace();
    std::size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != ']' && s[j] != '[') ++j;
    if (j == i) return false;
    const std::string tok(s.substr(i, j - i));  // from_chars for double needs exact syntax; strtod accepts "1e3", "+1"
    char* end = nullptr;
    v = std::strtod(tok.c_str(), &end);
    if (end != tok.c_str() + tok.size()) return false;
    i = j;
    return true;
  }
  bool integer(long long& v) {
    skipSpace();
    const auto r = std::from_chars(s.data() + i, s.data() + s.size(), v);
    if (r.ec != std::errc() || r.ptr == s.data() + i) return false;
    i = static_cast<std::size_t>(r.ptr - s.data());
    return i == s.size() || s[i] == ' ' || s[i] == '\t' || s[i] == ']';
  }
  // "[v0 v1 ...]" with between min and max numbers
  bool block(std::vector<double>& out, std::size_t min, std::size_t max) {
    out.clear();
    skipSpace();
    if (i >= s.size() || s[i] != '[') return false;
    ++i;
    for (;;) {
      skipSpace();
      if (i < s.size() && s[i] == ']') {
        ++i;
        return out.size() >= min && out.size() <= max;
      }
      double v = 0;
      if (!number(v) || out.size() >= max) return false;
      out.push_back(v);
    }
  }
  bool atEnd() {
    skipSpace();
    return i >= s.size();
  }
};

std::string parse6d(Cursor& c, DTrackDatagram& out) {
  long long n = 0;
  if (!c.integer(n) || n < 0 || n > 10000) return "6d: expected the number of bodies";
  std::vector<double> b;
  std::set<int> ids;
  for (long long k = 0; k < n; ++k) {
    DTrackBody body;
    if (!c.block(b, 2, 2)) return fmt::format("6d body {}: expected [id quality]", k);
    if (b[0] < 0 || b[0] != std::floor(b[0]) || b[0] > 1e6) return fmt::format("6d body {}: bad id {}", k, b[0]);
    body.id = static_cast<int>(b[0]);
    if (!ids.insert(body.id).second) return fmt::format("6d body {}: duplicate id {}", k, body.id);
    body.quality = b[1];
    if (!c.block(b, 3, 6)) return fmt::format("6d body {} (id {}): expected [sx sy sz (η θ φ)]", k, body.id);
    if (b.size() != 3 && b.size() != 6) return fmt::format("6d body {} (id {}): expected 3 or 6 values in the position block", k, body.id);
    body.position_mm = math::Vector3(b[0], b[1], b[2]);
    if (!c.block(b, 9, 9)) return fmt::format("6d body {} (id {}): expected [b0 .. b8]", k, body.id);
    for (int col = 0; col < 3; ++col)
      for (int row = 0; row < 3; ++row) body.rotation(row, col) = b[3 * col + row];  // column-wise
    if (!body.position_mm.allFinite() || !body.rotation.allFinite() || !std::isfinite(body.quality))
      return fmt::format("6d body id {}: non-finite value", body.id);
    if (body.quality >= 0) {
      const double orth = (body.rotation.transpose() * body.rotation - math::Matrix3::Identity()).norm();
      if (orth > 1e-3 || body.rotation.determinant() < 0)
        return fmt::format("6d body id {}: rotation matrix is not a rotation (|RᵀR − I| = {:.3g})", body.id, orth);
    }
    out.bodies.push_back(body);
  }
  if (!c.atEnd()) return "6d: unexpected text after the last body";
  return {};
}

}  // namespace

std::string parseDTrack(std::string_view datagram, DTrackDatagram& out) {
  out = DTrackDatagram{};
  int line_no = 0;
  std::size_t pos = 0;
  bool any_6d = false;
  while (pos < datagram.size()) {
    std::size_t end = datagram.find_first_of("\r\n", pos);
    if (end == std::string_view::npos) end = datagram.size();
    const std::string_view line = datagram.substr(pos, end - pos);
    pos = end;
    while (pos < datagram.size() && (datagram[pos] == '\r' || datagram[pos] == '\n')) {
      if (datagram[pos] == '\n') ++line_no;
      ++pos;
    }
    if (line.empty()) continue;
    const int shown = line_no + 1 - (pos < datagram.size() || (!datagram.empty() && datagram.back() == '\n') ? 1 : 0);
    auto err = [&](const std::string& m) { return fmt::format("line {}: {}", shown < 1 ? 1 : shown, m); };
    for (char ch : line)
      if (static_cast<unsigned char>(ch) < 0x20 && ch != '\t') return err("control character in the datagram");
    const std::size_t sp = line.find(' ');
    const std::string_view key = line.substr(0, sp);
    Cursor c{line, sp == std::string_view::npos ? line.size() : sp};
    if (key == "fr") {
      long long v = 0;
      if (!c.integer(v) || v < 0 || v > 0xffffffffLL || !c.atEnd()) return err("fr: expected a frame counter");
      out.frame_counter = static_cast<std::uint32_t>(v);
    } else if (key == "ts") {
      double v = 0;
      if (!c.number(v) || !std::isfinite(v) || v < 0 || !c.atEnd()) return err("ts: expected a timestamp in seconds");
      out.timestamp = v;
    } else if (key == "6dcal") {
      long long v = 0;
      if (!c.integer(v) || v < 0 || v > 100000 || !c.atEnd()) return err("6dcal: expected a body count");
      out.calibrated_bodies = static_cast<int>(v);
    } else if (key == "6d") {
      if (any_6d) return err("6d: second 6d line in one datagram");
      any_6d = true;
      const std::string why = parse6d(c, out);
      if (!why.empty()) return err(why);
    }
    // other record types are not used: skipped
  }
  if (!out.frame_counter) return "line 1: no 'fr' line (not a DTrack2 ASCII datagram)";
  return {};
}

struct DTrackSource::Impl {
  asio::io_context io;
  asio::ip::udp::socket socket{io};
  std::vector<char> buffer = std::vector<char>(65536);
};

DTrackSource::DTrackSource(DTrackOptions options) : impl_(std::make_unique<Impl>()), options_(std::move(options)) {
  asio::error_code ec;
  const auto address = asio::ip::make_address(options_.bind_address, ec);
  if (ec) throw std::runtime_error("dtrack2: bad bind address '" + options_.bind_address + "': " + ec.message());
  const asio::ip::udp::endpoint ep(address, static_cast<unsigned short>(options_.port));
  impl_->socket.open(ep.protocol(), ec);
  if (!ec) impl_->socket.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) impl_->socket.bind(ep, ec);
  if (ec)
    throw std::runtime_error(fmt::format("dtrack2: cannot bind UDP {}:{}: {}", options_.bind_address, options_.port, ec.message()));
  impl_->socket.non_blocking(true);
  for (const auto& [id, name] : options_.bodies) {
    Body b;
    b.name = name;
    b.id = id;
    b.tracked = false;
    b.quality = 0;
    last_.push_back(b);
  }
}

DTrackSource::~DTrackSource() = default;

int DTrackSource::port() const { return impl_->socket.local_endpoint().port(); }

std::string DTrackSource::describe() const {
  return fmt::format("ART DTrack2 UDP ASCII on {}:{} ({} bodies)", options_.bind_address, port(), options_.bodies.size());
}

Frame DTrackSource::toFrame(const DTrackDatagram& frame, std::int64_t receive_ns) {
  Frame s;
  s.frame_number = frame.frame_counter.value_or(0);
  s.stamp_ns = frame.timestamp ? static_cast<std::int64_t>(std::llround(*frame.timestamp * 1e9)) : receive_ns;
  for (Body& b : last_) {
    b.tracked = false;
    b.quality = 0;
    for (const DTrackBody& d : frame.bodies) {
      if (d.id != b.id || d.quality < 0) continue;
      b.tracked = true;
      b.quality = std::min(1.0, d.quality);
      b.pose.p = options_.room_rotation * (d.position_mm * options_.unit_to_m);
      b.pose.R = options_.room_rotation * d.rotation;
    }
    s.bodies.push_back(b);
  }
  return s;
}

std::optional<Frame> DTrackSource::next(std::chrono::microseconds timeout) {
  const std::int64_t until = core::steadyNs() + timeout.count() * 1000;
  for (;;) {
    asio::error_code ec;
    asio::ip::udp::endpoint from;
    const std::size_t n = impl_->socket.receive_from(asio::buffer(impl_->buffer), from, 0, ec);
    if (!ec) {
      DTrackDatagram frame;
      const std::string why = parseDTrack(std::string_view(impl_->buffer.data(), n), frame);
      if (why.empty()) return toFrame(frame, core::wallNs());
      ++malformed_;
      if (malformed_ < 10 || malformed_ % 1000 == 0)
        spdlog::warn("dtrack2: malformed datagram from {} ({} bytes, {} so far): {}", from.address().to_string(), n,
                     malformed_, why);
      continue;
    }
    if (ec != asio::error::would_block && ec != asio::error::try_again)
      spdlog::warn("dtrack2: receive failed: {}", ec.message());
    const std::int64_t left = until - core::steadyNs();
    if (left <= 0) return std::nullopt;
    pollfd p{impl_->socket.native_handle(), POLLIN, 0};
    ::poll(&p, 1, static_cast<int>(std::max<std::int64_t>(1, left / 1000000)));
  }
}

}  // namespace mannequin::mocap
