#include "swap_barrier.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "mannequin/transport/topics.hpp"

namespace mannequin::render_node {

using Clock = std::chrono::steady_clock;

SwapBarrier::SwapBarrier(transport::Publisher& publisher, std::string name, double timeout_s,
                         std::function<void(std::chrono::microseconds)> poll, std::function<bool()> stopping)
    : pub_(publisher),
      name_(std::move(name)),
      timeout_(std::chrono::nanoseconds(static_cast<std::int64_t>(timeout_s * 1e9))),
      poll_(std::move(poll)),
      stopping_(std::move(stopping)) {}

void SwapBarrier::onMessage(const v1::RenderSync& m) {
  if (m.node() == name_) return;
  auto [it, fresh] = peers_.try_emplace(m.node());
  Peer& p = it->second;
  p.heard = Clock::now();
  if (fresh) spdlog::info("swap barrier: peer '{}' joined", m.node());
  if (p.dropped && (m.frame() > p.frame || fresh)) {
    p.dropped = false;
    spdlog::info("swap barrier: peer '{}' is back", m.node());
  }
  if (m.frame() > p.frame) p.frame = m.frame();
}

void SwapBarrier::post(std::uint64_t frame) {
  v1::RenderSync m;
  m.set_frame(frame);
  m.set_node(name_);
  pub_.publish(transport::topics::kRenderSync, m);
  pub_.poll();
  last_post_ = Clock::now();
}

void SwapBarrier::keepAlive(std::uint64_t frame) {
  if (Clock::now() - last_post_ >= timeout_ / 4) post(frame);
}

void SwapBarrier::greet() {
  const auto end = Clock::now() + std::max<std::chrono::nanoseconds>(timeout_, std::chrono::seconds(2));
  auto next = Clock::now();
  while (Clock::now() < end && !stopping_()) {
    if (Clock::now() >= next) {
      post(0);
      next += std::chrono::milliseconds(50);
    }
    poll_(std::chrono::milliseconds(10));
  }
  spdlog::info("swap barrier: {} peer(s) after the greeting, leader '{}'", peers(), leader());
}

std::string SwapBarrier::leader() const {
  std::string l = name_;
  for (const auto& [n, p] : peers_)
    if (!p.dropped && n < l) l = n;
  return l;
}

int SwapBarrier::peers() const {
  int n = 0;
  for (const auto& [k, p] : peers_) n += p.dropped ? 0 : 1;
  return n;
}

std::optional<std::uint64_t> SwapBarrier::awaitLeader(std::uint64_t after, const std::function<bool()>& have_newer) {
  const std::string l = leader();
  std::optional<Clock::time_point> deadline;
  while (!stopping_()) {
    if (leader() != l) return std::nullopt;  // a smaller name came back or joined
    const Peer& p = peers_.at(l);
    if (p.frame > after) return p.frame;
    if (!deadline && have_newer()) deadline = Clock::now() + timeout_;
    // dead: a newer state waits here for the timeout and nothing at all came from the leader meanwhile
    if (deadline && Clock::now() >= *deadline && Clock::now() - p.heard >= timeout_) {
      peers_.at(l).dropped = true;
      ++drops_;
      spdlog::warn("swap barrier: leader '{}' silent for {} ms; dropped", l,
                   std::chrono::duration_cast<std::chrono::milliseconds>(timeout_).count());
      return std::nullopt;
    }
    keepAlive(after);
    poll_(std::chrono::milliseconds(2));
  }
  return std::nullopt;
}

int SwapBarrier::arriveAndWait(std::uint64_t frame) {
  post(frame);
  const auto deadline = Clock::now() + timeout_;
  for (;;) {
    bool all = true;
    for (const auto& [n, p] : peers_)
      if (!p.dropped && p.frame < frame) all = false;
    if (all || stopping_()) break;
    if (Clock::now() >= deadline) {
      for (auto& [n, p] : peers_)
        if (!p.dropped && p.frame < frame) {
          p.dropped = true;
          ++drops_;
          spdlog::warn("swap barrier: peer '{}' not at frame {} after {} ms; dropped", n, frame,
                       std::chrono::duration_cast<std::chrono::milliseconds>(timeout_).count());
        }
      break;
    }
    poll_(std::chrono::milliseconds(1));
  }
  return peers();
}

}  // namespace mannequin::render_node
