// bench-render: one headless render node's frame time (docs/render.md). Goal (issue 14): ≥ 60 fps at
// 1280×720 with two mannequins in the cockpit scene and contact arrows, on Mesa llvmpipe.
// BM_MocapToPhoton: the mocap frame published → the first swap that shows it, through live processes
// mannequin-mocap → mannequin-sim (+ mannequin-collision) → mannequin-render (goal p99 ≤ 25 ms).
#include <benchmark/benchmark.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <GL/gl.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <thread>

#include "bench_main.hpp"
#include "mannequin/core/clock.hpp"
#include "mannequin/transport/subscriber.hpp"
#include "mannequin/transport/topics.hpp"
#include "mannequin/render/renderer.hpp"
#include "mannequin/render/view.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"
#include "mannequin/v1/world.pb.h"

namespace {

using namespace mannequin;

void setVec(const math::Vector3& p, v1::Vec3& out) {
  out.set_x(p.x());
  out.set_y(p.y());
  out.set_z(p.z());
}

// Two standing male_50th (one colour each), 8 foot contacts of 150 N each and 2 hand contacts with forces.
v1::WorldState twoMannequins(const skeleton::Model& model) {
  v1::WorldState ws;
  for (int m = 0; m < 2; ++m) {
    math::VectorX q = skeleton::standingConfiguration(model);
    q(1) += m == 0 ? -0.5 : 0.5;
    skeleton::Data d(model);
    skeleton::forwardKinematics(model, d, q);
    v1::MannequinState* ms = ws.add_mannequins();
    ms->set_name(m == 0 ? "pilot" : "copilot");
    ms->set_model(model.name);
    for (const skeleton::Segment& s : model.segments) {
      v1::NamedPose* np = ms->add_segments();
      np->set_name(s.name);
      const math::SE3& p = d.oMi[static_cast<std::size_t>(s.joint)];
      setVec(p.p, *np->mutable_pose()->mutable_position());
      const Eigen::Quaterniond qq(p.R);
      auto* o = np->mutable_pose()->mutable_orientation();
      o->set_w(qq.w()); o->set_x(qq.x()); o->set_y(qq.y()); o->set_z(qq.z());
    }
    setVec(d.com, *ms->mutable_com());
    for (int k = 0; k < 10; ++k) {
      v1::ContactPoint* c = ms->add_contacts();
      c->set_body_a("scene/floor");
      c->set_body_b(ms->name() + "/foot");
      const bool hand = k >= 8;
      setVec(math::Vector3(0.1 * (k % 2), q(1) + 0.1 * ((k / 2) % 2) - 0.05, hand ? 1.0 : 0.0), *c->mutable_point());
      setVec(math::Vector3::UnitZ(), *c->mutable_normal());
      setVec(math::Vector3(hand ? 40.0 : 0.0, 0, hand ? -60.0 : -150.0), *c->mutable_force());
      c->set_normal_force(150);
    }
  }
  return ws;
}

struct Fixture {
  Fixture(int w, int h) : ctx(w, h), model(skeleton::buildMannequin(skeleton::loadMannequinSpec(bench::dataFile("configs/mannequins/male_50th.yaml")))) {
    renderer = std::make_unique<render::Renderer>();
    assets.scene = collision::loadScene(bench::dataFile("configs/scenes/cockpit.yaml"));
    assets.addModel(model.name, model);
    ws = twoMannequins(model);
    view = render::loadView(bench::dataFile("configs/views/desktop.yaml"));
  }
  render::HeadlessContext ctx;
  skeleton::Model model;
  std::unique_ptr<render::Renderer> renderer;
  render::SceneAssets assets;
  v1::WorldState ws;
  render::ViewConfig view;
};

// CPU time of the whole process (every thread: llvmpipe's rasteriser threads too), ns.
std::int64_t processCpuNs() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<std::int64_t>(t.tv_sec) * 1'000'000'000LL + t.tv_nsec;
}

// buildScene + draw + read-back (glFinish, glReadPixels, rows flipped), what a headless node does per frame
// before writing the PNG. Counters: fps; process_cpu_ms = CPU time of all the process's threads per frame
// (the calling thread and llvmpipe's rasterisers: what the frame costs the host's cores, less sensitive to
// other load on a shared host than the wall time); draws and triangles of the last frame.
void BM_HeadlessFrame(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  Fixture f(w, h);
  const render::Camera cam = f.view.camera(w, h);
  const std::int64_t cpu0 = processCpuNs();
  for (auto _ : state) {
    const render::RenderScene scene = render::buildScene(f.ws, f.assets, f.view.style);
    f.renderer->draw(scene, cam, w, h, f.view.background);
    const render::Image img = f.ctx.read();  // includes glFinish: the frame is done
    benchmark::DoNotOptimize(img.rgb.data());
  }
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["process_cpu_ms"] = static_cast<double>(processCpuNs() - cpu0) * 1e-6 / static_cast<double>(std::max<std::int64_t>(1, state.iterations()));
  state.counters["draws"] = f.renderer->stats().draw_calls;
  state.counters["triangles"] = static_cast<double>(f.renderer->stats().triangles);
  state.SetLabel(render::Renderer::describeContext());
}
BENCHMARK(BM_HeadlessFrame)->Args({1280, 720})->Args({640, 360})->Unit(benchmark::kMillisecond)->UseRealTime();

