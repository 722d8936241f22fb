// mannequin-collision: answers collision.query with collision.contacts (the collision library: FCL
// world of the scene and the mannequins' segment capsules). See docs/cluster.md.
#include <CLI/CLI.hpp>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <map>

#include "mannequin/collision/world.hpp"
#include "mannequin/core/config.hpp"
#include "mannequin/service/runtime.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"
#include "mannequin/transport/clock.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/health.hpp"
#include "mannequin/transport/validate.hpp"

using namespace mannequin;

namespace {
struct MannequinSlot {
  std::string name;
  skeleton::Model model;
  std::unique_ptr<skeleton::Data> data;
  int index = -1;
};
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mannequin-collision: the collision world (scene + mannequin segment capsules) answering\n"
               "collision.query (step number, mannequin configurations, object poses) with collision.contacts\n"
               "(witness points in body and world frames, normals, signed distances), one answer per query."};
  service::CommonOptions common;
  service::addCommonOptions(app, common, true);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    service::setupLogging(common.log_level);
    const auto& stop = service::installStopSignals();
    const core::ConfigNode config = core::ConfigNode::load(common.config);
    config.allowOnly({"name", "publish", "connect", "scene", "activation_distance", "mannequins"});
    const std::string name = common.name.empty() ? config.get("name", std::string("collision")) : common.name;
    std::vector<std::string> publish = common.publish, connect = common.connect;
    if (publish.empty()) publish = config["publish"].strings();
    if (connect.empty() && config.has("connect")) connect = config["connect"].strings();

    collision::WorldOptions wo;
    wo.activation_distance = config.getIn("activation_distance", wo.activation_distance, 0.0, 10.0);
    collision::World world(wo);
    if (auto scene = config.find("scene")) {
      try {
        world.addScene(collision::loadScene(scene->str()));
      } catch (const std::exception& e) {
        scene->fail(e.what());
      }
    }
    std::vector<MannequinSlot> mannequins;
    for (const core::ConfigNode& m : config["mannequins"].items()) {
      m.allowOnly({"name", "config", "margin", "self_collision"});
      MannequinSlot slot;
      slot.name = m["name"].str();
      try {
        slot.model = skeleton::buildMannequin(skeleton::loadMannequinSpec(m["config"].str()));
      } catch (const std::exception& e) {
        m["config"].fail(e.what());
      }
      collision::MannequinOptions mo;
      mo.name = slot.name;
      mo.margin = m.getIn("margin", 0.0, 0.0, 1.0);
      mo.self_collision = m.get("self_collision", true);
      slot.index = world.addMannequin(slot.model, mo);
      mannequins.push_back(std::move(slot));
    }
    for (auto& s : mannequins) s.data = std::make_unique<skeleton::Data>(s.model);

    zmq::context_t context;
    transport::Publisher pub(context, {name, publish});
    transport::Subscriber sub(context, {name, connect});
    transport::HealthReporter health(pub, name, &sub, common.heartbeat_period);
    collision::ContactSet contacts;
    v1::ContactSet answer;
    std::uint64_t queries = 0, errors = 0, contacts_total = 0;
    double worst_ms = 0;
    auto split = [&](const std::string& body, std::string& mannequin, std::string& segment) {
      const auto slash = body.find('/');
      for (const auto& s : mannequins)
        if (slash != std::string::npos && body.compare(0, slash, s.name) == 0 && slash == s.name.size()) {
          mannequin = s.name;
          segment = body.substr(slash + 1);
          return;
        }
      mannequin.clear();
      segment = body;
    };
    sub.subscribe(
        transport::topics::kCollisionQuery,
        std::function<void(const v1::CollisionQuery&)>([&](const v1::CollisionQuery& q) {
          const std::int64_t t0 = transport::steadyNs();
          answer.Clear();
          answer.mutable_header()->set_stamp_ns(q.header().stamp_ns());
          answer.set_step(q.step());
          std::string error;
          for (const v1::MannequinConfiguration& mc : q.mannequins()) {
            MannequinSlot* slot = nullptr;
            for (auto& s : mannequins)
              if (s.name == mc.name()) slot = &s;
            if (slot == nullptr) {
              error = "unknown mannequin '" + mc.name() + "'";
              break;
            }
            if (mc.q_size() != slot->model.nq) {
              error = fmt::format("mannequin '{}': {} coordinates, expected {}", mc.name(), mc.q_size(), slot->model.nq);
              break;
            }
            skeleton::VectorX qv(slot->model.nq);
            for (int k = 0; k < slot->model.nq; ++k) qv(k) = mc.q(k);
            if (!qv.allFinite()) {
              error = "mannequin '" + mc.name() + "': non-finite configuration";
              break;
            }
            skeleton::forwardKinematics(slot->model, *slot->data, qv);
            world.updateMannequin(slot->index, *slot->data);
          }
          if (error.empty())
            for (const v1::BodyPose& b : q.bodies()) {
              const int id = world.findBody(b.body());
              if (id < 0 || world.bodyKind(id) != collision::BodyKind::kMovable) {
                error = "no movable body '" + b.body() + "'";
                break;
              }
              world.setBodyPose(id, transport::fromMsg(b.pose()));
            }
          if (!error.empty()) {
            ++errors;
            answer.set_error(error);
          } else {
            world.query(q.step(), contacts);
            for (const collision::Contact& c : contacts.contacts) {
              v1::Contact* m = answer.add_contacts();
              std::string ma, sa, mb, sb;
              split(world.bodyName(c.body_a), ma, sa);
              split(world.bodyName(c.body_b), mb, sb);
              m->set_mannequin_a(ma);
              m->set_body_a(sa);
              m->set_mannequin_b(mb);
              m->set_body_b(sb);
              transport::toMsg(c.point_a, *m->mutable_point_a());
              transport::toMsg(c.point_b, *m->mutable_point_b());
              transport::toMsg(c.normal, *m->mutable_normal());
              m->set_distance(c.distance);
              transport::toMsg(world.bodyPose(c.body_a).act(c.point_a), *m->mutable_point_a_world());
              transport::toMsg(world.bodyPose(c.body_b).act(c.point_b), *m->mutable_point_b_world());
            }
            contacts_total += contacts.contacts.size();
          }
          const double ms = (transport::steadyNs() - t0) * 1e-6;
          answer.set_compute_time_s(ms * 1e-3);
          worst_ms = std::max(worst_ms, ms);
          pub.publish(transport::topics::kCollisionContacts, answer);
          ++queries;
          health.loopIteration();
        }),
        transport::validateCollisionQuery);
    spdlog::info("{}: {} bodies ({} mannequins), activation distance {} m; contacts on {}, queries from {}", name,
                 world.bodyCount(), mannequins.size(), world.activationDistance(), fmt::join(pub.boundEndpoints(), ", "),
                 fmt::join(connect, ", "));
    health.setState(v1::SERVICE_STATE_RUNNING);
    health.tick(true);
    const std::int64_t start = transport::steadyNs();
    while (!stop.load()) {
      if (common.duration > 0 && (transport::steadyNs() - start) * 1e-9 >= common.duration) break;
      pub.poll();
      sub.poll(std::chrono::milliseconds(10));
      health.setStat("queries", static_cast<double>(queries));
      health.setStat("query_errors", static_cast<double>(errors));
      health.setStat("contacts_last", static_cast<double>(answer.contacts_size()));
      health.setStat("worst_query_ms", worst_ms);
      if (health.tick()) worst_ms = 0;
    }
    health.setState(v1::SERVICE_STATE_STOPPING);
    health.tick(true);
    spdlog::info("{}: stopped after {} queries ({} errors, {} contacts in all)", name, queries, errors, contacts_total);
    return 0;
  } catch (const std::exception& e) {
    spdlog::critical("{}", e.what());
    return 1;
  }
}
