// Force plates: the c3d.org sample01 walk (two AMTI type-2 plates on 16 analog channels at 200 Hz) decoded
// by hand from the file's bytes and in its three processor formats, what the plates say checked against
// physics (the reaction points up out of the floor, the centre of pressure lies on the plate and under a
// foot), types 1, 3 and 4 on plates built in memory with hand-computed loads, and bad FORCE_PLATFORM
// parameters named.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "mannequin/mocap/c3d.hpp"
#include "mannequin/mocap/force_plate.hpp"
#include "samples.hpp"

namespace mc = mannequin::mocap;

namespace {

float littleEndianFloat(const std::string& b, std::size_t o) {
  std::uint32_t v = 0;
  for (int k = 3; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(b[o + static_cast<std::size_t>(k)]);
  return std::bit_cast<float>(v);
}

// The PC file's layout as read by hand (c3d_test.cpp, PcFileMatchesItsHeaderReadByHand): frames from byte
// 5120, each 26 points × 4 floats then 64 analog floats (4 subframes × 16 channels). Plate 1 is on channels
// 1-6 (FORCE_PLATFORM:CHANNEL), ANALOG:OFFSET 2048, GEN_SCALE 0.5, and these ANALOG:SCALE values (floats):
constexpr std::size_t kDataStart = 5120;
constexpr std::size_t kFrameBytes = (4 * 26 + 64) * 4;
constexpr float kPlate1Scale[6] = {-0.86f, -0.884f, -1.488f, -239.36f, -227.74f, -92.9f};

/// Channel `ch` (0-based, < 6) of plate 1 at analog sample `s`, scaled, from the bytes.
double handChannel(const std::string& bytes, int s, int ch) {
  const std::size_t f = static_cast<std::size_t>(s / 4), sub = static_cast<std::size_t>(s % 4);
  const float stored = littleEndianFloat(bytes, kDataStart + f * kFrameBytes + 26 * 16 + (sub * 16 + static_cast<std::size_t>(ch)) * 4);
  return (static_cast<double>(stored) - 2048.0) * static_cast<double>(kPlate1Scale[ch]) * 0.5;
}

// One analog sample of plate 1 computed by hand: the channels less their mean over ZERO = frames 1..10
// (samples 0..39), then the CoP on the surface 21.6 mm above the transducer (ORIGIN (-4.4, 1.9, -21.6),
// plate z down): px = (c Fx - My) / Fz, py = (Mx + c Fy) / Fz, less (a, b); Tz = Mz - (px Fy - py Fx).
struct HandSample {
  Eigen::Vector3d f, m;
  double cop_x = 0, cop_y = 0, tz = 0;
};
HandSample handSample(const std::string& bytes, int s) {
  double v[6];
  for (int ch = 0; ch < 6; ++ch) {
    double base = 0.0;
    for (int k = 0; k < 40; ++k) base += handChannel(bytes, k, ch);
    v[ch] = handChannel(bytes, s, ch) - base / 40.0;
  }
  HandSample h;
  h.f = Eigen::Vector3d(v[0], v[1], v[2]);
  h.m = Eigen::Vector3d(v[3], v[4], v[5]);
  const double a = static_cast<double>(-4.4f), b = static_cast<double>(1.9f), c = static_cast<double>(-21.6f);
  const double px = (c * h.f.x() - h.m.y()) / h.f.z(), py = (h.m.x() + c * h.f.y()) / h.f.z();
  h.cop_x = px - a;
  h.cop_y = py - b;
  h.tz = h.m.z() - (px * h.f.y() - py * h.f.x());
  return h;
}

TEST(ForcePlates, OneSampleOfTheRealFileDecodedByHandFromItsBytes) {
  const std::string path = c3dtest::samplePath("pr");
  const std::string bytes = c3dtest::fileBytes(path);
  ASSERT_GT(bytes.size(), kDataStart + 450 * kFrameBytes - 1) << path;
  const mc::C3d c = mc::readC3dFile(path);
  const mc::ForcePlates fp = mc::readForcePlates(c);
  ASSERT_EQ(fp.plates.size(), 2u);
  EXPECT_EQ(fp.subframes, 4);
  EXPECT_EQ(fp.samples, 1800);
  EXPECT_DOUBLE_EQ(fp.rate, 200.0);
  const mc::ForcePlate& plate = fp.plates[0];
  EXPECT_EQ(plate.type, 2);
  EXPECT_EQ(plate.channels, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(plate.zero_first, 1);
  EXPECT_EQ(plate.zero_last, 10);
  // corners 1..4 at (520, 1242), (57, 1243), (58, 1751), (521, 1750) mm: x along +X, y along -Y, z down
  EXPECT_GT(plate.axes.col(0).x(), 0.999);
  EXPECT_LT(plate.axes.col(1).y(), -0.999);
  EXPECT_GT(plate.normal().z(), 0.999);
  EXPECT_NEAR(plate.centre.x(), (520.0451 + 57.0463 + 58.1765 + 521.1754) / 4, 1e-3);
  // every 25th sample where the plate carries more than 100 N (the channels hold the reaction on the
  // walker: Fz < 0 along the plate's downward z), by hand
  int checked = 0;
  for (int s = 40; s < fp.samples; s += 25) {
    const HandSample h = handSample(bytes, s);
    if (h.f.z() > -100.0) continue;
    ++checked;
    const mc::PlateReaction r = fp.reaction(0, s);
    EXPECT_NEAR((r.force - plate.axes * h.f).norm(), 0.0, 1e-6 * h.f.norm()) << "sample " << s;
    EXPECT_NEAR(r.normal_force, -h.f.z(), 1e-6 * std::abs(h.f.z()));
    const Eigen::Vector3d local = plate.axes.transpose() * (r.cop - plate.centre);
    EXPECT_NEAR(local.x(), h.cop_x, 1e-6) << "sample " << s;
    EXPECT_NEAR(local.y(), h.cop_y, 1e-6) << "sample " << s;
    EXPECT_NEAR(local.z(), 0.0, 1e-9);
    EXPECT_NEAR(r.free_moment, -h.tz, 1e-6 * std::max(1.0, std::abs(h.tz)));  // about the upward normal
  }
  EXPECT_GE(checked, 5);
}

TEST(ForcePlates, TheThreeProcessorFormatsGiveTheSameReactions) {
  const mc::ForcePlates pc = mc::readForcePlates(mc::readC3dFile(c3dtest::samplePath("pr")));
  for (const char* kind : {"sr", "vr"}) {
    const mc::ForcePlates other = mc::readForcePlates(mc::readC3dFile(c3dtest::samplePath(kind)));
    ASSERT_EQ(other.plates.size(), pc.plates.size()) << kind;
    ASSERT_EQ(other.samples, pc.samples) << kind;
    for (int p = 0; p < 2; ++p) {
      for (int s = 0; s < pc.samples; ++s) {
        ASSERT_LE((other.wrenchAt(p, s) - pc.wrenchAt(p, s)).norm(), 1e-9) << kind << " plate " << p << " sample " << s;
      }
    }
  }
}

// What the plates say must be physics: the reaction on a walker pushes up and out of the floor, and the
// centre of pressure lies on the loaded plate and under the foot standing on it (the foot's three markers
// RFT1-3 or LFT1-3, on the foot's top and side: the sole is within a foot's half length, 15 cm, of their
// centroid). A sign error in a moment, ORIGIN taken the other way or a corner order misread moves the CoP
// off the foot by up to the plate's size.
TEST(ForcePlates, TheRealWalkPushesUpWithItsCentreOfPressureOnThePlateAndUnderAFoot) {
  const mc::C3d c = mc::readC3dFile(c3dtest::samplePath("pr"));
  const mc::ForcePlates fp = mc::readForcePlates(c);
  int loaded = 0, under_foot = 0;
  for (int p = 0; p < 2; ++p) {
    const mc::ForcePlate& plate = fp.plates[static_cast<std::size_t>(p)];
    const Eigen::Vector3d half_x = 0.25 * ((plate.corners[0] + plate.corners[3]) - (plate.corners[1] + plate.corners[2]));
    const Eigen::Vector3d half_y = 0.25 * ((plate.corners[0] + plate.corners[1]) - (plate.corners[2] + plate.corners[3]));
    for (int f = 0; f < c.frames_present; ++f) {
      const mc::PlateReaction r = fp.frameReaction(p, f);
      if (r.normal_force < 200.0) continue;  // a foot on the plate, not its first or last touch
      ++loaded;
      EXPECT_GT(r.force.z(), 0.95 * r.force.norm()) << "plate " << p + 1 << " frame " << f << ": the reaction points up";
      const Eigen::Vector3d local = plate.axes.transpose() * (r.cop - plate.centre);
      EXPECT_LE(std::abs(local.x()), half_x.norm() + 5.0) << "plate " << p + 1 << " frame " << f;
      EXPECT_LE(std::abs(local.y()), half_y.norm() + 5.0) << "plate " << p + 1 << " frame " << f;
      double nearest = 1e9;
      for (const char* foot : {"RFT", "LFT"}) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        int n = 0;
        for (int k = 1; k <= 3; ++k) {
          const int i = c.pointIndex(std::string(foot) + std::to_string(k));
          if (i < 0) continue;
          if (const auto q = c.point(f, i)) {
            sum += Eigen::Vector3d((*q)[0], (*q)[1], (*q)[2]);
            ++n;
          }
        }
        if (n > 0) nearest = std::min(nearest, (sum / n - r.cop).head<2>().norm());
      }
      if (nearest <= 150.0) ++under_foot;
    }
  }
  ASSERT_GE(loaded, 40) << "the walk loads the plates for about a second";
  EXPECT_GE(under_foot, static_cast<int>(0.95 * loaded)) << under_foot << " of " << loaded << " loaded frames";
}

// A walker's centre of pressure rolls from heel to toe: on each plate it moves forward over the stance, in
// the direction the walker goes (from the plate stepped on first to the other), by more than 10 cm (a
// foot is 25 cm long). A moment taken with the wrong sign rolls it backwards.
TEST(ForcePlates, TheCentreOfPressureRollsFromHeelToToeInTheWalkingDirection) {
  const mc::C3d c = mc::readC3dFile(c3dtest::samplePath("pr"));
  const mc::ForcePlates fp = mc::readForcePlates(c);
  std::vector<int> first(2, -1), last(2, -1);
  for (int p = 0; p < 2; ++p) {
    for (int f = 0; f < c.frames_present; ++f) {
      if (fp.frameReaction(p, f).normal_force < 200.0) continue;
      if (first[static_cast<std::size_t>(p)] < 0) first[static_cast<std::size_t>(p)] = f;
      last[static_cast<std::size_t>(p)] = f;
    }
    ASSERT_GE(first[static_cast<std::size_t>(p)], 0) << "plate " << p + 1 << " is stepped on";
  }
  const int earlier = first[0] < first[1] ? 0 : 1, later = 1 - earlier;
  EXPECT_GT(first[static_cast<std::size_t>(later)], last[static_cast<std::size_t>(earlier)]) << "one foot on each plate, one after the other";
  const Eigen::Vector3d walk = (fp.plates[static_cast<std::size_t>(later)].centre - fp.plates[static_cast<std::size_t>(earlier)].centre).normalized();
  for (int p = 0; p < 2; ++p) {
    const Eigen::Vector3d heel = fp.frameReaction(p, first[static_cast<std::size_t>(p)]).cop;
    const Eigen::Vector3d toe = fp.frameReaction(p, last[static_cast<std::size_t>(p)]).cop;
    EXPECT_GT((toe - heel).dot(walk), 100.0) << "plate " << p + 1 << ": heel " << heel.transpose() << ", toe " << toe.transpose();
  }
}

// -- plates built in memory: types 1, 3 and 4 with loads computed by hand -----------------------------

mc::C3dParameter plateParameter(const std::string& name, std::vector<int> dims, std::vector<double> numbers) {
  mc::C3dParameter p;
  p.group = "FORCE_PLATFORM";
  p.name = name;
  p.type = 4;
  p.dims = std::move(dims);
  p.numbers = std::move(numbers);
  return p;
}

/// A one-frame, one-subframe file with one plate of `type` on channels 1..n holding `values`, its
/// corners a 400 × 600 plate at the lab origin with the plate's x along lab +X and z down.
mc::C3d memoryPlate(int type, const std::vector<double>& values, std::vector<double> origin = {0, 0, 0}) {
  mc::C3d c;
  c.file = "memory.c3d";
  c.frames_present = 1;
  c.rate = 100.0;
  c.analog_channels = static_cast<int>(values.size());
  c.analog_subframes = 1;
  c.analog_rate = 100.0;
  for (std::size_t k = 0; k < values.size(); ++k) {
    c.analog_labels.push_back("A" + std::to_string(k + 1));
    c.analog_stored.push_back(static_cast<float>(values[k]));
  }
  c.analog_scale.assign(values.size(), 1.0);
  c.analog_offset.assign(values.size(), 0.0);
  std::vector<double> channels;
  for (std::size_t k = 0; k < values.size(); ++k) channels.push_back(static_cast<double>(k + 1));
  c.parameters.push_back(plateParameter("USED", {}, {1}));
  c.parameters.push_back(plateParameter("TYPE", {1}, {static_cast<double>(type)}));
  c.parameters.push_back(plateParameter("CHANNEL", {static_cast<int>(values.size()), 1}, channels));
  // (+x +y), (-x +y), (-x -y), (+x -y) of a plate whose y is lab -Y: z = x × y is lab -Z (down)
  c.parameters.push_back(plateParameter("CORNERS", {3, 4, 1}, {200, -300, 0, -200, -300, 0, -200, 300, 0, 200, 300, 0}));
  c.parameters.push_back(plateParameter("ORIGIN", {3, 1}, std::move(origin)));
  return c;
}

/// Storage of the test's floats: channel values are exactly representable here.
void expectCop(const mc::PlateReaction& r, double x, double y) {
  // plate (x, y) is lab (x, -y) on the surface z = 0
  EXPECT_NEAR(r.cop.x(), x, 1e-4);
  EXPECT_NEAR(r.cop.y(), -y, 1e-4);
  EXPECT_NEAR(r.cop.z(), 0.0, 1e-9);
}

TEST(ForcePlates, Type1GivesItsCentreOfPressureAndFreeMomentBack) {
  // the reaction Fx Fy Fz (800 N up: -800 along the plate's z), CoP (30, -40) from the surface centre,
  // Tz 500 about the plate's z (down), i.e. -500 about the upward normal
  const mc::ForcePlates fp = mc::readForcePlates(memoryPlate(1, {20, -10, -800, 30, -40, 500}));
  const mc::PlateReaction r = fp.reaction(0, 0);
  expectCop(r, 30, -40);
  EXPECT_NEAR(r.free_moment, -500.0, 1e-6);
  EXPECT_NEAR(r.normal_force, 800.0, 1e-9);
  EXPECT_TRUE(r.force.isApprox(Eigen::Vector3d(20, 10, 800))) << r.force.transpose();  // (x, -y, -z)
}

TEST(ForcePlates, Type3KistlerSensorsGiveTheLoadPointUnderShear) {
  // sensors at (±a, ±b) = (±120, ±200), surface 50 above them (az0 = -50, plate z down); a reaction of
  // 1000 N up (W = -1000 along z) with shear Fx = 100, Fy = -60 at the surface point (x0, y0) = (30, -40). Moments about
  // the sensor-plane centre: My = az0 Fx - x0 W, Mx = y0 W - az0 Fy; the vertical sensors share W with
  // bilinear weights at the point (xe, ye) = (-My / W, Mx / W); the shear splits evenly.
  const double a = 120, b = 200, az0 = -50, w = -1000, fx = 100, fy = -60, x0 = 30, y0 = -40;
  const double my = az0 * fx - x0 * w, mx = y0 * w - az0 * fy;
  const double xe = -my / w, ye = mx / w;
  const double fz1 = w * (1 + xe / a) * (1 + ye / b) / 4, fz2 = w * (1 - xe / a) * (1 + ye / b) / 4;
  const double fz3 = w * (1 - xe / a) * (1 - ye / b) / 4, fz4 = w * (1 + xe / a) * (1 - ye / b) / 4;
  // Mz from the shear sensors: b(-fx12 + fx34) + a(fy14 - fy23) = 2 b d, with fx12 = fx/2 - d, fx34 = fx/2 + d
  const double d = 3.0;
  const mc::ForcePlates fp = mc::readForcePlates(
      memoryPlate(3, {fx / 2 - d, fx / 2 + d, fy / 2, fy / 2, fz1, fz2, fz3, fz4}, {a, b, az0}));
  const mc::PlateReaction r = fp.reaction(0, 0);
  expectCop(r, x0, y0);
  // the free moment: Mz less the moment of the shear applied at the CoP, Mz - (x0 Fy - y0 Fx), about the
  // plate's z; about the upward normal its opposite
  EXPECT_NEAR(r.free_moment, -(2 * b * d - (x0 * fy - y0 * fx)), 1e-3);
  EXPECT_NEAR(r.normal_force, 1000.0, 1e-6);
}

TEST(ForcePlates, Type4AppliesItsCalibrationMatrixStoredColumnByColumn) {
  // raw channels (10, 0, -400, 0, 0, 0) and C = 2 I except C(2, 0) = 0.5 (row Fz, column channel 1):
  // Fz = 2 × -400 + 0.5 × 10 = -795, Fx = 20; the matrix is stored first index fastest, (i, j) at i + 6 j
  mc::C3d c = memoryPlate(4, {10, 0, -400, 0, 0, 0}, {0, 0, -30});
  std::vector<double> cal(36, 0.0);
  for (int i = 0; i < 6; ++i) cal[static_cast<std::size_t>(i + 6 * i)] = 2.0;
  cal[2 + 6 * 0] = 0.5;
  c.parameters.push_back(plateParameter("CAL_MATRIX", {6, 6, 1}, cal));
  const mc::ForcePlates fp = mc::readForcePlates(c);
  EXPECT_TRUE(fp.wrenchAt(0, 0).isApprox((Eigen::Matrix<double, 6, 1>() << 20, 0, -795, 0, 0, 0).finished()))
      << fp.wrenchAt(0, 0).transpose();
  // shear at the transducer's origin, 30 below the surface: the line of action meets the surface at
  // px = (c Fx - My) / Fz = -30 × 20 / -795
  expectCop(fp.reaction(0, 0), -30.0 * 20 / -795, 0.0);
}

TEST(ForcePlates, AnOriginStoredTheOtherWayRoundIsTurnedRound) {
  // types 2 and 4: ORIGIN with z > 0 is the vector from the surface to the transducer; read as its opposite
  const std::vector<double> channels = {40, -25, -700, 9000, -12000, 800};
  const mc::ForcePlates usual = mc::readForcePlates(memoryPlate(2, channels, {3, -2, -40}));
  const mc::ForcePlates flipped = mc::readForcePlates(memoryPlate(2, channels, {-3, 2, 40}));
  EXPECT_TRUE(flipped.plates[0].origin.isApprox(Eigen::Vector3d(3, -2, -40)));
  EXPECT_TRUE(flipped.reaction(0, 0).cop.isApprox(usual.reaction(0, 0).cop, 1e-12));
  EXPECT_THROW((void)usual.reaction(1, 0), std::out_of_range);
  EXPECT_THROW((void)usual.frameReaction(0, 1), std::out_of_range);
}

TEST(ForcePlates, BelowTheThresholdThereIsNoCentreOfPressure) {
  const mc::ForcePlates fp = mc::readForcePlates(memoryPlate(2, {1, 2, -19.5, 0, 0, 0}, {0, 0, -40}));
  const mc::PlateReaction r = fp.reaction(0, 0);
  EXPECT_FALSE(r.cop.allFinite());
  EXPECT_EQ(r.free_moment, 0.0);
  EXPECT_NEAR(r.normal_force, 19.5, 1e-6);
}

// -- bad parameters: named, with the parameter's byte offset ------------------------------------------

/// The byte where the values of `p` start: name length, group id, name, next offset, type, dimensions.
std::size_t valuesAt(const std::string& bytes, const mc::C3dParameter& p) {
  const std::size_t name = static_cast<std::size_t>(std::abs(static_cast<signed char>(bytes[p.offset])));
  const std::size_t ndims = static_cast<unsigned char>(bytes[p.offset + 2 + name + 3]);
  return p.offset + 2 + name + 4 + ndims;
}

void putInt16(std::string& bytes, std::size_t at, int v) {
  bytes[at] = static_cast<char>(v & 0xff);
  bytes[at + 1] = static_cast<char>((v >> 8) & 0xff);
}

void expectPlateError(const std::string& bytes, const char* parameter, const std::string& text) {
  const mc::C3d c = mc::parseC3d(bytes, "plates.c3d");
  const mc::C3dParameter* p = c.find("FORCE_PLATFORM", parameter);
  try {
    (void)mc::readForcePlates(c);
    ADD_FAILURE() << "no error, expected '" << text << "'";
  } catch (const mc::C3dError& e) {
    EXPECT_EQ(e.file(), "plates.c3d");
    if (p != nullptr) {
      EXPECT_EQ(e.offset(), p->offset) << e.what();
    }
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(ForcePlates, BadParametersAreNamedWithTheirOffset) {
  const std::string good = c3dtest::fileBytes(c3dtest::samplePath("pr"));
  const mc::C3d c = mc::parseC3d(good, "plates.c3d");
  const mc::C3dParameter& type = *c.find("FORCE_PLATFORM", "TYPE");
  const mc::C3dParameter& channel = *c.find("FORCE_PLATFORM", "CHANNEL");
  const mc::C3dParameter& zero = *c.find("FORCE_PLATFORM", "ZERO");
  {  // an unknown type
    std::string bad = good;
    putInt16(bad, valuesAt(bad, type), 7);
    expectPlateError(bad, "TYPE", "FORCE_PLATFORM:TYPE of plate 1 is 7");
  }
  {  // type 4 without its calibration matrix
    std::string bad = good;
    putInt16(bad, valuesAt(bad, type) + 2, 4);
    expectPlateError(bad, "USED", "FORCE_PLATFORM:CAL_MATRIX is missing");
  }
  {  // five channels per plate for type 2 (CHANNEL's first dimension 6 -> 5)
    std::string bad = good;
    const std::size_t name = channel.name.size();
    bad[channel.offset + 2 + name + 4] = 5;
    expectPlateError(bad, "CHANNEL", "needs 6");
  }
  {  // a channel the file does not have
    std::string bad = good;
    putInt16(bad, valuesAt(bad, channel) + 2 * 3, 17);
    expectPlateError(bad, "CHANNEL", "the file has analog channels 1..16");
  }
  {  // a baseline after the last frame
    std::string bad = good;
    putInt16(bad, valuesAt(bad, zero), 451);
    putInt16(bad, valuesAt(bad, zero) + 2, 460);
    expectPlateError(bad, "ZERO", "FORCE_PLATFORM:ZERO = 451");
  }
  {  // a baseline running past the last frame is cut there; "0 10" reads as 1..10
    std::string cut = good, from_zero = good;
    putInt16(cut, valuesAt(cut, zero) + 2, 600);
    EXPECT_EQ(mc::readForcePlates(mc::parseC3d(cut, "cut.c3d")).plates[0].zero_last, 450);
    putInt16(from_zero, valuesAt(from_zero, zero), 0);
    const mc::ForcePlates fp = mc::readForcePlates(mc::parseC3d(from_zero, "zero.c3d"));
    EXPECT_EQ(fp.plates[0].zero_first, 1);
    EXPECT_EQ(fp.plates[0].zero_last, 10);
  }
  // degenerate corners (all four at one point)
  mc::C3d flat = memoryPlate(2, {0, 0, 100, 0, 0, 0}, {0, 0, -40});
  for (mc::C3dParameter& p : flat.parameters) {
    if (p.name == "CORNERS") std::fill(p.numbers.begin(), p.numbers.end(), 5.0);
  }
  EXPECT_THROW((void)mc::readForcePlates(flat), mc::C3dError);
}

}  // namespace
