// mannequin-render: one render node, one view (docs/render.md). A thin main over mannequin::render.
//   --headless: an off-screen EGL context, PNG frames into --out (deterministic: the same input gives the
//               same files); --from F.mcap renders the sim.world messages of a recording frame by frame;
//               --sheet COLS also tiles the frames into one contact sheet (DIR/sheet.png).
//   otherwise:  a GLFW window (needs a display); --from plays the recording at its own pace, looping.
//   --connect:  the live sim.world of publishers (newest state; headless: a frame per new state).
//               A wall view with `head_body` takes its eye from that rigid body of mocap.frame (same endpoints).
//   sync: true (view file): live nodes (headless or windows) swap in lockstep (swap_barrier.hpp).
//   --publish:  a node of a deployment (mannequin-launch passes --name, --publish, --connect): heartbeats
//               (health.heartbeat) on that endpoint, like every service.
#include <GLFW/glfw3.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <thread>

#include <spdlog/spdlog.h>

#include "mannequin/core/clock.hpp"
#include "mannequin/core/config.hpp"
#include "mannequin/core/main.hpp"
#include "mannequin/core/paths.hpp"
#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/render/overlay.hpp"
#include "mannequin/render/renderer.hpp"
#include "mannequin/render/view.hpp"
#include "mannequin/service/runtime.hpp"
#include "mannequin/simservice/config.hpp"
#include "mannequin/transport/health.hpp"
#include "mannequin/transport/publisher.hpp"
#include "mannequin/transport/subscriber.hpp"
#include "mannequin/transport/topics.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/v1/world.pb.h"
#include "swap_barrier.hpp"

using namespace mannequin;
namespace fs = std::filesystem;

namespace {

constexpr const char* kWorldTopic = "sim.world";

struct Options {
  std::string view = "configs/views/desktop.yaml";
  std::string sim, scene, from, out, size;
  std::vector<std::string> connect;  // live sim.world publishers
  std::string name = "render";       // --name: heartbeat name (the launcher passes the service name)
  std::vector<std::string> publish;  // --publish: where heartbeats go (the launcher passes the endpoint)
  std::string security;              // --security FILE: CURVE keys (a `security` section; the launcher writes one)
  service::Security curve;           // its keys (unset: plaintext)
  double duration = 0;               // live: s of wall time (0: until SIGINT/SIGTERM or --frames)
  bool headless = false;
  bool overlay = false;  // --overlay: the text line (frame, render fps, sim lateness)
  int every = 1;
  long long frames = 0;  // 0: all
  int sheet = 0;         // --sheet COLS: the frames also tiled into DIR/sheet.png, COLS per row (0: no sheet)
};

constexpr long long kMaxSheetFrames = 64;  // a contact sheet holds every frame in memory

/// The node on the network: the ZeroMQ context of its sockets and, with --publish (a node of a deployment),
/// its publisher and heartbeats (state RUNNING while it draws, frames counted in the loop rate).
class NodeLink {
 public:
  explicit NodeLink(const Options& o) {
    if (o.publish.empty()) return;
    transport::PublisherOptions po{o.name, o.publish};
    po.curve = o.curve.server;
    pub_ = std::make_unique<transport::Publisher>(context_, po);
    health_ = std::make_unique<transport::HealthReporter>(*pub_, o.name);
    health_->setState(v1::SERVICE_STATE_RUNNING);
    health_->tick(true);
  }
  ~NodeLink() {
    if (!health_) return;
    health_->setState(v1::SERVICE_STATE_STOPPING);
    health_->tick(true);
  }
  NodeLink(const NodeLink&) = delete;
  NodeLink& operator=(const NodeLink&) = delete;
  /// Once per loop iteration (a frame drawn or a wait): subscriptions, heartbeat when due.
  void service(long long frames) {
    if (!health_) return;
    health_->setStat("frames", static_cast<double>(frames));
    pub_->poll();
    health_->tick();
  }
  void frameDrawn() {
    if (health_) health_->loopIteration();
  }
  zmq::context_t& context() { return context_; }
  transport::Publisher* publisher() { return pub_.get(); }

