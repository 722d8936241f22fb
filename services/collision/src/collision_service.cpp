#include "mannequin/collisionservice/collision_service.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <chrono>

#include "mannequin/core/paths.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/transport/clock.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/validate.hpp"

namespace mannequin::collisionservice {

CollisionServiceConfig parseCollisionConfig(const core::ConfigNode& config) {
  config.allowOnly({"name", "publish", "connect", "security", "scene", "activation_distance", "mannequins"});
  CollisionServiceConfig c;
  c.activation_distance = config.getIn("activation_distance", c.activation_distance, 0.0, 10.0);
  if (auto scene = config.find("scene")) {
    try {
      c.scene = collision::loadScene(core::findData(scene->str()));
    } catch (const std::exception& e) {
      scene->fail(e.what());
    }
  }
  for (const core::ConfigNode& m : config["mannequins"].items()) {
    m.allowOnly({"name", "config", "margin", "self_collision"});
    MannequinEntry e;
    e.name = m["name"].str();
    for (const MannequinEntry& other : c.mannequins)
      if (other.name == e.name) m["name"].fail("two mannequins named '" + e.name + "'");
    try {
      e.model = skeleton::buildMannequin(skeleton::loadMannequinSpec(core::findData(m["config"].str())));
    } catch (const std::exception& ex) {
      m["config"].fail(ex.what());
    }
    e.margin = m.getIn("margin", 0.0, 0.0, 1.0);
    e.self_collision = m.get("self_collision", true);
    c.mannequins.push_back(std::move(e));
  }
  return c;
}

namespace {
collision::WorldOptions worldOptions(const CollisionServiceConfig& config) {
  collision::WorldOptions o;
  o.activation_distance = config.activation_distance;
  return o;
}
}  // namespace

QueryHandler::QueryHandler(const CollisionServiceConfig& config) : world_(worldOptions(config)) {
  if (config.scene) world_.addScene(*config.scene);
  mannequins_.reserve(config.mannequins.size());
  for (const MannequinEntry& e : config.mannequins) {
    Slot& slot = mannequins_.emplace_back();
    slot.name = e.name;
    slot.model = e.model;
    collision::MannequinOptions mo;
    mo.name = e.name;
    mo.margin = e.margin;
    mo.self_collision = e.self_collision;
    slot.index = world_.addMannequin(slot.model, mo);
  }
  for (Slot& s : mannequins_) {  // after the vector stops moving: Data refers to its Model
    s.data = std::make_unique<skeleton::Data>(s.model);
    s.q = skeleton::VectorX::Zero(s.model.nq);
  }
}

// Poses the mannequins and movable bodies of a query; "" or what is wrong with it.
std::string QueryHandler::pose(const v1::CollisionQuery& q) {
  for (const v1::MannequinConfiguration& mc : q.mannequins()) {
    Slot* slot = nullptr;
    for (Slot& s : mannequins_)
      if (s.name == mc.name()) slot = &s;
    if (slot == nullptr) return "unknown mannequin '" + mc.name() + "'";
    if (mc.q_size() != slot->model.nq)
      return fmt::format("mannequin '{}': {} coordinates, expected {}", mc.name(), mc.q_size(), slot->model.nq);
    for (int k = 0; k < slot->model.nq; ++k) slot->q(k) = mc.q(k);
    if (!slot->q.allFinite()) return "mannequin '" + mc.name() + "': non-finite configuration";
    skeleton::forwardKinematics(slot->model, *slot->data, slot->q);
    world_.updateMannequin(slot->index, *slot->data);
  }
  for (const v1::BodyPose& b : q.bodies()) {
    const int id = world_.findBody(b.body());
    if (id < 0 || world_.bodyKind(id) != collision::BodyKind::kMovable) return "no movable body '" + b.body() + "'";
    const math::SE3 pose = transport::fromMsg(b.pose());
    if (!pose.p.allFinite() || !pose.R.allFinite()) return "body '" + b.body() + "': non-finite pose";
    world_.setBodyPose(id, pose);
  }
  return {};
}

void QueryHandler::split(const std::string& body, std::string& mannequin, std::string& segment) const {
  const auto slash = body.find('/');
  for (const Slot& s : mannequins_)
    if (slash == s.name.size() && body.compare(0, slash, s.name) == 0) {
      mannequin = s.name;
      segment = body.substr(slash + 1);
      return;
    }
  mannequin.clear();
  segment = body;
}

bool QueryHandler::answer(const v1::CollisionQuery& q, v1::ContactSet& out) {
  out.Clear();
  out.mutable_header()->set_stamp_ns(q.header().stamp_ns());
  out.set_step(q.step());
  if (std::string error = pose(q); !error.empty()) {
    out.set_error(error);
    return false;
  }
  world_.query(q.step(), contacts_);
  std::string ma, sa, mb, sb;
  for (const collision::Contact& c : contacts_.contacts) {
    v1::Contact* m = out.add_contacts();
    split(world_.bodyName(c.body_a), ma, sa);
    split(world_.bodyName(c.body_b), mb, sb);
    m->set_mannequin_a(ma);
    m->set_body_a(sa);
    m->set_mannequin_b(mb);
    m->set_body_b(sb);
    transport::toMsg(c.point_a, *m->mutable_point_a());
    transport::toMsg(c.point_b, *m->mutable_point_b());
    transport::toMsg(c.normal, *m->mutable_normal());
    m->set_distance(c.distance);
    transport::toMsg(world_.bodyPose(c.body_a).act(c.point_a), *m->mutable_point_a_world());
    transport::toMsg(world_.bodyPose(c.body_b).act(c.point_b), *m->mutable_point_b_world());
  }
  return true;
}

struct CollisionService::Impl {
  service::Endpoints endpoints;
  QueryHandler handler;
  transport::Publisher pub;
  transport::Subscriber sub;
  transport::HealthReporter health;
  v1::ContactSet answer;
  CollisionStats stats;
  double worst_ms = 0;

