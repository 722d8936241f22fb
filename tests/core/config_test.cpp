// The one config reader: every error is "FILE:LINE: field 'a.b': message", unknown keys are refused, and the
// typed readers (numbers with their ranges, lists, rotations, choices) refuse what they cannot represent.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "mannequin/core/config.hpp"

namespace {
using mannequin::core::ConfigError;
using mannequin::core::ConfigNode;

// what() of the ConfigError `read` throws on `yaml`, or a failure naming the yaml when it throws none
std::string errorOf(const std::string& yaml, const std::function<void(const ConfigNode&)>& read) {
  try {
    read(ConfigNode::parse(yaml, "c.yaml"));
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no ConfigError for:\n" << yaml;
  return {};
}

TEST(ConfigNode, ErrorsNameFileLineAndFieldPath) {
  const std::string yaml = "a:\n  b:\n    - 1\n    - x\n";
  EXPECT_EQ(errorOf(yaml, [](const ConfigNode& r) { r["a"]["b"].items()[1].num(); }),
            "c.yaml:4: field 'a.b[1]': 'x' is not a number");
  EXPECT_EQ(errorOf(yaml, [](const ConfigNode& r) { r["a"]["c"]; }), "c.yaml:2: field 'a': missing required key 'c'");
  EXPECT_EQ(errorOf("a: 1\nb: 2\n", [](const ConfigNode& r) { r.fail("bad"); }), "c.yaml:1: field '<top>': bad");
  const ConfigNode r = ConfigNode::parse(yaml, "c.yaml");
  EXPECT_EQ(r["a"]["b"].items()[1].where(), "c.yaml:4");
  EXPECT_EQ(r["a"]["b"].items()[1].path(), "a.b[1]");
}

TEST(ConfigNode, UnknownKeysAreRefusedWithTheirLineAndTheAllowedOnes) {
  const std::string e = errorOf("name: x\nsub:\n  ok: 1\n  colour: red\n",
                                [](const ConfigNode& r) { r["sub"].allowOnly({"ok", "size"}); });
  EXPECT_EQ(e, "c.yaml:4: field 'sub.colour': unknown key (expected one of: ok, size)");
  EXPECT_NO_THROW(ConfigNode::parse("ok: 1\n", "c.yaml").allowOnly({"ok"}));
}

TEST(ConfigNode, SyntaxErrorsAndUnreadableFilesNameTheFile) {
  const std::string e = errorOf("a: 1\nb: [1, 2\n", [](const ConfigNode&) {});
  EXPECT_EQ(e.rfind("c.yaml:", 0), 0u) << e;
  EXPECT_NE(e.find("YAML syntax error"), std::string::npos) << e;
  EXPECT_NE(errorOf("- a\n- b\n", [](const ConfigNode&) {}).find("c.yaml:1: expected a map"), std::string::npos);
  try {
    ConfigNode::load("/no/such/dir/x.yaml");
    ADD_FAILURE() << "no error for a missing file";
  } catch (const ConfigError& err) {
    EXPECT_EQ(std::string(err.what()).rfind("/no/such/dir/x.yaml:0: cannot read the file", 0), 0u) << err.what();
  }
}

TEST(ConfigNode, NumbersRefuseNonFiniteValuesAndRespectTheirRanges) {
  const ConfigNode r = ConfigNode::parse("a: 2.5\nz: 0\nn: -1\ninf: .inf\nninf: -.inf\nnan: .NaN\nbig: 1e999\n", "c.yaml");
  EXPECT_DOUBLE_EQ(r["a"].num(), 2.5);
  EXPECT_DOUBLE_EQ(r["a"].positive(), 2.5);
  EXPECT_DOUBLE_EQ(r["z"].nonNegative(), 0.0);
  EXPECT_DOUBLE_EQ(r["a"].numIn(2.5, 3.0), 2.5);
  EXPECT_EQ(errorOf("z: 0\n", [](const ConfigNode& n) { n["z"].positive(); }), "c.yaml:1: field 'z': must be > 0, got 0");
  EXPECT_EQ(errorOf("n: -1\n", [](const ConfigNode& n) { n["n"].nonNegative(); }), "c.yaml:1: field 'n': must be >= 0, got -1");
  EXPECT_EQ(errorOf("a: 4\n", [](const ConfigNode& n) { n["a"].numIn(0, 3); }), "c.yaml:1: field 'a': 4 is outside [0, 3]");
  for (const char* key : {"inf", "ninf", "nan", "big"})
    EXPECT_NE(errorOf(R"(inf: .inf
ninf: -.inf
nan: .NaN
big: 1e999
)", [&](const ConfigNode& n) { n[key].num(); }).find("is not a finite number"), std::string::npos) << key;
  // an end stop may be infinite (a free side), never NaN
  EXPECT_TRUE(std::isinf(r["inf"].numOrInfinity()) && r["inf"].numOrInfinity() > 0);
  EXPECT_TRUE(std::isinf(r["ninf"].numOrInfinity()) && r["ninf"].numOrInfinity() < 0);
  EXPECT_EQ(errorOf("nan: .nan\n", [](const ConfigNode& n) { n["nan"].numOrInfinity(); }),
            "c.yaml:1: field 'nan': '.nan' is not a number");
  EXPECT_EQ(r["z"].integerIn(0, 3), 0);
  EXPECT_EQ(errorOf("p: 1.5\n", [](const ConfigNode& n) { n["p"].integerIn(0, 100); }),
            "c.yaml:1: field 'p': '1.5' is not an integer");
  EXPECT_EQ(errorOf("p: 101\n", [](const ConfigNode& n) { n["p"].integerIn(0, 100); }),
            "c.yaml:1: field 'p': 101 is outside [0, 100]");
}

TEST(ConfigNode, VectorsHaveTheirSize) {
  const ConfigNode r = ConfigNode::parse("v: [1, 2, 3, 4]\n", "c.yaml");
  EXPECT_EQ(r["v"].vector(4), Eigen::Vector4d(1, 2, 3, 4));
  EXPECT_EQ(r["v"].vector().size(), 4);
  EXPECT_EQ(errorOf("v: [1, 2, 3, 4]\n", [](const ConfigNode& n) { n["v"].vector(6); }),
            "c.yaml:1: field 'v': expected a list of 6 numbers, got 4 values");
  EXPECT_EQ(errorOf("v:\n  - 1\n  - y\n", [](const ConfigNode& n) { n["v"].vector(2); }),
            "c.yaml:3: field 'v[1]': 'y' is not a number");
  EXPECT_EQ(errorOf("v: 3\n", [](const ConfigNode& n) { n["v"].vec3(); }), "c.yaml:1: field 'v': expected a list");
}

TEST(ConfigNode, RollPitchYawInDegreesIsRzRyRx) {
  const ConfigNode r = ConfigNode::parse("a: [0, 90, 0]\nb: [10, 20, 30]\nc: [0, 0]\n", "c.yaml");
  // pitch 90°: z onto x
  EXPECT_LT((r["a"].rpyDeg().col(2) - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  const double d = 3.14159265358979323846 / 180.0;
  const Eigen::Matrix3d expect = (Eigen::AngleAxisd(30 * d, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(20 * d, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(10 * d, Eigen::Vector3d::UnitX()))
                                     .toRotationMatrix();
  EXPECT_LT((r["b"].rpyDeg() - expect).norm(), 1e-12);
  EXPECT_EQ(errorOf("c: [0, 0]\n", [](const ConfigNode& n) { n["c"].rpyDeg(); }),
            "c.yaml:1: field 'c': expected [x, y, z], got 2 values");
}

TEST(ConfigNode, ChoiceNamesTheOptions) {
  const ConfigNode r = ConfigNode::parse("m: replay\nx: fast\n", "c.yaml");
  EXPECT_EQ(r["m"].choice({"live", "replay"}), 1u);
  EXPECT_EQ(errorOf("x: fast\n", [](const ConfigNode& n) { n["x"].choice({"live", "replay"}); }),
            "c.yaml:1: field 'x': expected live or replay, got 'fast'");
  EXPECT_EQ(errorOf("x: qr\n", [](const ConfigNode& n) { n["x"].choice({"a", "b", "c"}); }),
            "c.yaml:1: field 'x': expected a, b or c, got 'qr'");
}

TEST(ConfigNode, FailAtFormatsAnErrorFoundAfterReading) {
  const ConfigNode r = ConfigNode::parse("a:\n  b: 1\n", "c.yaml");
  try {
    mannequin::core::failAt(r["a"]["b"].where(), "a.b", "no such frame");
    ADD_FAILURE() << "failAt returned";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "c.yaml:2: field 'a.b': no such frame");
  }
}

}  // namespace
