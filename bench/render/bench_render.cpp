// bench-render: one headless render node's frame time (docs/render.md). Goal (issue 14): ≥ 60 fps at
// 1280×720 with two mannequins in the cockpit scene and contact arrows, on Mesa llvmpipe.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>

#include "bench_main.hpp"
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

// buildScene + draw + glFinish (what a headless node does before reading back).
void BM_HeadlessFrame(benchmark::State& state) {
  const int w = static_cast<int>(state.range(0)), h = static_cast<int>(state.range(1));
  Fixture f(w, h);
  const render::Camera cam = f.view.camera(w, h);
  for (auto _ : state) {
    const render::RenderScene scene = render::buildScene(f.ws, f.assets, f.view.style);
    f.renderer->draw(scene, cam, w, h, f.view.background);
    const render::Image img = f.ctx.read();  // includes glFinish: the frame is done
    benchmark::DoNotOptimize(img.rgb.data());
  }
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel(render::Renderer::describeContext());
}
BENCHMARK(BM_HeadlessFrame)->Args({1280, 720})->Args({640, 360})->Unit(benchmark::kMillisecond)->UseRealTime();

// buildScene alone (no GL): the CPU cost of the scene model per frame.
void BM_BuildScene(benchmark::State& state) {
  Fixture f(16, 16);
  for (auto _ : state) {
    const render::RenderScene scene = render::buildScene(f.ws, f.assets, f.view.style);
    benchmark::DoNotOptimize(scene.solids.data());
  }
}
BENCHMARK(BM_BuildScene)->Unit(benchmark::kMicrosecond);

}  // namespace

MANNEQUIN_BENCHMARK_MAIN("bench-render", "configs/mannequins/male_50th.yaml", "configs/scenes/cockpit.yaml",
                         "configs/views/desktop.yaml")
