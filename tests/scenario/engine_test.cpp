// The engine: a transition on each event kind (and not before), boolean combinations, phases and
// actions, the context stack (interrupt / resume), observation checks, no allocation per step.
#include <gtest/gtest.h>

#include <cmath>

#include <string>

#include "../common/alloc_counter.hpp"
#include "common.hpp"
#include "mannequin/scenario/engine.hpp"

using namespace mannequin::scenario;

namespace {

const std::string kEngineHeader = R"(scenario: t
mannequins:
  - name: m
    frames: [hand, foot]
objects:
  - name: door
    values: [angle_deg]
triggers: [go, stop]
)";

// two states: a → b when `when`; b: hand autonomous (goal 1 m up), back to a on trigger stop
Scenario twoStates(const std::string& when) {
  return parseScenario(kEngineHeader + "states:\n  - name: a\n    transitions:\n      - to: b\n        when: " + when +
                           "\n  - name: b\n    modes:\n      hand: {mode: autonomous, goal: {xyz: [0, 0, 1]}, duration_s: 0.5}\n"
                           "    transitions:\n      - {to: a, when: {trigger: stop}}\n",
                       "t.yaml");
}

Observation observation(const Scenario& s) {
  Observation o;
  o.frames.resize(s.frames.size());
  o.objects.resize(s.objects.size());
  for (std::size_t i = 0; i < s.objects.size(); ++i) o.objects[i].values.assign(s.objects[i].values.size(), 0.0);
  return o;
}

struct Machine {
  explicit Machine(const std::string& when) : engine(twoStates(when)), obs(observation(engine.scenario())) {}
  // one step of 10 ms; true when the state is b afterwards
  bool step() {
    obs.time += 0.01;
    engine.step(obs);
    obs.triggers.clear();
    return engine.stateName() == "b";
  }
  Engine engine;
  Observation obs;
};

}  // namespace

TEST(ScenarioEngine, ZoneLevelEvents) {
  Machine in("{inside: {frame: hand, sphere: {center: [1, 0, 0], radius: 0.1}}}");
  EXPECT_FALSE(in.step());
  in.obs.frames[0].pose.p = {0.95, 0, 0};
  EXPECT_TRUE(in.step());

  Machine out("{outside: {frame: foot, box: {center: [0, 0, 0], half_extents: [0.2, 0.1, 0.1]}}}");
  EXPECT_FALSE(out.step());
  out.obs.frames[1].pose.p = {0.15, 0.05, -0.05};  // inside the box still
  EXPECT_FALSE(out.step());
  out.obs.frames[1].pose.p = {0.15, 0.15, 0.0};  // out along y
  EXPECT_TRUE(out.step());
}

TEST(ScenarioEngine, RotatedBoxUsesItsAxes) {
  // a box long along world y (its x axis turned 90° about z)
  Machine r("{inside: {frame: hand, box: {center: [0, 0, 0], half_extents: [0.5, 0.05, 0.05], rpy_deg: [0, 0, 90]}}}");
  r.obs.frames[0].pose.p = {0.3, 0, 0};  // along world x: outside
  EXPECT_FALSE(r.step());
  r.obs.frames[0].pose.p = {0, 0.3, 0};
  EXPECT_TRUE(r.step());
}

TEST(ScenarioEngine, EnterAndLeaveAreEdges) {
  Machine enter("{enter: {frame: hand, sphere: {center: [0, 0, 0], radius: 0.1}}}");
  // inside from the first step: no crossing, no event
  EXPECT_FALSE(enter.step());
  EXPECT_FALSE(enter.step());
  enter.obs.frames[0].pose.p = {0.5, 0, 0};
  EXPECT_FALSE(enter.step());
  enter.obs.frames[0].pose.p = {0.05, 0, 0};
  EXPECT_TRUE(enter.step());

  Machine leave("{leave: {frame: hand, sphere: {center: [0, 0, 0], radius: 0.1}}}");
  EXPECT_FALSE(leave.step());
  leave.obs.frames[0].pose.p = {0.2, 0, 0};
  EXPECT_TRUE(leave.step());
}