 private:
  zmq::context_t context_;
  std::unique_ptr<transport::Publisher> pub_;
  std::unique_ptr<transport::HealthReporter> health_;
};

/// The overlay's lines (render::overlayLines): the sim.world step and time; live also the render fps (frames
/// drawn per second, smoothed) and the lateness (now − the state's send time, ms); the sim's lag behind mocap,
/// the stale-contact flag and the scenario line. Recordings show no fps nor lateness, so their frames stay
/// deterministic.
class OverlayText {
 public:
  std::vector<render::OverlayLine> line(const v1::WorldState& ws, bool live) {
    if (!live) return render::overlayLines(ws, nullptr);
    const auto now = std::chrono::steady_clock::now();
    if (last_) {
      const double dt = std::chrono::duration<double>(now - *last_).count();
      if (dt > 0) fps_ = fps_ <= 0 ? 1.0 / dt : 0.9 * fps_ + 0.1 / dt;
    }
    last_ = now;
    const std::int64_t sent = ws.header().send_time_ns();
    const render::OverlayLive stats{fps_, sent > 0 ? static_cast<double>(core::wallNs() - sent) * 1e-6 : 0.0};
    return render::overlayLines(ws, &stats);
  }
  /// In every eye's part of the image (a stereo wall: the same text in both halves, on the screen plane).
  static void draw(render::Renderer& r, const std::vector<render::OverlayLine>& lines,
                   const std::vector<render::EyeView>& eyes, int h) {
    for (const auto& [segments, colour] : render::layoutOverlay(lines, h))
      for (const render::EyeView& e : eyes) r.drawOverlay(segments, e.x, e.width, h, colour);
  }