// buildScene + draw + glFinish without the read-back: what the read-back (glReadPixels GL_RGB + row flip)
// adds to BM_HeadlessFrame is the difference.
void BM_HeadlessDrawOnly(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  Fixture f(w, h);
  const render::Camera cam = f.view.camera(w, h);
  for (auto _ : state) {
    const render::RenderScene scene = render::buildScene(f.ws, f.assets, f.view.style);
    f.renderer->draw(scene, cam, w, h, f.view.background);
    glFinish();
  }
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HeadlessDrawOnly)->Args({1280, 720})->Unit(benchmark::kMillisecond)->UseRealTime();

// writePng of the benchmark's 1280×720 frame to a temporary file: arg 0 PngSpeed::kSmall, 1 kFast
// (a live headless node writes its frame with kFast before it counts as swapped). Counter: bytes written.
void BM_WritePng(benchmark::State& state) {
  const render::PngSpeed speed = state.range(0) != 0 ? render::PngSpeed::kFast : render::PngSpeed::kSmall;
  render::Image img;
  {
    Fixture f(1280, 720);
    f.renderer->draw(render::buildScene(f.ws, f.assets, f.view.style), f.view.camera(1280, 720), 1280, 720, f.view.background);
    img = f.ctx.read();
  }
  const std::string path = (std::filesystem::temp_directory_path() / ("bench-render-" + std::to_string(::getpid()) + ".png")).string();
  for (auto _ : state) render::writePng(path, img, speed);
  state.counters["bytes"] = static_cast<double>(std::filesystem::file_size(path));
  std::filesystem::remove(path);
}
BENCHMARK(BM_WritePng)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// buildScene alone (no GL): the CPU cost of the scene model per frame.
void BM_BuildScene(benchmark::State& state) {
  Fixture f(16, 16);
  for (auto _ : state) {
    const render::RenderScene scene = render::buildScene(f.ws, f.assets, f.view.style);
    benchmark::DoNotOptimize(scene.solids.data());
  }
}
BENCHMARK(BM_BuildScene)->Unit(benchmark::kMicrosecond);

// ---- mocap-to-photon latency through live processes ------------------------------------------------------

namespace fs = std::filesystem;