TEST(ScenarioEngine, DistanceEvents) {
  Machine point("{distance: {frame: hand, point: [1, 0, 0], below: 0.1}}");
  EXPECT_FALSE(point.step());
  point.obs.frames[0].pose.p = {0.92, 0, 0};
  EXPECT_TRUE(point.step());

  Machine frames("{distance: {frame: hand, to_frame: foot, above: 1.0}}");
  frames.obs.frames[1].pose.p = {0, 0, 0.9};
  EXPECT_FALSE(frames.step());
  frames.obs.frames[1].pose.p = {0, 0, 1.1};
  EXPECT_TRUE(frames.step());

  Machine object("{distance: {frame: foot, object: door, below: 0.5}}");
  object.obs.objects[0].pose.p = {2, 0, 0};
  EXPECT_FALSE(object.step());
  object.obs.objects[0].pose.p = {0.4, 0, 0};
  EXPECT_TRUE(object.step());
}

TEST(ScenarioEngine, ForceEvent) {
  Machine r("{force: {frame: hand, above: 50}}");
  r.obs.frames[0].force = {30, 30, 0};  // 42 N
  EXPECT_FALSE(r.step());
  r.obs.frames[0].force = {40, 30, 0};  // 50 N: not above
  EXPECT_FALSE(r.step());
  r.obs.frames[0].force = {40, 30, 10};
  EXPECT_TRUE(r.step());
}

TEST(ScenarioEngine, ReachedPoseWithinTolerance) {
  Machine r("{reached: {frame: foot, pose: {xyz: [0, 0, 1], rpy_deg: [0, 0, 90]}, tolerance_m: 0.01, tolerance_deg: 2}}");
  r.obs.frames[1].pose = SE3(mannequin::math::expSO3(Vector3(0, 0, M_PI / 2)), Vector3(0, 0, 0.98));  // 2 cm off
  EXPECT_FALSE(r.step());
  r.obs.frames[1].pose.p.z() = 0.995;
  r.obs.frames[1].pose.R = mannequin::math::expSO3(Vector3(0, 0, M_PI / 2 + 3 * M_PI / 180));  // 3° off
  EXPECT_FALSE(r.step());
  r.obs.frames[1].pose.R = mannequin::math::expSO3(Vector3(0, 0, M_PI / 2 + 1 * M_PI / 180));
  EXPECT_TRUE(r.step());
}

TEST(ScenarioEngine, ReachedAutonomousGoalRelativeToObject) {
  const Scenario s = parseScenario(kEngineHeader + R"(states:
  - name: a
    modes:
      hand: {mode: autonomous, goal: {xyz: [0, 0, 0.5]}, relative_to: door, duration_s: 1}
    transitions:
      - {to: b, when: {reached: {frame: hand, tolerance_m: 0.01}}}
  - name: b
)",
                                   "t.yaml");
  Engine e(s);
  Observation o = observation(s);
  o.objects[0].pose.p = {2, 0, 0};  // the goal is resolved at configure: (2, 0, 0.5)
  e.step(o);
  EXPECT_TRUE(e.step(o).frames[0].goal.p.isApprox(Vector3(2, 0, 0.5)));
  o.objects[0].pose.p = {5, 0, 0};  // the object moving later does not move the goal
  o.time = 0.1;
  o.frames[0].pose.p = {2, 0, 0.5};
  e.step(o);
  EXPECT_EQ(e.stateName(), "b");
}

TEST(ScenarioEngine, TimeInState) {
  Machine r("{time: 0.1}");
  int steps = 0;
  while (!r.step()) ++steps;
  // entered at t = 0.01 (first step); time_in_state >= 0.1 first at t = 0.11, the 11th step (the 12th if
  // 0.11 - 0.01 rounds below 0.1)
  EXPECT_GE(steps, 10);
  EXPECT_LE(steps, 11);
}

TEST(ScenarioEngine, ObjectStateValue) {
  Machine r("{object: {name: door, value: angle_deg, above: 60}}");
  r.obs.objects[0].values[0] = 59;
  EXPECT_FALSE(r.step());
  r.obs.objects[0].values[0] = 61;
  EXPECT_TRUE(r.step());
}

