// The swap barrier of synchronised render nodes over render.sync (mannequin/renderservice/swap_barrier.hpp).
#include "mannequin/renderservice/swap_barrier.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "mannequin/transport/topics.hpp"

namespace mannequin::renderservice {

SwapBarrier::SwapBarrier(transport::Publisher& publisher, std::string name, double timeout_s,
                         std::function<void(std::chrono::microseconds)> poll, std::function<bool()> stopping,
                         std::function<Clock::time_point()> now)
    : pub_(publisher),
      name_(std::move(name)),
      timeout_(std::chrono::nanoseconds(static_cast<std::int64_t>(timeout_s * 1e9))),
      poll_(std::move(poll)),
      stopping_(std::move(stopping)),
      now_(now ? std::move(now) : std::function<Clock::time_point()>([] { return Clock::now(); })) {}

void SwapBarrier::onMessage(const v1::RenderSync& m) {
  if (m.node() == name_) return;
  auto [it, fresh] = peers_.try_emplace(m.node());
  Peer& p = it->second;
  p.heard = now_();
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
  last_post_ = now_();
}

void SwapBarrier::keepAlive(std::uint64_t frame) {
  if (now_() - last_post_ >= timeout_ / 4) post(frame);
}

void SwapBarrier::greet() {
  const auto end = now_() + std::max<std::chrono::nanoseconds>(timeout_, std::chrono::seconds(2));
  auto next = now_();
  while (now_() < end && !stopping_()) {
    if (now_() >= next) {
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
    // the leader's post, or a peer's: a follower posts only the step it draws for its leader, so a peer's
    // newer post relays the leader's (a leader killed while sending its post may reach one survivor only)
    // or is the step of a peer that found the leader dead first and leads now
    if (const std::uint64_t f = newestPost(); f > after) return f;
    const Peer& p = peers_.at(l);
    if (!deadline && have_newer()) deadline = now_() + timeout_;
    // dead: a newer state waits here for the timeout and nothing at all came from the leader meanwhile
    if (deadline && now_() >= *deadline && now_() - p.heard >= timeout_) {
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
  const auto deadline = now_() + timeout_;
  const std::string l = leader();
  for (;;) {
    const auto now = now_();
    bool all = true;
    for (auto& [n, p] : peers_) {
      if (p.dropped || p.frame >= frame) continue;
      if (n == l && now - p.heard >= timeout_) {
        // the leader posts a step before its followers draw it: a leader that has not posted this one took
        // no part in it (this node drew a peer's relay of its last post, or the step of a peer that found it
        // dead); silent for the timeout besides, it is dead, as in awaitLeader: not waited for a whole
        // timeout more, while the peer that leads now waits for this node
        p.dropped = true;
        ++drops_;
        spdlog::warn("swap barrier: leader '{}' silent for {} ms, not at frame {} (a peer's post); dropped", n,
                     std::chrono::duration_cast<std::chrono::milliseconds>(timeout_).count(), frame);
        continue;
      }
      all = false;
    }
    if (all || stopping_()) break;
    if (now >= deadline) {
      for (auto& [n, p] : peers_)
        if (!p.dropped && p.frame < frame) {
          p.dropped = true;
          ++drops_;
          spdlog::warn("swap barrier: peer '{}' not at frame {} after {} ms; dropped", n, frame,
                       std::chrono::duration_cast<std::chrono::milliseconds>(timeout_).count());
        }
      break;
    }
    keepAlive(frame);
    poll_(std::chrono::milliseconds(1));
  }
  return peers();
}

std::uint64_t SwapBarrier::newestPost() const {
  std::uint64_t f = 0;
  for (const auto& [n, p] : peers_)
    if (!p.dropped) f = std::max(f, p.frame);
  return f;
}

}  // namespace mannequin::renderservice
