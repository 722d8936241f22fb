// Scenario files: the shipped ones load; every validation error names FILE:LINE and the reason;
// unreachable states are warnings.
#include <gtest/gtest.h>

#include <string>

#include "common.hpp"
#include "mannequin/scenario/scenario.hpp"

using namespace mannequin::scenario;
using mannequin::core::ConfigError;

namespace {

const std::string kHeader = R"(scenario: t
mannequins:
  - name: m
    frames: [hand, foot]
  - name: n
    frames: [hand]
objects:
  - name: door
    values: [angle_deg]
triggers: [go]
)";

// the 1-based line of the text containing `marker`
int lineOf(const std::string& text, const std::string& marker) {
  const auto pos = text.find(marker);
  EXPECT_NE(pos, std::string::npos) << marker;
  int line = 1;
  for (std::size_t i = 0; i < pos; ++i) line += text[i] == '\n';
  return line;
}

// parses kHeader + body and expects "t.yaml:LINE:" (LINE: the line with `marker`) and `reason`
void expectError(const std::string& body, const std::string& marker, const std::string& reason) {
  const std::string text = kHeader + body;
  try {
    parseScenario(text, "t.yaml");
    ADD_FAILURE() << "no error for:\n" << body;
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    const std::string where = "t.yaml:" + std::to_string(lineOf(text, marker)) + ":";
    EXPECT_EQ(what.rfind(where, 0), 0u) << what << "\nexpected to start with " << where;
    EXPECT_NE(what.find(reason), std::string::npos) << what << "\nexpected: " << reason;
  }
}

}  // namespace

TEST(ScenarioLoader, ShippedDrillLoads) {
  const Scenario s = loadScenario(scenario_test::sourceDir() + "/configs/scenarios/drill.yaml");
  EXPECT_EQ(s.name, "drill");
  EXPECT_TRUE(s.warnings.empty());
  ASSERT_EQ(s.frames.size(), 2u);
  EXPECT_EQ(s.frames[0].name(), "worker.hand_r");
  ASSERT_EQ(s.states.size(), 4u);
  EXPECT_EQ(s.states[static_cast<std::size_t>(s.initial)].name, "approach");
  const State& drilling = s.states[static_cast<std::size_t>(s.stateIndex("drilling"))];
  ASSERT_EQ(drilling.modes[0].mode, ControlMode::kConstrained);
  EXPECT_EQ(drilling.modes[0].mechanism->spec.type, mannequin::control::MechanismType::kSlidingPivot);
  EXPECT_DOUBLE_EQ(drilling.modes[0].mechanism->spec.upper(0), 0.04);
  EXPECT_EQ(drilling.modes[1].mode, ControlMode::kFree);
  const State& retract = s.states[static_cast<std::size_t>(s.stateIndex("retract"))];
  EXPECT_EQ(retract.modes[0].mode, ControlMode::kAutonomous);
  EXPECT_EQ(retract.modes[0].relative_to, s.objectIndex("wall"));
  ASSERT_EQ(retract.exit.size(), 1u);
  EXPECT_EQ(retract.exit[0].kind, Action::Kind::kRelease);
}

TEST(ScenarioLoader, ShippedInterruptLoads) {
  const Scenario s = loadScenario(scenario_test::sourceDir() + "/configs/scenarios/interrupt.yaml");
  EXPECT_TRUE(s.warnings.empty());
  ASSERT_EQ(s.interrupts.size(), 1u);
  EXPECT_TRUE(s.interrupts[0].urgent);
  EXPECT_EQ(s.interrupts[0].to, s.stateIndex("phone_call"));
  const State& screwing = s.states[static_cast<std::size_t>(s.stateIndex("screwing"))];
  ASSERT_EQ(screwing.transitions.size(), 2u);
  EXPECT_TRUE(screwing.transitions[0].urgent);
  EXPECT_TRUE(s.states[static_cast<std::size_t>(s.stateIndex("steady"))].transitions[0].resume);
}

TEST(ScenarioLoader, FrameNamesQualifiedWhenAmbiguous) {
  const Scenario s = parseScenario(kHeader + "states:\n  - name: a\n    modes: {m.hand: free, n.hand: free, foot: free}\n", "t.yaml");
  EXPECT_EQ(s.frameIndex("foot"), 1);
  EXPECT_EQ(s.frameIndex("n.hand"), 2);
  EXPECT_EQ(s.frameIndex("hand"), -1);  // two mannequins have one
  expectError("states:\n  - name: a\n    transitions:\n      - {to: a, when: {force: {frame: hand, above: 1}}}  # X\n",
              "# X", "ambiguous");
}

