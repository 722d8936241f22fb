// mannequin-collision: answers collision.query with collision.contacts (mannequin::collisionservice).
#include "mannequin/collisionservice/collision_service.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  service::Cli cli{"mannequin-collision: the collision world (scene + mannequin segment capsules) answering\n"
                   "collision.query (step number, mannequin configurations, object poses) with collision.contacts\n"
                   "(witness points in body and world frames, normals, signed distances), one answer per query."};
  return cli.run(argc, argv, [&](const std::atomic<bool>& stop) {
    const core::ConfigNode config = service::loadConfig(cli.options);
    const collisionservice::CollisionServiceConfig c = collisionservice::parseCollisionConfig(config);
    zmq::context_t context(cli.options.io_threads);
    collisionservice::CollisionService service(c, service::resolveEndpoints(cli.options, config, "collision"), context,
                                               cli.options.heartbeat_period);
    return service.run(stop, cli.options.duration);
  });
}