 private:
  std::optional<std::chrono::steady_clock::time_point> last_;
  double fps_ = 0;
};

/// Geometry: the sim config's scene and mannequins, or --scene; models not named there are looked up as
/// configs/mannequins/<model>.yaml (the model name is the config's `name`).
render::SceneAssets loadAssets(const Options& o) {
  render::SceneAssets a;
  if (!o.sim.empty()) {
    const simservice::SimServiceConfig cfg = simservice::loadSimConfig(core::findData(o.sim));
    if (cfg.world.physics.enabled) a.scene = cfg.world.physics.scene;
    for (const auto& m : cfg.mannequins) a.addModel(m.name, skeleton::buildMannequin(skeleton::loadMannequinSpec(m.config)));
  }
  if (!o.scene.empty()) a.scene = collision::loadScene(core::findData(o.scene));
  return a;
}

void addMissingModels(const v1::WorldState& ws, render::SceneAssets& assets, std::set<std::string>& tried) {
  for (const v1::MannequinState& m : ws.mannequins()) {
    if (assets.capsules.count(m.name()) || assets.capsules.count(m.model()) || !tried.insert(m.model()).second) continue;
    try {
      const std::string path = core::findData("configs/mannequins/" + m.model() + ".yaml");
      assets.addModel(m.model(), skeleton::buildMannequin(skeleton::loadMannequinSpec(path)));
      spdlog::info("mannequin '{}': model '{}' from {}", m.name(), m.model(), path);
    } catch (const std::exception& e) {
      spdlog::warn("mannequin '{}': no model '{}' ({}); drawn as spheres (pass --sim)", m.name(), m.model(), e.what());
    }
  }
}

/// What a frame draws of `ws`: its scene with the hidden layers removed.
render::RenderScene sceneOf(const v1::WorldState& ws, const render::SceneAssets& assets, const render::ViewConfig& view,
                            const render::RenderLayers& layers) {
  render::RenderScene s = render::buildScene(ws, assets, view.style);
  render::applyLayers(s, layers);
  return s;
}

/// `view` with its orbit camera's target on the followed mannequin (desktop views with `follow`, or `follow`
/// given: the window's key F), shifted by the user's pan since the start (`orbit` − the view's own).
render::ViewConfig followedView(const render::ViewConfig& view, const render::OrbitCamera& orbit, const v1::WorldState* ws,
                                const std::string& follow) {
  render::ViewConfig v = view;
  v.orbit = orbit;
  if (ws == nullptr || follow.empty() || view.type != render::ViewConfig::Type::kDesktop) return v;
  v.orbit = render::followed(orbit, *ws, follow, (orbit.target - view.orbit.target).head<2>());
  return v;
}

/// Every sim.world message of a recording, in log-time order.
std::vector<v1::WorldState> readRecording(const std::string& path) {
  const recording::McapReader reader = recording::McapReader::open(path);
  recording::ReadFilter filter;
  filter.topics = {kWorldTopic};
  (void)reader.channelsOf(filter.topics);  // throws listing the file's topics when it has no sim.world
  std::vector<v1::WorldState> out;
  recording::MessageCursor cursor = reader.messages(filter);
  recording::Message msg;
  while (cursor.next(msg)) {
    v1::WorldState ws;
    if (!ws.ParseFromString(msg.data))
      throw std::runtime_error(path + ": sim.world message " + std::to_string(out.size()) + " is not a WorldState");
    out.push_back(std::move(ws));
  }
  return out;
}

/// The newest sim.world of the publishers in `o.connect` (kLatest: a backlog is skipped; the publisher
/// re-sends its last state to a late subscriber, so a node shows the current scene at once).
class LiveWorld {
 public:
  LiveWorld(zmq::context_t& context, const std::vector<std::string>& endpoints, const render::ViewConfig& view,
            const std::optional<transport::CurveClientOptions>& curve)
      : sub_(context, transport::SubscriberOptions{"render", endpoints, 1000, 10000, curve}) {
    if (view.sync) {
      // the swap barrier shows the leader's step: every state is kept (queue delivery), the last kRing by step
      static constexpr transport::Topic<v1::WorldState> kWorldQueued{transport::topics::kSimWorld.name,
                                                                      transport::Delivery::kQueue};
      sub_.subscribe(kWorldQueued, [this](const v1::WorldState& ws) {
        latest_ = ws;
        ++received_;
        ring_[ws.step()] = ws;
        if (ring_.size() > kRing) ring_.erase(ring_.begin());
      });
    } else {
      sub_.subscribe(transport::topics::kSimWorld, [this](const v1::WorldState& ws) {
        latest_ = ws;
        ++received_;
      });
    }
    if (!view.head_body.empty())  // a wall with a tracked head: its eye follows that rigid body of mocap.frame
      sub_.subscribe(transport::topics::kMocapFrame, [this, &view](const v1::MocapFrame& f) {
        if (const auto h = render::trackedHead(f, view)) head_ = h;
      });
  }
  /// The camera(s) of `view` (ViewConfig::eyes: one, or a stereo wall's two) with the tracked head when
  /// there is one; a head that left the room (an eye behind the wall) keeps the last usable cameras.
  const std::vector<render::EyeView>& eyes(const render::ViewConfig& view, int w, int h) {
    render::ViewConfig v = view;
    if (head_) v.head = *head_;
    try {
      eyes_ = v.eyes(w, h);
    } catch (const std::invalid_argument& e) {
      if (eyes_.empty() || eyes_.back().x + eyes_.back().width != w) eyes_ = view.eyes(w, h);
    }
    return eyes_;
  }
  /// Waits up to `timeout` for traffic; true when a newer state than the last call's arrived.
  bool poll(std::chrono::microseconds timeout) {
    sub_.poll(timeout);
    const bool fresh = received_ != seen_;
    seen_ = received_;
    return fresh;
  }
  const v1::WorldState& latest() const { return latest_; }
  long long received() const { return received_; }
  transport::Subscriber& subscriber() { return sub_; }
  /// Sync mode: the newest step received (0: none yet).
  std::uint64_t newestStep() const { return ring_.empty() ? 0 : ring_.rbegin()->first; }
  /// Sync mode: the state of step `step`, or (missed: dropped upstream or out of the ring) the newest one
  /// before it, else the oldest kept; nullptr when nothing arrived.
  const v1::WorldState* stateAt(std::uint64_t step) const {
    if (ring_.empty()) return nullptr;
    auto it = ring_.upper_bound(step);
    if (it == ring_.begin()) return &it->second;
    return &std::prev(it)->second;
  }

