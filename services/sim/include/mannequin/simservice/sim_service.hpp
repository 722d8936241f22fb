#pragma once
/// \file sim_service.hpp
/// \brief The sim service's loop (mannequin-sim is a thin main over it).
///
/// Live mode: paced by the steady clock, one World step every δt; between steps it waits on its
/// subscriptions. The World clock is anchored to the capture clock at the first mocap frame (and again
/// if the two drift apart by more than reanchor_threshold). sim.world every 1/world_rate s.
/// Replay mode: driven by input timestamps, no wall clock: each mocap frame (in arrival order) makes the
/// World step until its capture time; same inputs ⇒ same sim.world bytes (send_time_ns = 0).
/// Collision (mode service): every period_steps steps it publishes collision.query (step number, every
/// mannequin's q) and waits for collision.contacts of that step up to the deadline — live: before the
/// next query (pipelined); replay: at once (synchronous, so the contacts used do not depend on timing);
/// past the deadline the previous set is reused and sim.world says contacts_stale.
#include <atomic>
#include <memory>

#include <zmq.hpp>

#include "mannequin/simservice/config.hpp"

namespace mannequin::simservice {

struct SimStats {
  std::uint64_t steps = 0;
  std::uint64_t worlds = 0;
  std::uint64_t mocap_frames = 0;
  std::uint64_t queries = 0;
  std::uint64_t contact_sets = 0;
  std::uint64_t stale_contacts = 0;
  std::uint64_t overruns = 0;   ///< live: steps started more than 10 ms late (then the pacing resynchronises)
  std::uint64_t dropped_steps = 0;  ///< live: steps of wall time skipped by those resynchronisations (⌊lateness / δt⌋ each)
};

class SimService {
 public:
  /// Builds the World and binds/connects. \throws core::ConfigError, std::runtime_error.
  SimService(const SimServiceConfig& config, zmq::context_t& context, double heartbeat_period = 0.5);
  ~SimService();
  /// Runs until `stop` or `duration` seconds (0 = no limit). Returns 0.
  int run(const std::atomic<bool>& stop, double duration = 0.0);
  SimStats stats() const;
  /// Endpoints bound (tcp ports resolved).
  std::vector<std::string> boundEndpoints() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mannequin::simservice