// A child process (posix_spawn); stop() sends SIGTERM to a pid > 0 and waits with a deadline (SIGKILL at it).
// Its standard output goes to the benchmark's standard error: the benchmark's own standard output carries
// only its report (--benchmark_format=json, read by tools/perf-report).
class Child {
 public:
  explicit Child(std::vector<std::string> args) {
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    ::posix_spawn_file_actions_init(&actions);
    ::posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);
    if (::posix_spawnp(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid_ = 0;
    ::posix_spawn_file_actions_destroy(&actions);
    if (pid_ <= 0) throw std::runtime_error("cannot start " + args[0]);
  }
  ~Child() { stop(10); }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  /// Waits up to deadline_s for the child to exit by itself; true when it did.
  bool wait(double deadline_s) {
    if (pid_ <= 0) return true;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(deadline_s);
    do {
      int st = 0;
      const pid_t r = ::waitpid(pid_, &st, WNOHANG);
      if (r == pid_ || r < 0) {
        pid_ = 0;
        return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    } while (std::chrono::steady_clock::now() < end);
    return false;
  }
  void stop(double deadline_s) {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    if (wait(deadline_s) || pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    int st = 0;
    ::waitpid(pid_, &st, 0);
    pid_ = 0;
  }

 private:
  pid_t pid_ = 0;
};

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::min<double>(static_cast<double>(v.size() - 1), p * static_cast<double>(v.size())));
  return v[i];
}

// CLOCK_REALTIME − CLOCK_MONOTONIC (ns): Header.send_time_ns is wall time (core::wallNs), swaps.log is
// steady_clock (CLOCK_MONOTONIC, system-wide on Linux, so another process's value converts with this offset).
// The tightest of 50 bracketed reads.
std::int64_t wallMinusSteady() {
  std::int64_t best_gap = INT64_MAX, offset = 0;
  for (int i = 0; i < 50; ++i) {
    const std::int64_t s0 = core::steadyNs(), w = core::wallNs(), s1 = core::steadyNs();
    if (s1 - s0 < best_gap) {
      best_gap = s1 - s0;
      offset = w - (s0 + (s1 - s0) / 2);
    }
  }
  return offset;
}

// What the chain sends: per sim.world step, its send time and the mocap frame it used.
struct StateRef {
  std::int64_t state_sent_ns = 0;
  std::uint64_t mocap_sequence = 0;
  std::int64_t mocap_sent_ns = 0;
};

// BM_MocapToPhoton/W/H/window: starts mannequin-mocap (the demo BVH, 120 Hz), mannequin-collision,
// mannequin-sim (sim_demo, world_rate 60 Hz) and one mannequin-render node with `sync: true` (alone: it
// leads, and logs every swap as "step steady_ns" in DIR/swaps.log) for 20 s; a subscriber of our own
// records each sim.world step's FrameRef (the mocap frame it used, with that frame's send time). For every
// mocap frame that a swap shows, latency = its first swap's time − the frame's send time. window = 0:
// headless, the swap is the PNG written; window = 1: a window under xvfb-run, the swap is
// glFinish + glfwSwapBuffers (no PNG). cave = 1 (headless only): the three synchronised walls of
// configs/deployments/cave.yaml instead of one node; a step's swap time is the last of the three walls'.
// Counters in ms; the first 2 s of swaps (greeting, warm-up) are left out.
void BM_MocapToPhoton(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  const bool window = state.range(2) != 0;
  const bool cave = state.range(3) != 0;
  if (cave && window) {
    state.SkipWithError("cave = 1 is headless only");
    return;
  }
  const double run_s = 20;
  const fs::path bin = fs::read_symlink("/proc/self/exe").parent_path();
  const fs::path dir = fs::temp_directory_path() / ("bench-render-latency-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "frames");
  const std::string ipc = "ipc://" + dir.string() + "/";
  std::ofstream(dir / "view.yaml") << "type: desktop\nsync: true\n";
  if (window && std::system("command -v xvfb-run >/dev/null 2>&1") != 0) {
    state.SkipWithError("xvfb-run is not installed (tools/setup installs xvfb)");
    return;
  }
  const std::vector<std::string> names =
      cave ? std::vector<std::string>{"wall_front", "wall_left", "wall_right"} : std::vector<std::string>{"view"};
  for (auto _ : state) {
    std::map<std::uint64_t, StateRef> refs;
    std::int64_t offset0 = 0, offset1 = 0;
    {
      zmq::context_t context;
      transport::Subscriber sub(context, transport::SubscriberOptions{"bench", {ipc + "sim"}});
      static constexpr transport::Topic<v1::WorldState> kWorldQueued{transport::topics::kSimWorld.name,
                                                                      transport::Delivery::kQueue};
      sub.subscribe(kWorldQueued, [&](const v1::WorldState& ws) {
        StateRef r;
        r.state_sent_ns = ws.header().send_time_ns();
        if (ws.mocap_sources_size() > 0) {
          r.mocap_sequence = ws.mocap_sources(0).sequence();
          r.mocap_sent_ns = ws.mocap_sources(0).send_time_ns();
        }
        refs[ws.step()] = r;
      });
      const std::string log = "warn";
      Child mocap({(bin / "mannequin-mocap").string(), "--config", bench::dataFile("configs/sim/mocap_demo.yaml"), "--name", "mocap",
                   "--publish", ipc + "mocap", "--log-level", log});
      Child collision({(bin / "mannequin-collision").string(), "--config", bench::dataFile("configs/sim/collision_demo.yaml"),
                       "--name", "collision", "--publish", ipc + "collision", "--connect", ipc + "sim", "--log-level", log});
      Child sim({(bin / "mannequin-sim").string(), "--config", bench::dataFile("configs/sim/sim_demo.yaml"), "--name", "sim",
                 "--publish", ipc + "sim", "--connect", ipc + "mocap", "--connect", ipc + "collision", "--log-level", log});
      // a window takes the view's size: pass it through a view file of that size
      if (window) std::ofstream(dir / "view.yaml") << "type: desktop\nsync: true\nsize: [" << w << ", " << h << "]\n";
      offset0 = wallMinusSteady();
      std::vector<std::unique_ptr<Child>> nodes;
      for (const std::string& name : names) {
        const std::string view = cave ? bench::dataFile("configs/deployments/cave/" + name + ".yaml") : (dir / "view.yaml").string();
        std::vector<std::string> render{(bin / "mannequin-render").string(), "--view", view, "--sim",
                                        bench::dataFile("configs/sim/sim_demo.yaml"), "--name", name, "--publish", ipc + name,
                                        "--connect", ipc + "sim", "--out", (dir / "frames" / name).string(), "--duration",
                                        std::to_string(run_s), "--log-level", log};
        for (const std::string& peer : names)
          if (peer != name) render.insert(render.end(), {"--connect", ipc + peer});
        if (window)
          render.insert(render.begin(), {"xvfb-run", "-a", "-s", "-screen 0 " + std::to_string(w) + "x" + std::to_string(h) + "x24"});
        else
          render.insert(render.end(), {"--headless", "--size", std::to_string(w) + "x" + std::to_string(h)});
        nodes.push_back(std::make_unique<Child>(render));
      }
      const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(run_s + 30);
      bool done = false;
      while (!done && std::chrono::steady_clock::now() < end) {
        sub.poll(std::chrono::milliseconds(10));
        done = true;
        for (auto& n : nodes) done = n->wait(0) && done;
      }
      for (int i = 0; i < 20; ++i) sub.poll(std::chrono::milliseconds(5));  // the last states in flight
      offset1 = wallMinusSteady();
      for (auto& n : nodes) n->stop(10);
      sim.stop(10);
      collision.stop(10);
      mocap.stop(10);
    }
    // swaps: "step steady_ns" per node; a step counts when every node swapped it, at the last node's time
    std::map<std::uint64_t, std::pair<std::size_t, std::int64_t>> by_step;  // step → (nodes, latest time)
    for (const std::string& name : names) {
      std::ifstream in(dir / "frames" / name / "swaps.log");
      std::uint64_t step;
      std::int64_t t;
      while (in >> step >> t) {
        auto& e = by_step[step];
        ++e.first;
        e.second = std::max(e.second, t);
      }
    }
    std::vector<std::pair<std::uint64_t, std::int64_t>> swaps;
    for (const auto& [step, e] : by_step)
      if (e.first == names.size()) swaps.emplace_back(step, e.second);
    if (swaps.empty()) {
      state.SkipWithError("the render node logged no swap (see its stderr above)");
      break;
    }
    const std::int64_t offset = (offset0 + offset1) / 2;
    const std::int64_t warm = swaps.front().second + 2'000'000'000LL;
    std::vector<double> photon, render_only;
    std::uint64_t last_seq = 0;
    std::size_t unknown = 0, used = 0;
    for (const auto& [step, t] : swaps) {
      const auto it = refs.find(step);
      if (t < warm) {  // warm-up: not counted, but its mocap frames were shown already
        if (it != refs.end()) last_seq = it->second.mocap_sequence;
        continue;
      }
      if (it == refs.end()) {
        ++unknown;
        continue;
      }
      ++used;
      const std::int64_t swap_wall = t + offset;
      render_only.push_back(static_cast<double>(swap_wall - it->second.state_sent_ns) * 1e-6);
      if (it->second.mocap_sequence != 0 && it->second.mocap_sequence != last_seq) {  // its first swap
        photon.push_back(static_cast<double>(swap_wall - it->second.mocap_sent_ns) * 1e-6);
        last_seq = it->second.mocap_sequence;
      }
    }
    state.counters["p50_ms"] = percentile(photon, 0.5);
    state.counters["p99_ms"] = percentile(photon, 0.99);
    state.counters["max_ms"] = photon.empty() ? 0 : *std::max_element(photon.begin(), photon.end());
    state.counters["frames"] = static_cast<double>(photon.size());
    state.counters["state_p50_ms"] = percentile(render_only, 0.5);
    state.counters["state_p99_ms"] = percentile(render_only, 0.99);
    state.counters["swaps"] = static_cast<double>(used);
    state.counters["fps"] = used > 1 ? static_cast<double>(used - 1) /
                                           (static_cast<double>(swaps.back().second - std::max(warm, swaps.front().second)) * 1e-9)
                                     : 0.0;
    state.counters["clock_drift_ns"] = static_cast<double>(offset1 - offset0);
    if (unknown > 0) state.counters["swaps_unmatched"] = static_cast<double>(unknown);
  }
  fs::remove_all(dir);
}
BENCHMARK(BM_MocapToPhoton)
    ->Args({1280, 720, 0, 0})
    ->Args({640, 360, 0, 0})
    ->Args({1280, 720, 1, 0})
    ->Args({640, 640, 0, 1})
    ->ArgNames({"w", "h", "window", "cave"})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace

MANNEQUIN_BENCHMARK_MAIN("bench-render", "configs/mannequins/male_50th.yaml", "configs/scenes/cockpit.yaml",
                         "configs/views/desktop.yaml")
