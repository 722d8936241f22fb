#pragma once
/// \file swap_barrier.hpp
/// \brief The swap barrier of synchronised render nodes (view file `sync: true`, docs/render.md), over the
/// render.sync topic: every node publishes RenderSync{frame = the sim.world step it has drawn, node = its
/// name} on its own publisher and subscribes to its peers' (the deployment's `connect`).
///
/// Per frame: the leader (the smallest name among this node and the peers not dropped) draws its newest
/// state and posts its step f; a follower waits for a post of a step newer than its last one, by the
/// leader or by a peer (a follower posts only the leader's steps, so a peer's post relays the leader's),
/// draws that step and posts it; then every node waits until every peer not dropped has posted a
/// step >= f, and swaps. A peer that does not answer within the timeout is dropped (not waited for)
/// until it posts again; so is a leader that posts nothing at all (every waiting node re-posts as a
/// keep-alive, see keepAlive()) for the timeout while this node has a newer state, or while this node
/// waits in the barrier of a step that leader did not post (the next name leads). A node that joins late
/// is waited for from its first post.
///
/// A leader killed while sending its post may reach only some followers: they draw that step and post
/// it, which relays it to the others, so the survivors still swap the same step; then the first survivor
/// that finds the leader silent for the timeout leads, and the others take its post at once.
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "mannequin/transport/publisher.hpp"

namespace mannequin::renderservice {

class SwapBarrier {
 public:
  using Clock = std::chrono::steady_clock;
  /// `poll(timeout)` waits up to timeout for traffic (delivering render.sync to onMessage); `stopping()`
  /// ends the waits early; `now()` is the clock the timeouts are measured on (steady_clock when empty; a
  /// test's scripted poll advances its own instead of waiting).
  SwapBarrier(transport::Publisher& publisher, std::string name, double timeout_s,
              std::function<void(std::chrono::microseconds)> poll, std::function<bool()> stopping,
              std::function<Clock::time_point()> now = {});

  /// Handler of render.sync (own messages are ignored).
  void onMessage(const v1::RenderSync& m);
  /// Start-up: posts a hello (frame 0) every 50 ms for max(timeout, 2 s) so that nodes started together
  /// know each other before their first frame.
  void greet();
  bool isLeader() const { return leader() == name_; }
  std::string leader() const;
  /// Follower: the newest step > `after` posted by the leader or by a peer not dropped (a relay of the
  /// leader's, or the post of a peer that already leads); nullopt when the leader changed (this node may
  /// lead now), it was dropped (no post within the timeout while `have_newer()`), or on stop.
  std::optional<std::uint64_t> awaitLeader(std::uint64_t after, const std::function<bool()>& have_newer);
  /// Posts `frame` (drawn) and waits until every peer not dropped posted >= frame, or the timeout (the
  /// late ones are dropped); the leader, when it did not post `frame` (this node drew a peer's post) and
  /// nothing at all came from it for the timeout, is dropped at once. Re-posts `frame` every timeout/4
  /// while waiting. Returns the number of peers that made it.
  int arriveAndWait(std::uint64_t frame);
  int peers() const;  ///< peers not dropped
  /// While waiting (for a leader, a new state or the barrier): re-posts `frame` (the last one swapped, or
  /// in the barrier the one arrived at) at most every timeout/4, so peers see this node alive and do not
  /// take it for dead.
  void keepAlive(std::uint64_t frame);
  std::uint64_t dropped() const { return drops_; }

 private:
  struct Peer {
    std::uint64_t frame = 0;
    bool dropped = false;
    Clock::time_point heard;
  };
  void post(std::uint64_t frame);
  std::uint64_t newestPost() const;  ///< the newest step posted by a peer not dropped (0: none)
  transport::Publisher& pub_;
  std::string name_;
  std::chrono::nanoseconds timeout_;
  std::function<void(std::chrono::microseconds)> poll_;
  std::function<bool()> stopping_;
  std::function<Clock::time_point()> now_;
  std::map<std::string, Peer> peers_;
  std::uint64_t drops_ = 0;
  Clock::time_point last_post_;
};

}  // namespace mannequin::renderservice