TEST(ScenarioEngine, TriggersByNameAndValue) {
  Machine r("{trigger: {name: go, value: now}}");
  r.obs.triggers.push_back({"go", "later"});
  EXPECT_FALSE(r.step());
  r.obs.triggers.push_back({"stop", "now"});
  EXPECT_FALSE(r.step());
  r.obs.triggers.push_back({"nonsense", ""});
  EXPECT_FALSE(r.step());
  EXPECT_EQ(r.engine.step(r.obs).unknown_triggers.size(), 0u);  // cleared by step(): none this time
  r.obs.triggers.push_back({"nonsense", ""});
  r.obs.time += 0.01;
  const StepResult& res = r.engine.step(r.obs);
  ASSERT_EQ(res.unknown_triggers.size(), 1u);
  EXPECT_EQ(res.unknown_triggers[0], "nonsense");
  r.obs.triggers.clear();
  r.obs.triggers.push_back({"go", "now"});
  EXPECT_TRUE(r.step());
  // a trigger is an event of the step it arrives in: the any-value form
  Machine any("{trigger: go}");
  any.obs.triggers.push_back({"go", "whatever"});
  EXPECT_TRUE(any.step());
}

TEST(ScenarioEngine, BooleanCombinations) {
  const std::string force = "{force: {frame: hand, above: 10}}", door = "{object: {name: door, value: angle_deg, above: 30}}";
  // all: both needed
  Machine all("{all: [" + force + ", " + door + "]}");
  all.obs.frames[0].force = {20, 0, 0};
  EXPECT_FALSE(all.step());
  all.obs.frames[0].force = {0, 0, 0};
  all.obs.objects[0].values[0] = 40;
  EXPECT_FALSE(all.step());
  all.obs.frames[0].force = {20, 0, 0};
  EXPECT_TRUE(all.step());
  // any: either
  Machine any("{any: [" + force + ", " + door + "]}");
  EXPECT_FALSE(any.step());
  any.obs.objects[0].values[0] = 40;
  EXPECT_TRUE(any.step());
  // not, nested: not (force or door)
  Machine nor("{not: {any: [" + force + ", " + door + "]}}");
  nor.obs.frames[0].force = {20, 0, 0};
  EXPECT_FALSE(nor.step());
  nor.obs.frames[0].force = {0, 0, 0};
  EXPECT_TRUE(nor.step());
}

TEST(ScenarioEngine, PhasesAndActionsOfTheDrill) {
  const Scenario s = loadScenario(scenario_test::sourceDir() + "/configs/scenarios/drill.yaml");
  Engine e(s);
  Observation o = observation(s);
  o.frames[0].target.p = o.frames[0].pose.p = {0.2, -0.2, 1.2};
  const StepResult* r = &e.step(o);
  // first step: configure + start of approach (grasp), then its run
  ASSERT_EQ(r->actions.size(), 1u);
  EXPECT_EQ(r->actions[0].action->kind, Action::Kind::kGrasp);
  ASSERT_EQ(r->phases.size(), 3u);
  EXPECT_EQ(r->phases[0].second, Phase::kConfigure);
  EXPECT_EQ(r->phases[1].second, Phase::kStart);
  EXPECT_EQ(r->phases[2].second, Phase::kRun);
  // the hand enters the zone in front of the hole: drilling, hand_r constrained
  o.time = 0.01;
  o.frames[0].target.p = o.frames[0].pose.p = {0.45, -0.19, 1.2};
  r = &e.step(o);
  EXPECT_TRUE(r->switched);
  EXPECT_EQ(e.stateName(), "drilling");
  EXPECT_EQ(r->frames[0].mode, ControlMode::kConstrained);
  EXPECT_EQ(r->frames[1].mode, ControlMode::kFree);
  ASSERT_EQ(e.lastEvents().size(), 1u);
  EXPECT_EQ(e.lastEvents()[0], "guide or near the hole");
  // run(approach), teardown(approach), configure(drilling), start(drilling)
  ASSERT_EQ(r->phases.size(), 4u);
  EXPECT_EQ(r->phases[1], std::make_pair(s.stateIndex("approach"), Phase::kTeardown));
  EXPECT_EQ(r->phases[3], std::make_pair(s.stateIndex("drilling"), Phase::kStart));
  ASSERT_EQ(r->actions.size(), 1u);
  EXPECT_EQ(r->actions[0].action->kind, Action::Kind::kSetGains);
  // after the blend the setpoint is on the axis (y = -0.2, z = 1.2) at the target's depth
  for (int i = 2; i < 60; ++i) {
    o.time = 0.01 * i;
    r = &e.step(o);
  }
  EXPECT_FALSE(r->frames[0].blending);
  EXPECT_NEAR(r->frames[0].setpoint.pose.p.y(), -0.2, 1e-9);
  EXPECT_NEAR(r->frames[0].setpoint.pose.p.z(), 1.2, 1e-9);
  EXPECT_NEAR(r->frames[0].setpoint.pose.p.x(), 0.45, 1e-9);
  // depth reached: retract (autonomous to 20 cm out of the wall), then free with the release
  o.objects[0].values[0] = 0.035;
  o.time += 0.01;
  r = &e.step(o);
  EXPECT_EQ(e.stateName(), "retract");
  EXPECT_EQ(r->frames[0].mode, ControlMode::kAutonomous);
  o.objects[0].values[0] = 0;
  for (int i = 0; i < 100 && e.stateName() == "retract"; ++i) {
    o.time += 0.01;
    o.frames[0].pose = r->frames[0].setpoint.pose;  // a perfect tracker
    r = &e.step(o);
  }
  EXPECT_EQ(e.stateName(), "free");
  ASSERT_EQ(r->actions.size(), 1u);
  EXPECT_EQ(r->actions[0].action->kind, Action::Kind::kRelease);
  EXPECT_FALSE(r->actions[0].entry);
}