TEST(ScenarioLoader, UnknownState) {
  expectError("states:\n  - name: a\n    transitions:\n      - to: nowhere  # X\n        when: {time: 1}\n", "# X",
              "unknown state 'nowhere'");
  expectError("initial: b  # X\nstates:\n  - name: a\n", "# X", "unknown state 'b'");
}

TEST(ScenarioLoader, TransitionToNowhere) {
  expectError("states:\n  - name: a\n    transitions:\n      - when: {time: 1}  # X\n", "# X",
              "give 'to: STATE' or 'resume: true'");
}

TEST(ScenarioLoader, DuplicateState) {
  expectError("states:\n  - name: a\n  - name: a  # X\n", "# X", "duplicate state 'a'");
}

TEST(ScenarioLoader, UnknownFrame) {
  expectError("states:\n  - name: a\n    modes:\n      m.elbow: free  # X\n", "# X", "unknown control frame 'm.elbow'");
  expectError("states:\n  - name: a\n    transitions:\n      - to: a\n        when: {force: {frame: knee, above: 3}}  # X\n",
              "# X", "unknown control frame 'knee'");
  expectError("states:\n  - name: a\n    entry:\n      - grasp: {frame: toe, object: door}  # X\n", "# X",
              "unknown control frame 'toe'");
}

TEST(ScenarioLoader, UnknownEventKind) {
  expectError("states:\n  - name: a\n    transitions:\n      - to: a\n        when: {collides: {frame: foot}}  # X\n",
              "# X", "unknown event 'collides'");
  // inside a combination too
  expectError("states:\n  - name: a\n    transitions:\n      - to: a\n        when:\n          any:\n            - {time: 1}\n"
              "            - {teleport: 3}  # X\n",
              "# X", "unknown event 'teleport'");
}

TEST(ScenarioLoader, UnknownObjectTriggerValue) {
  expectError("states:\n  - name: a\n    transitions:\n      - to: a\n        when: {object: {name: window, value: angle_deg, above: 1}}  # X\n",
              "# X", "unknown object 'window'");
  expectError("states:\n  - name: a\n    transitions:\n      - to: a\n        when: {object: {name: door, value: speed, above: 1}}  # X\n",
              "# X", "object 'door' has no value 'speed'");
  expectError("states:\n  - name: a\n    transitions:\n      - to: a\n        when: {trigger: stop}  # X\n", "# X",
              "unknown trigger 'stop'");
}

TEST(ScenarioLoader, BadModesAndActions) {
  expectError("states:\n  - name: a\n    modes:\n      foot: {mode: constrained}  # X\n", "# X", "needs a 'mechanism'");
  expectError("states:\n  - name: a\n    modes:\n      foot: {mode: flying}  # X\n", "# X", "expected free, constrained or autonomous");
  expectError("states:\n  - name: a\n    modes:\n      foot: {mode: autonomous, goal: {xyz: [0, 0, 1]}}  # X\n", "# X",
              "needs 'duration_s'");
  expectError("states:\n  - name: a\n    modes:\n      foot:\n        mode: constrained\n        mechanism: {type: hinge}  # X\n",
              "# X", "hinge");
  expectError("states:\n  - name: a\n    entry:\n      - wave: {frame: foot}  # X\n", "# X", "unknown action 'wave'");
  // reached without a pose needs the frame to be autonomous in that state
  expectError("states:\n  - name: a\n    transitions:\n      - to: a\n        when: {reached: {frame: foot}}  # X\n",
              "# X", "not autonomous in state 'a'");
}

TEST(ScenarioLoader, ResumeNeedsAnUrgentTransition) {
  expectError("states:\n  - name: a\n    transitions:\n      - resume: true  # X\n        when: {time: 1}\n", "# X",
              "no urgent transition");
}

TEST(ScenarioLoader, UnreachableStatesAreWarnings) {
  const std::string text = kHeader +
                           "states:\n  - name: a\n    transitions:\n      - {to: b, when: {time: 1}}\n  - name: b\n"
                           "  - name: island  # X\n";
  const Scenario s = parseScenario(text, "t.yaml");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].where, "t.yaml:" + std::to_string(lineOf(text, "# X")));
  EXPECT_NE(s.warnings[0].message.find("'island' is unreachable"), std::string::npos);
}
