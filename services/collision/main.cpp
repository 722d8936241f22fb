// mannequin-collision: answers collision.query with collision.contacts (mannequin::collisionservice).
#include "mannequin/collisionservice/collision_service.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  CLI::App app{"mannequin-collision: the collision world (scene + mannequin segment capsules) answering\n"
               "collision.query (step number, mannequin configurations, object poses) with collision.contacts\n"
               "(witness points in body and world frames, normals, signed distances), one answer per query."};
  service::CommonOptions common;
  service::addCommonOptions(app, common);
  return service::runService(app, common, argc, argv, [&](const std::atomic<bool>& stop) {
    const core::ConfigNode config = service::loadConfig(common);
    const collisionservice::CollisionServiceConfig c = collisionservice::parseCollisionConfig(config);
    zmq::context_t context;
    collisionservice::CollisionService service(c, service::resolveEndpoints(common, config, "collision"), context,
                                               common.heartbeat_period);
    return service.run(stop, common.duration);
  });
}