 private:
  static constexpr std::size_t kRing = 512;
  std::map<std::uint64_t, v1::WorldState> ring_;
  transport::Subscriber sub_;
  v1::WorldState latest_;
  long long received_ = 0, seen_ = 0;
  std::optional<render::Vec3> head_;
  std::vector<render::EyeView> eyes_;
};

/// Synchronised nodes: the step to draw next (the leader's newest state, or as a follower the leader's
/// post), or nullopt when there is none yet this turn (waited a little; call again). The state is in
/// live.stateAt(step) (a missed step gives the newest before it, with a warning).
std::optional<std::uint64_t> syncPick(render_node::SwapBarrier& barrier, LiveWorld& live, std::uint64_t last,
                                      double timeout_s, const std::function<bool()>& over) {
  std::uint64_t step = 0;
  if (barrier.isLeader()) {
    live.poll(std::chrono::milliseconds(5));
    if (live.newestStep() <= last) {
      barrier.keepAlive(last);
      return std::nullopt;
    }
    step = live.newestStep();
  } else {
    const auto f = barrier.awaitLeader(last, [&] { return live.newestStep() > last; });
    if (!f) return std::nullopt;
    step = *f;
    // the leader's state normally arrived already (same publisher); wait for it up to the timeout
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (live.newestStep() < step && std::chrono::steady_clock::now() < until && !over())
      live.poll(std::chrono::milliseconds(2));
  }
  const v1::WorldState* ws = live.stateAt(step);
  if (ws == nullptr) return std::nullopt;
  if (ws->step() != step) spdlog::warn("swap barrier: step {} missed here; drawing step {}", step, ws->step());
  return step;
}

int runHeadless(const Options& o, const render::ViewConfig& view, render::SceneAssets& assets, NodeLink& link) {
  int w = view.width, h = view.height;
  if (!o.size.empty()) {
    const auto s = render::parseSize(o.size);
    w = s[0];
    h = s[1];
  }
  if (o.out.empty()) {
    spdlog::error("--headless needs --out DIR (where the PNG frames go)");
    return core::kExitUsage;
  }
  if (o.sheet > 0 && (o.frames < 1 || o.frames > kMaxSheetFrames)) {
    spdlog::error("--sheet needs --frames K with 1 <= K <= {} (the sheet's frames are kept in memory); got --frames {}", kMaxSheetFrames, o.frames);
    return core::kExitUsage;
  }
  fs::create_directories(o.out);
  render::HeadlessContext ctx(w, h);
  render::Renderer renderer;
  spdlog::info("headless {}x{} on {}", w, h, render::Renderer::describeContext());
  render::RenderLayers layers = view.layers;
  if (o.overlay) layers.overlay = true;
  // the camera of a state: the view's, with a desktop `follow` its target on the followed mannequin
  const auto cameraOf = [&](const v1::WorldState* ws) { return followedView(view, view.orbit, ws, view.follow).eyes(w, h); };
  std::set<std::string> tried;
  long long written = 0;
  std::vector<render::Image> sheet;
  OverlayText overlay;
  const auto emit = [&](const render::RenderScene& scene, const std::vector<render::EyeView>& eyes, std::size_t index,
                        const v1::WorldState* ws, bool live) {
    renderer.draw(scene, eyes, h, view.background);
    if (layers.overlay && ws != nullptr) OverlayText::draw(renderer, overlay.line(*ws, live), eyes, h);
    char name[64];
    std::snprintf(name, sizeof name, "frame_%06zu.png", index);
    const render::Image image = ctx.read();
    render::writePng((fs::path(o.out) / name).string(), image);
    if (o.sheet > 0) sheet.push_back(image);
    ++written;
    link.frameDrawn();
    link.service(written);
  };
  if (!o.connect.empty() && view.sync) {
    // live, synchronised: the swap barrier picks the step (the leader's newest); frames are named by that
    // step and each swap is logged in DIR/swaps.log ("step steady_ns"), so nodes can be compared
    if (link.publisher() == nullptr) {
      spdlog::error("{}: sync: true needs --publish ENDPOINT (the node's render.sync; mannequin-launch passes it)", view.source);
      return core::kExitUsage;
    }
    LiveWorld live(link.context(), o.connect, view, o.curve.client);
    const auto& stop = core::installStopSignals();
    const auto start = std::chrono::steady_clock::now();
    const auto over = [&] {
      return stop.load() || (o.frames > 0 && written >= o.frames) ||
             (o.duration > 0 && std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= o.duration);
    };
    render_node::SwapBarrier barrier(
        *link.publisher(), o.name, view.sync_timeout, [&](std::chrono::microseconds t) { live.poll(t); }, over);
    live.subscriber().subscribe(transport::topics::kRenderSync, [&](const v1::RenderSync& m) { barrier.onMessage(m); });
    std::ofstream log(fs::path(o.out) / "swaps.log");
    barrier.greet();
    std::uint64_t last = 0;
    while (!over()) {
      link.service(written);
      const auto picked = syncPick(barrier, live, last, view.sync_timeout, over);
      if (!picked) continue;
      const std::uint64_t step = *picked;
      const v1::WorldState* ws = live.stateAt(step);
      addMissingModels(*ws, assets, tried);
      const auto& eyes = live.eyes(followedView(view, view.orbit, ws, view.follow), w, h);
      renderer.draw(sceneOf(*ws, assets, view, layers), eyes, h, view.background);
      if (layers.overlay) OverlayText::draw(renderer, overlay.line(*ws, true), eyes, h);
      const render::Image img = ctx.read();
      barrier.arriveAndWait(step);
      // the swap: the frame goes out now
      char name[64];
      std::snprintf(name, sizeof name, "frame_%06llu.png", static_cast<unsigned long long>(step));
      render::writePng((fs::path(o.out) / name).string(), img, render::PngSpeed::kFast);
      log << step << ' ' << std::chrono::steady_clock::now().time_since_epoch().count() << '\n' << std::flush;
      ++written;
      link.frameDrawn();
      last = step;
    }
    spdlog::info("swap barrier: {} peers at the end, {} drops", barrier.peers(), barrier.dropped());
  } else if (!o.connect.empty()) {
    // live: a frame per new state (every Nth), named by its arrival count, until --frames, --duration or a signal
    LiveWorld live(link.context(), o.connect, view, o.curve.client);
    const auto& stop = core::installStopSignals();
    const auto start = std::chrono::steady_clock::now();
    long long states = 0;
    while (!stop.load() && (o.frames <= 0 || written < o.frames) &&
           (o.duration <= 0 || std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < o.duration)) {
      link.service(written);
      if (!live.poll(std::chrono::milliseconds(100))) continue;
      const long long index = states++;
      if (index % o.every != 0) continue;
      addMissingModels(live.latest(), assets, tried);
      emit(sceneOf(live.latest(), assets, view, layers),
           live.eyes(followedView(view, view.orbit, &live.latest(), view.follow), w, h), static_cast<std::size_t>(index),
           &live.latest(), true);
    }
  } else if (o.from.empty()) {
    // neither a recording nor publishers: the static scene, once
    render::RenderScene still = render::buildStaticScene(assets, view.style);
    render::applyLayers(still, layers);
    emit(still, cameraOf(nullptr), 0, nullptr, false);
  } else {
    const std::vector<v1::WorldState> states = readRecording(o.from);
    if (states.empty()) {
      spdlog::error("{}: no sim.world messages", o.from);
      return core::kExitFailure;
    }
    for (std::size_t i = 0; i < states.size(); i += static_cast<std::size_t>(o.every)) {
      if (o.frames > 0 && written >= o.frames) break;
      addMissingModels(states[i], assets, tried);
      emit(sceneOf(states[i], assets, view, layers), cameraOf(&states[i]), i, &states[i], false);
    }
  }
  std::printf("wrote %lld frames (%dx%d) to %s\n", written, w, h, o.out.c_str());
  if (!sheet.empty()) {
    const render::Image tiled = render::tile(sheet, o.sheet, 4, {255, 255, 255});
    const std::string path = (fs::path(o.out) / "sheet.png").string();
    render::writePng(path, tiled);
    std::printf("wrote the contact sheet of %zu frames (%dx%d) to %s\n", sheet.size(), tiled.width, tiled.height, path.c_str());
  }
  return core::kExitOk;
}

/// A window's input state (mouse: orbit, pan, zoom; keys: docs/render.md "Keys").
struct Input {
  render::OrbitCamera* orbit = nullptr;
  const render::ViewConfig* view = nullptr;
  double x = 0, y = 0;
  bool left = false, right = false;
  render::RenderLayers layers;  // 1..7 toggle
  std::string follow;           // F toggles between "" and the view's `follow` (or mannequin 0)
  bool paused = false;          // P: the drawn state is frozen
};

void onKey(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS) return;
  auto* in = static_cast<Input*>(glfwGetWindowUserPointer(w));
  if (key >= GLFW_KEY_1 && key < GLFW_KEY_1 + render::RenderLayers::kCount) {
    const int i = key - GLFW_KEY_1;
    in->layers.flag(i) = !in->layers.flag(i);
    spdlog::info("layer {} {}", render::RenderLayers::names()[static_cast<std::size_t>(i)], in->layers.flag(i) ? "on" : "off");
  } else if (key == GLFW_KEY_F && in->view->type == render::ViewConfig::Type::kDesktop) {
    in->follow = in->follow.empty() ? (in->view->follow.empty() ? std::string("0") : in->view->follow) : std::string();
    spdlog::info("follow {}", in->follow.empty() ? "off" : in->follow);
  } else if (key == GLFW_KEY_P) {
    in->paused = !in->paused;
    spdlog::info("{}", in->paused ? "paused" : "running");
  } else if (key == GLFW_KEY_R) {
    *in->orbit = in->view->orbit;
  }
}

