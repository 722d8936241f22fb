#pragma once
/// \file topics.hpp
/// \brief Every topic of the cluster, with its message type and delivery policy (one place).
///
/// Frames on the wire are multipart [topic][payload]: the topic is the exact name below (ZeroMQ
/// subscriptions are prefixes; the subscriber checks the full name), the payload a serialized message
/// whose field 1 is a mannequin.v1.Header.
///
/// Delivery:
/// - kQueue: every message is delivered in order (up to the high-water mark; a gap in the header
///   sequence is counted as dropped). Used for streams where each message matters (mocap frames,
///   collision answers, commands, triggers).
/// - kLatest: "latest value only": a subscriber that falls behind gets only the newest message of
///   the topic on each poll (older ones are counted as superseded, never queued up); state topics.
///   A publisher keeps the last value of every kLatest topic and re-sends it as soon as a new
///   subscriber's subscription reaches it, so a late joiner gets the current state at once.
#include <string_view>

#include <mannequin/v1/collision.pb.h>
#include <mannequin/v1/health.pb.h>
#include <mannequin/v1/mocap.pb.h>
#include <mannequin/v1/scenario.pb.h>
#include <mannequin/v1/world.pb.h>

namespace mannequin::transport {

/// Schema version written in every Header by this build (package mannequin.v1 → 1). Receivers
/// reject (count as malformed) messages with another version.
inline constexpr unsigned kSchemaVersion = 1;

enum class Delivery { kQueue, kLatest };

/// A topic name bound to its message type M at compile time.
template <class M>
struct Topic {
  using Message = M;
  std::string_view name;
  Delivery delivery;
};

namespace topics {
inline constexpr Topic<v1::MocapFrame> kMocapFrame{"mocap.frame", Delivery::kQueue};
inline constexpr Topic<v1::WorldState> kSimWorld{"sim.world", Delivery::kLatest};
inline constexpr Topic<v1::CollisionQuery> kCollisionQuery{"collision.query", Delivery::kLatest};
inline constexpr Topic<v1::ContactSet> kCollisionContacts{"collision.contacts", Delivery::kQueue};
inline constexpr Topic<v1::ModeCommand> kScenarioCommand{"scenario.command", Delivery::kQueue};
inline constexpr Topic<v1::ScenarioState> kScenarioState{"scenario.state", Delivery::kLatest};
inline constexpr Topic<v1::Trigger> kScenarioTrigger{"scenario.trigger", Delivery::kQueue};
inline constexpr Topic<v1::RenderSync> kRenderSync{"render.sync", Delivery::kQueue};
inline constexpr Topic<v1::Heartbeat> kHeartbeat{"health.heartbeat", Delivery::kLatest};

/// Name, message type (full protobuf name) and delivery of every topic, for tools (record/replay).
struct TopicInfo {
  std::string_view name;
  std::string_view type;
  Delivery delivery;
};
inline constexpr TopicInfo kAll[] = {
    {"mocap.frame", "mannequin.v1.MocapFrame", Delivery::kQueue},
    {"sim.world", "mannequin.v1.WorldState", Delivery::kLatest},
    {"collision.query", "mannequin.v1.CollisionQuery", Delivery::kLatest},
    {"collision.contacts", "mannequin.v1.ContactSet", Delivery::kQueue},
    {"scenario.command", "mannequin.v1.ModeCommand", Delivery::kQueue},
    {"scenario.state", "mannequin.v1.ScenarioState", Delivery::kLatest},
    {"scenario.trigger", "mannequin.v1.Trigger", Delivery::kQueue},
    {"render.sync", "mannequin.v1.RenderSync", Delivery::kQueue},
    {"health.heartbeat", "mannequin.v1.Heartbeat", Delivery::kLatest},
};

/// The entry of kAll named `name`, or nullptr.
constexpr const TopicInfo* find(std::string_view name) {
  for (const TopicInfo& t : kAll)
    if (t.name == name) return &t;
  return nullptr;
}
}  // namespace topics

}  // namespace mannequin::transport