TEST(ScenarioEngine, ContextStackInterruptAndResume) {
  const Scenario s = loadScenario(scenario_test::sourceDir() + "/configs/scenarios/interrupt.yaml");
  Engine e(s);
  Observation o = observation(s);
  const auto step = [&](double dt) -> const StepResult& {
    o.time += dt;
    const StepResult& r = e.step(o);
    o.triggers.clear();
    return r;
  };
  step(0);
  o.triggers.push_back({"start", ""});
  step(0.01);
  ASSERT_EQ(e.stateName(), "screwing");
  for (int i = 0; i < 100; ++i) step(0.01);  // 1 s of screwing
  const double screwing_time = e.timeInState();
  EXPECT_NEAR(screwing_time, 1.0, 1e-9);

  // the phone interrupts from any state: screwing is suspended (no teardown) and stacked
  o.triggers.push_back({"phone", ""});
  const StepResult& r1 = step(0.01);
  EXPECT_EQ(e.stateName(), "phone_call");
  EXPECT_EQ(e.contextStack(), std::vector<std::string>{"screwing"});
  for (const auto& p : r1.phases) EXPECT_NE(p.second, Phase::kTeardown);
  EXPECT_EQ(r1.frames[1].mode, ControlMode::kAutonomous);
  // a second phone call does not stack phone_call on itself
  o.triggers.push_back({"phone", ""});
  step(0.01);
  EXPECT_EQ(e.contextStack().size(), 1u);
  for (int i = 0; i < 50; ++i) step(0.01);

  // hanging up resumes screwing: start only (no configure), its time in state kept
  o.triggers.push_back({"hang_up", ""});
  const StepResult& r2 = step(0.01);
  EXPECT_EQ(e.stateName(), "screwing");
  EXPECT_TRUE(e.contextStack().empty());
  ASSERT_EQ(r2.phases.size(), 3u);
  EXPECT_EQ(r2.phases[1], std::make_pair(s.stateIndex("phone_call"), Phase::kTeardown));
  EXPECT_EQ(r2.phases[2], std::make_pair(s.stateIndex("screwing"), Phase::kStart));
  EXPECT_NEAR(e.timeInState(), screwing_time + 0.01, 1e-9);  // the step it was suspended in
  EXPECT_EQ(r2.frames[0].mode, ControlMode::kConstrained);

  // nested: a push too hard interrupts (urgent transition of screwing), the phone interrupts that too
  o.frames[0].force = {0, 0, 100};
  step(0.01);
  EXPECT_EQ(e.stateName(), "steady");
  o.triggers.push_back({"phone", ""});
  step(0.01);
  EXPECT_EQ(e.stateName(), "phone_call");
  EXPECT_EQ(e.contextStack(), (std::vector<std::string>{"screwing", "steady"}));
  o.triggers.push_back({"hang_up", ""});
  step(0.01);
  EXPECT_EQ(e.stateName(), "steady");
  // steady resumes once the force is back to normal and 0.5 s have passed in it
  o.frames[0].force = {0, 0, 5};
  int steps = 0;
  while (e.stateName() == "steady" && steps < 200) {
    step(0.01);
    ++steps;
  }
  EXPECT_EQ(e.stateName(), "screwing");
  EXPECT_TRUE(e.contextStack().empty());
  EXPECT_LT(steps, 60);
  // and the task finishes normally
  o.objects[0].values[0] = 4;
  step(0.01);
  EXPECT_EQ(e.stateName(), "done");
}