  Impl(const CollisionServiceConfig& c, const service::Endpoints& e, zmq::context_t& ctx, double hb)
      : endpoints(e), handler(c), pub(ctx, service::publisherOptions(e)), sub(ctx, service::subscriberOptions(e)), health(pub, e.name, &sub, hb) {
    sub.subscribe(transport::topics::kCollisionQuery,
                  std::function<void(const v1::CollisionQuery&)>([this](const v1::CollisionQuery& q) { onQuery(q); }),
                  transport::validateCollisionQuery);
  }

  void onQuery(const v1::CollisionQuery& q) {
    const std::int64_t t0 = transport::steadyNs();
    if (handler.answer(q, answer))
      stats.contacts += static_cast<std::uint64_t>(answer.contacts_size());
    else
      ++stats.errors;
    const double ms = static_cast<double>(transport::steadyNs() - t0) * 1e-6;
    answer.set_compute_time_s(ms * 1e-3);
    worst_ms = std::max(worst_ms, ms);
    pub.publish(transport::topics::kCollisionContacts, answer);
    ++stats.queries;
    health.loopIteration();
  }

  void updateHealth() {
    health.setStat("queries", static_cast<double>(stats.queries));
    health.setStat("query_errors", static_cast<double>(stats.errors));
    health.setStat("contacts_last", static_cast<double>(answer.contacts_size()));
    health.setStat("worst_query_ms", worst_ms);
  }
};

CollisionService::CollisionService(const CollisionServiceConfig& config, const service::Endpoints& endpoints,
                                   zmq::context_t& context, double heartbeat_period)
    : impl_(std::make_unique<Impl>(config, endpoints, context, heartbeat_period)) {}

CollisionService::~CollisionService() = default;

CollisionStats CollisionService::stats() const { return impl_->stats; }
std::vector<std::string> CollisionService::boundEndpoints() const { return impl_->pub.boundEndpoints(); }

int CollisionService::run(const std::atomic<bool>& stop, double duration) {
  Impl& s = *impl_;
  const collision::CollisionWorld& w = s.handler.world();
  spdlog::info("{}: {} bodies ({} mannequins), activation distance {} m; contacts on {}, queries from {}", s.endpoints.name,
               w.bodyCount(), s.handler.numMannequins(), w.activationDistance(), fmt::join(s.pub.boundEndpoints(), ", "),
               fmt::join(s.endpoints.connect, ", "));
  service::ServiceLoop loop(s.health, stop, duration);
  loop.run(
      [&] {
        s.pub.poll();
        s.sub.poll(std::chrono::milliseconds(10));
        s.updateHealth();
        return true;
      },
      [&] { s.worst_ms = 0; }, [&] { s.updateHealth(); });
  spdlog::info("{}: stopped after {} queries ({} errors, {} contacts in all)", s.endpoints.name, s.stats.queries, s.stats.errors,
               s.stats.contacts);
  return 0;
}

}  // namespace mannequin::collisionservice
