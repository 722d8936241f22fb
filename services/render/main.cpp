// mannequin-render: one render node, one view (docs/render.md). A thin main over mannequin::renderservice
// on the service kit (services/common).
//   --headless: an off-screen EGL context, PNG frames into --out (deterministic: the same input gives the
//               same files); --from F.mcap renders the sim.world messages of a recording frame by frame;
//               --sheet COLS also tiles the frames into one contact sheet (DIR/sheet.png).
//   otherwise:  a GLFW window (needs a display); --from plays the recording at its own pace, looping.
//   --connect:  the live sim.world of publishers (newest state; headless: a frame per new state).
//               A wall view with `head_body` takes its eye from that rigid body of mocap.frame (same endpoints).
//   sync: true (view file): live nodes (headless or windows) swap in lockstep (renderservice/swap_barrier.hpp).
//   --publish:  a node of a deployment (mannequin-launch passes --name, --publish, --connect): heartbeats
//               (health.heartbeat) on that endpoint, like every service.
#include <spdlog/spdlog.h>

#include "mannequin/core/main.hpp"
#include "mannequin/core/paths.hpp"
#include "mannequin/renderservice/render_node.hpp"
#include "mannequin/service/runtime.hpp"

using namespace mannequin;

int main(int argc, char** argv) {
  service::Cli cli{"mannequin-render: one render node: draws the mannequins, the scene, objects, contacts and force\n"
                   "arrows of sim.world for one view (desktop orbit camera or a VR wall's off-axis frustum).\n"
                   "--headless renders off-screen (EGL, no display needed) into PNG frames; --from renders a\n"
                   "recording (MCAP with sim.world, e.g. from mannequin-simulate --out or mannequin-record).",
                   service::ConfigFile::kNone};
  service::CommonOptions& common = cli.options;
  renderservice::NodeOptions o;
  CLI::App& app = cli.app;
  app.add_option("--view", o.view, "view file (configs/views/*.yaml)")->capture_default_str();
  app.add_option("--sim", o.sim, "sim config whose scene and mannequin models to draw (configs/sim/*.yaml)");
  app.add_option("--scene", o.scene, "scene file (configs/scenes/*.yaml); overrides the sim config's");
  app.add_option("--from", o.from, "render the sim.world messages of this MCAP recording")->excludes(app.get_option("--connect"));
  app.add_flag("--overlay", o.overlay,
               "draw the text line: sim.world step and time (recording), or step, render fps and sim lateness (live)");
  app.add_flag("--headless", o.headless, "render off-screen into PNG frames (needs --out)");
  app.add_option("--size", o.size, "headless image size WIDTHxHEIGHT (default: the view's size)")
      ->check([](const std::string& s) {
        try {
          (void)render::parseSize(s);
          return std::string();
        } catch (const std::exception& e) {
          return std::string(e.what());
        }
      });
  app.add_option("--out", o.out, "directory of the PNG frames (frame_NNNNNN.png, N = message index)");
  app.add_option("--every", o.every, "render every Nth message")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--frames", o.frames, "write at most K frames (0: all); a window closes after K frames")->check(CLI::NonNegativeNumber);
  app.add_option("--sheet", o.sheet,
                 "headless: also tile the frames into DIR/sheet.png, COLS per row, 4 px white gaps (needs --frames K, K <= 64)")
      ->check(CLI::PositiveNumber);
  // the kit's options, described for a render node
  app.get_option("--name")->description(
      "node name (heartbeats, render.sync; default render; mannequin-launch passes the service name)");
  app.get_option("--publish")->description(
      "publish heartbeats (and render.sync) on this endpoint (repeatable; mannequin-launch passes the service's endpoint)");
  app.get_option("--connect")->description("render the live sim.world of this publisher (e.g. tcp://127.0.0.1:5556; repeatable)");
  app.get_option("--duration")->description("live: stop after S seconds (0: at --frames or SIGINT/SIGTERM)");
  app.get_option("--security")->description(
      "YAML file with a 'security' section: CURVE keys of the node's publisher and subscriber (docs/cluster.md; "
      "mannequin-launch writes one per service of a deployment with security)");
  return cli.run(argc, argv, [&](const std::atomic<bool>& stop) {
    render::ViewConfig view;
    render::SceneAssets assets;
    service::Endpoints endpoints;
    try {
      view = render::loadView(core::findData(o.view));
      assets = renderservice::loadAssets(o.sim, o.scene);
      endpoints = service::resolveEndpoints(common, service::loadConfig(common), "render", service::Publish::kOptional);
    } catch (const core::ConfigError& e) {
      spdlog::error("{}", e.what());
      return core::kExitUsage;
    }
    zmq::context_t context(common.io_threads);
    renderservice::RenderNode node(o, std::move(view), std::move(assets), std::move(endpoints), context, common.heartbeat_period);
    return node.run(stop, common.duration);
  });
}