int runWindow(const Options& o, const render::ViewConfig& view, render::SceneAssets& assets, NodeLink& link) {
  const char* x11 = std::getenv("DISPLAY");
  const char* wl = std::getenv("WAYLAND_DISPLAY");
  if ((x11 == nullptr || *x11 == '\0') && (wl == nullptr || *wl == '\0')) {
    spdlog::error("no display (DISPLAY and WAYLAND_DISPLAY are not set): use --headless --out DIR to render PNG "
                  "frames off-screen");
    return core::kExitUsage;
  }
  if (glfwInit() != GLFW_TRUE) {
    spdlog::error("cannot open the display '{}' (glfwInit failed): use --headless --out DIR to render PNG frames "
                  "off-screen", x11 ? x11 : wl);
    return core::kExitUsage;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  GLFWwindow* win = glfwCreateWindow(view.width, view.height, ("mannequin-render: " + view.name).c_str(), nullptr, nullptr);
  if (win == nullptr) {
    glfwTerminate();
    spdlog::error("cannot create an OpenGL 3.3 core window: use --headless --out DIR");
    return core::kExitUsage;
  }
  glfwMakeContextCurrent(win);
  glfwSwapInterval(1);
  if (view.sync && (o.connect.empty() || link.publisher() == nullptr)) {
    glfwDestroyWindow(win);
    glfwTerminate();
    spdlog::error("{}: sync: true needs --connect (live) and --publish ENDPOINT (the node's render.sync)", view.source);
    return core::kExitUsage;
  }
  std::vector<v1::WorldState> states;
  if (!o.from.empty()) states = readRecording(o.from);
  std::unique_ptr<LiveWorld> live;
  if (!o.connect.empty()) live = std::make_unique<LiveWorld>(link.context(), o.connect, view, o.curve.client);
  std::set<std::string> tried;
  int rc = core::kExitOk;
  {
    render::Renderer renderer;
    spdlog::info("window {}x{} on {}", view.width, view.height, render::Renderer::describeContext());
    render::OrbitCamera orbit = view.orbit;
    Input mouse;
    mouse.orbit = &orbit;
    mouse.view = &view;
    mouse.layers = view.layers;
    if (o.overlay) mouse.layers.overlay = true;
    mouse.follow = view.follow;
    glfwSetWindowUserPointer(win, &mouse);
    glfwSetKeyCallback(win, onKey);
    if (view.type == render::ViewConfig::Type::kDesktop) {
      glfwSetMouseButtonCallback(win, [](GLFWwindow* w, int button, int action, int) {
        auto* m = static_cast<Input*>(glfwGetWindowUserPointer(w));
        if (button == GLFW_MOUSE_BUTTON_LEFT) m->left = action == GLFW_PRESS;
        if (button == GLFW_MOUSE_BUTTON_RIGHT) m->right = action == GLFW_PRESS;
      });
      glfwSetCursorPosCallback(win, [](GLFWwindow* w, double x, double y) {
        auto* m = static_cast<Input*>(glfwGetWindowUserPointer(w));
        if (m->left) m->orbit->rotate(-0.01 * (x - m->x), 0.01 * (y - m->y));
        if (m->right) m->orbit->pan(-0.002 * m->orbit->distance * (x - m->x), 0.002 * m->orbit->distance * (y - m->y));
        m->x = x;
        m->y = y;
      });
      glfwSetScrollCallback(win, [](GLFWwindow* w, double, double dy) {
        static_cast<Input*>(glfwGetWindowUserPointer(w))->orbit->zoom(std::pow(0.9, dy));
      });
    }
    const auto start = std::chrono::steady_clock::now();
    const auto& stop = core::installStopSignals();
    const render::RenderScene still_all = render::buildStaticScene(assets, view.style);
    long long swapped = 0;
    OverlayText overlay;
    if (view.sync) {
      // synchronised: draw the barrier's step, swap once every live peer drew it (swaps.log in --out if given)
      const auto over = [&] {
        return glfwWindowShouldClose(win) || stop.load() || (o.frames > 0 && swapped >= o.frames) ||
               (o.duration > 0 && std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= o.duration);
      };
      render_node::SwapBarrier barrier(
          *link.publisher(), o.name, view.sync_timeout,
          [&](std::chrono::microseconds t) {
            live->poll(t);
            glfwPollEvents();
          },
          over);
      live->subscriber().subscribe(transport::topics::kRenderSync, [&](const v1::RenderSync& m) { barrier.onMessage(m); });
      std::ofstream log;
      if (!o.out.empty()) {
        fs::create_directories(o.out);
        log.open(fs::path(o.out) / "swaps.log");
      }
      barrier.greet();
      std::uint64_t last = 0;
      while (!over()) {
        link.service(swapped);
        glfwPollEvents();
        const auto picked = syncPick(barrier, *live, last, view.sync_timeout, over);
        if (!picked) continue;
        const v1::WorldState* ws = live->stateAt(*picked);
        int w = 0, h = 0;
        glfwGetFramebufferSize(win, &w, &h);
        addMissingModels(*ws, assets, tried);
        const auto& eyes = live->eyes(followedView(view, orbit, ws, mouse.follow), w, h);
        renderer.draw(sceneOf(*ws, assets, view, mouse.layers), eyes, h, view.background);
        if (mouse.layers.overlay) OverlayText::draw(renderer, overlay.line(*ws, true), eyes, h);
        glFinish();
        barrier.arriveAndWait(*picked);
        glfwSwapBuffers(win);
        if (log.is_open()) log << *picked << ' ' << std::chrono::steady_clock::now().time_since_epoch().count() << '\n' << std::flush;
        ++swapped;
        link.frameDrawn();
        last = *picked;
      }
    }
    std::optional<v1::WorldState> held;  // P: the state frozen on the screen
    bool held_live = false;
    while (!view.sync && !glfwWindowShouldClose(win) && !stop.load()) {
      int w = 0, h = 0;
      glfwGetFramebufferSize(win, &w, &h);
      if (live) live->poll(std::chrono::microseconds(0));
      // the state to draw: the newest live one, or the recording's at its sim time (looping); none: the scene
      const v1::WorldState* ws = nullptr;
      bool is_live = false;
      if (live) {
        if (live->received() > 0) {
          ws = &live->latest();
          is_live = true;
        }
      } else if (!states.empty()) {
        const double span = std::max(1e-9, states.back().sim_time() - states.front().sim_time());
        const double t = std::fmod(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), span) +
                         states.front().sim_time();
        std::size_t i = 0;
        while (i + 1 < states.size() && states[i + 1].sim_time() <= t) ++i;
        ws = &states[i];
      }
      if (mouse.paused && ws != nullptr) {
        if (!held) {
          held = *ws;
          held_live = is_live;
        }
        ws = &*held;
        is_live = held_live;
      } else if (!mouse.paused) {
        held.reset();
      }
      const render::ViewConfig v = followedView(view, orbit, ws, mouse.follow);
      const std::vector<render::EyeView> cam = live ? live->eyes(v, w, h) : v.eyes(w, h);
      if (ws == nullptr) {
        render::RenderScene still = still_all;
        render::applyLayers(still, mouse.layers);
        renderer.draw(still, cam, h, view.background);
      } else {
        addMissingModels(*ws, assets, tried);
        renderer.draw(sceneOf(*ws, assets, view, mouse.layers), cam, h, view.background);
        if (mouse.layers.overlay) OverlayText::draw(renderer, overlay.line(*ws, is_live), cam, h);
      }
      glfwSwapBuffers(win);
      glfwPollEvents();
      ++swapped;
      link.frameDrawn();
      link.service(swapped);
      if (o.frames > 0 && swapped >= o.frames) break;
    }
  }
  glfwDestroyWindow(win);
  glfwTerminate();
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mannequin-render: one render node: draws the mannequins, the scene, objects, contacts and force\n"
               "arrows of sim.world for one view (desktop orbit camera or a VR wall's off-axis frustum).\n"
               "--headless renders off-screen (EGL, no display needed) into PNG frames; --from renders a\n"
               "recording (MCAP with sim.world, e.g. from mannequin-simulate --out or mannequin-record)."};
  Options o;
  std::string log_level = "info";
  app.add_option("--view", o.view, "view file (configs/views/*.yaml)")->capture_default_str();
  app.add_option("--sim", o.sim, "sim config whose scene and mannequin models to draw (configs/sim/*.yaml)");
  app.add_option("--scene", o.scene, "scene file (configs/scenes/*.yaml); overrides the sim config's");
  auto* connect = app.add_option("--connect", o.connect,
                                 "render the live sim.world of this publisher (e.g. tcp://127.0.0.1:5556; repeatable)");
  app.add_option("--duration", o.duration, "live: stop after S seconds (0: at --frames or SIGINT/SIGTERM)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--from", o.from, "render the sim.world messages of this MCAP recording")->excludes(connect);
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
  app.add_option("--name", o.name, "node name (heartbeats; mannequin-launch passes the service name)")->capture_default_str();
  app.add_option("--publish", o.publish,
                 "publish heartbeats on this endpoint (repeatable; mannequin-launch passes the service's endpoint)");
  app.add_option("--security", o.security,
                 "YAML file with a 'security' section: CURVE keys of the node's publisher and subscriber (docs/cluster.md; "
                 "mannequin-launch writes one per service of a deployment with security)")
      ->check(CLI::ExistingFile);
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error, critical, off")->check(core::logLevelCheck());
  return core::runMain(app, argc, argv, [&] {
    core::setupLogging(log_level);
    render::ViewConfig view;
    render::SceneAssets assets;
    try {
      view = render::loadView(core::findData(o.view));
      assets = loadAssets(o);
      if (!o.security.empty()) o.curve = service::readSecurityFile(o.security, !o.connect.empty());
    } catch (const core::ConfigError& e) {
      spdlog::error("{}", e.what());
      return core::kExitUsage;
    }
    NodeLink link(o);
    return o.headless ? runHeadless(o, view, assets, link) : runWindow(o, view, assets, link);
  });
}
