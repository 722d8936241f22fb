#pragma once
/// \file collision_service.hpp
/// \brief The collision service: its config, the query handler (collision.query → collision.contacts
/// on a CollisionWorld of the scene and the mannequins' segment capsules), and its loop.
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <mannequin/v1/collision.pb.h>
#include <zmq.hpp>

#include "mannequin/collision/scene.hpp"
#include "mannequin/collision/world.hpp"
#include "mannequin/core/config.hpp"
#include "mannequin/service/runtime.hpp"
#include "mannequin/skeleton/kinematics.hpp"

namespace mannequin::collisionservice {

struct MannequinEntry {
  std::string name;      ///< instance name (as in collision.query and sim.world)
  skeleton::Model model; ///< built from its configs/mannequins/*.yaml
  double margin = 0.0;   ///< m, every segment
  bool self_collision = true;
};

struct CollisionServiceConfig {
  std::optional<collision::SceneSpec> scene;
  double activation_distance = 0.02;  ///< m (a scene's own value replaces it)
  std::vector<MannequinEntry> mannequins;
};

/// Reads the service config (keys name, publish, connect, scene, activation_distance, mannequins) and
/// loads the scene and the mannequins (paths found with core::findData).
/// \throws core::ConfigError naming FILE:LINE and the field.
CollisionServiceConfig parseCollisionConfig(const core::ConfigNode& config);

/// Answers collision queries: poses every mannequin from its configuration and the movable bodies from
/// their poses, then queries the CollisionWorld. A bad query (unknown mannequin or body, wrong number
/// of coordinates, non-finite configuration) is answered with `error` set and no contacts.
class QueryHandler {
 public:
  /// Builds the world. \throws std::invalid_argument (two mannequins with one name, bad margins).
  explicit QueryHandler(const CollisionServiceConfig& config);
  /// Fills `out` (cleared first): header.stamp_ns and step of the query, contacts with witness points in
  /// body and world frames, or error. Returns false for a bad query.
  bool answer(const v1::CollisionQuery& query, v1::ContactSet& out);
  const collision::CollisionWorld& world() const { return world_; }
  int numMannequins() const { return static_cast<int>(mannequins_.size()); }

 private:
  struct Slot {
    std::string name;
    skeleton::Model model;
    std::unique_ptr<skeleton::Data> data;
    int index = -1;
    skeleton::VectorX q;  // the query's configuration (sized at build time)
  };
  std::string pose(const v1::CollisionQuery& query);
  void split(const std::string& body, std::string& mannequin, std::string& segment) const;
  collision::CollisionWorld world_;
  std::vector<Slot> mannequins_;
  collision::ContactSet contacts_;
};

struct CollisionStats {
  std::uint64_t queries = 0, errors = 0, contacts = 0;
};

/// The service: subscribes collision.query, publishes collision.contacts and heartbeats.
class CollisionService {
 public:
  CollisionService(const CollisionServiceConfig& config, const service::Endpoints& endpoints, zmq::context_t& context,
                   double heartbeat_period = 0.5);
  ~CollisionService();
  /// Runs until `stop` or `duration` seconds (0: no limit). Returns 0.
  int run(const std::atomic<bool>& stop, double duration = 0.0);
  CollisionStats stats() const;
  std::vector<std::string> boundEndpoints() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mannequin::collisionservice