TEST(ScenarioEngine, RefusesMismatchedObservations) {
  Machine r("{time: 1}");
  r.obs.frames.pop_back();
  EXPECT_THROW(r.step(), std::invalid_argument);
  Machine v("{time: 1}");
  v.obs.objects[0].values.clear();
  EXPECT_THROW(v.step(), std::invalid_argument);
  Machine t("{time: 1}");
  t.step();
  t.obs.time -= 0.02;  // step() adds 0.01: 10 ms back in time
  EXPECT_THROW(t.step(), std::invalid_argument);
  // a NaN time, even on the first step, is refused (it would poison every later time comparison)
  Machine n("{time: 1}");
  n.obs.time = std::nan("");
  EXPECT_THROW(n.step(), std::invalid_argument);
  n.obs.time = 0;
  EXPECT_NO_THROW(n.step());
}

TEST(ScenarioEngine, Deterministic) {
  const Scenario s = loadScenario(scenario_test::sourceDir() + "/configs/scenarios/drill.yaml");
  Engine a(s), b(s);
  Observation o = observation(s);
  for (int i = 0; i < 300; ++i) {
    o.time = 0.01 * i;
    o.frames[0].target.p = {0.2 + 0.002 * i, -0.2 + 0.01 * std::sin(0.1 * i), 1.2};
    o.frames[0].pose = o.frames[0].target;
    const StepResult& ra = a.step(o);
    const StepResult& rb = b.step(o);
    ASSERT_EQ(a.state(), b.state());
    ASSERT_EQ(ra.frames[0].setpoint.pose.p, rb.frames[0].setpoint.pose.p);
    ASSERT_EQ(ra.frames[0].setpoint.pose.R, rb.frames[0].setpoint.pose.R);
  }
  EXPECT_EQ(a.stateName(), "drilling");
}

TEST(ScenarioEngine, NoAllocationPerStepSwitchesIncluded) {
  const Scenario s = loadScenario(scenario_test::sourceDir() + "/configs/scenarios/drill.yaml");
  Engine e(s);
  Observation o = observation(s);
  o.frames[0].target.p = o.frames[0].pose.p = {0.2, -0.2, 1.2};
  e.step(o);  // warm-up: the initial state's configure and start
  int visited[4] = {0, 0, 0, 0};
  int switches = 0;
  const long allocations = countAllocations([&] {
    for (int k = 1; k <= 3000; ++k) {
      o.time = 1e-3 * k;
      // the hand walks to the hole at 0.2 m/s, the drill reports 4 cm depth after 1.8 s
      o.frames[0].target.p.x() = std::min(0.2 + 0.2 * o.time, 0.5);
      o.objects[0].values[0] = o.time > 1.8 ? 0.04 : 0.0;
      const StepResult& r = e.step(o);
      o.frames[0].pose = r.frames[0].setpoint.pose;  // a perfect tracker
      switches += r.switched;
      ++visited[e.state()];
    }
  });
  if (allocations < 0) GTEST_SKIP() << "the sanitizer allocator hook could not be installed";
  EXPECT_EQ(switches, 3);  // approach → drilling → retract → free
  for (int v : visited) EXPECT_GT(v, 0);
  EXPECT_EQ(allocations, 0);
}
