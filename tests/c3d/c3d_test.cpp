// C3D reader: the c3d.org samples (PC, SGI and DEC REAL formats of one capture), int16 files written
// by the test in the three processor formats, truncated and malformed inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "c3d_writer.hpp"
#include "mannequin/mocap/c3d.hpp"
#include "samples.hpp"

namespace mc = mannequin::mocap;
using c3dtest::WriteSpec;

namespace {
using c3dtest::samplePath;
using c3dtest::fileBytes;

// what the reader must say about `bytes`: a C3dError at `offset` whose message contains `text`
void expectError(const std::string& bytes, std::size_t offset, const std::string& text) {
  try {
    (void)mc::parseC3d(bytes, "bad.c3d");
    ADD_FAILURE() << "no error, expected '" << text << "' at byte " << offset;
  } catch (const mc::C3dError& e) {
    EXPECT_EQ(e.file(), "bad.c3d");
    EXPECT_EQ(e.offset(), offset) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("bad.c3d: byte " + std::to_string(offset) + ": ", 0), 0u) << e.what();
  }
}

class Samples : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    for (const char* k : {"pr", "sr", "vr"}) {
      const std::string path = samplePath(k);
      ASSERT_FALSE(fileBytes(path).empty()) << "missing sample " << path;
    }
  }
};

// -- the real files ------------------------------------------------------------------------------

// Values read by hand from the PC file (xxd): header words 0250 1a00 4000 0100 c201 ...
// = parameter block 2, key 0x50, 26 points, 64 analog samples per frame, frames 1..0x1c2 = 450,
// scale 0xbdaaaaab = -1/12 (float storage), data start block 11, frame rate 0x42480000 = 50 Hz;
// the parameter block starts 01 50 09 54 (9 blocks, processor 84 Intel). The first frame at byte
// 5120 starts with the floats 248.58334, 226.83334, 37.416668, 15888 (mask 0x3e, residual 16).
TEST_F(Samples, PcFileMatchesItsHeaderReadByHand) {
  const mc::C3d c = mc::readC3dFile(samplePath("pr"));
  EXPECT_EQ(c.processor, mc::C3dProcessor::kIntel);
  EXPECT_EQ(c.storage, mc::C3dStorage::kFloat);
  EXPECT_EQ(c.points, 26);
  EXPECT_EQ(c.analog_per_frame, 64);
  EXPECT_EQ(c.first_frame, 1);
  EXPECT_EQ(c.last_frame, 450);
  EXPECT_EQ(c.framesDeclared(), 450);
  EXPECT_EQ(c.frames_present, 450);
  EXPECT_FALSE(c.truncated);
  EXPECT_DOUBLE_EQ(c.rate, 50.0);
  EXPECT_NEAR(c.scale, -1.0 / 12.0, 1e-7);
  EXPECT_EQ(c.data_start_block, 11);
  EXPECT_EQ(c.units, "mm");
  ASSERT_EQ(c.labels.size(), 26u);
  EXPECT_EQ(c.labels.front(), "RFT1");
  EXPECT_EQ(c.labels[22], "PV1");
  EXPECT_EQ(c.labels.back(), "pv4");  // trimmed, case kept
  const auto p = c.point(0, 0);
  ASSERT_TRUE(p.has_value());
  EXPECT_FLOAT_EQ(static_cast<float>((*p)[0]), 248.58334f);
  EXPECT_FLOAT_EQ(static_cast<float>((*p)[1]), 226.83334f);
  EXPECT_FLOAT_EQ(static_cast<float>((*p)[2]), 37.416668f);
  EXPECT_NEAR(c.residual[0], 16.0 / 12.0, 1e-5);
  // LFT1 in frame 0 has a negative fourth word
  EXPECT_FALSE(c.point(0, 3).has_value());
  // parameters by name, any case
  ASSERT_NE(c.find("point", "labels"), nullptr);
  EXPECT_EQ(c.find("Point", "Used")->numbers.at(0), 26.0);
  EXPECT_EQ(c.find("POINT", "NO_SUCH"), nullptr);
  ASSERT_NE(c.find("ANALOG", "LABELS"), nullptr);
  EXPECT_EQ(c.find("ANALOG", "LABELS")->strings().at(0), "FX1");
}

TEST_F(Samples, ThreeProcessorFormatsAgree) {
  const mc::C3d pc = mc::readC3dFile(samplePath("pr"));
  const mc::C3d sgi = mc::readC3dFile(samplePath("sr"));
  const mc::C3d dec = mc::readC3dFile(samplePath("vr"));
  EXPECT_EQ(sgi.processor, mc::C3dProcessor::kMips);
  EXPECT_EQ(dec.processor, mc::C3dProcessor::kDec);
  int invalid = 0;
  for (const mc::C3d* other : {&sgi, &dec}) {
    EXPECT_EQ(other->labels, pc.labels);
    EXPECT_EQ(other->units, pc.units);
    EXPECT_EQ(other->frames_present, pc.frames_present);
    EXPECT_DOUBLE_EQ(other->rate, pc.rate);
    EXPECT_FLOAT_EQ(static_cast<float>(other->scale), static_cast<float>(pc.scale));
    ASSERT_EQ(other->parameters.size(), pc.parameters.size());
    for (std::size_t k = 0; k < pc.parameters.size(); ++k) {
      EXPECT_EQ(other->parameters[k].name, pc.parameters[k].name);
      EXPECT_EQ(other->parameters[k].group, pc.parameters[k].group);
      EXPECT_EQ(other->parameters[k].chars, pc.parameters[k].chars);
      ASSERT_EQ(other->parameters[k].numbers.size(), pc.parameters[k].numbers.size());
      for (std::size_t i = 0; i < pc.parameters[k].numbers.size(); ++i) {
        EXPECT_FLOAT_EQ(static_cast<float>(other->parameters[k].numbers[i]),
                        static_cast<float>(pc.parameters[k].numbers[i]))
            << pc.parameters[k].group << ":" << pc.parameters[k].name << "[" << i << "]";
      }
    }
    for (int f = 0; f < pc.frames_present; ++f) {
      for (int i = 0; i < pc.points; ++i) {
        const auto a = pc.point(f, i);
        const auto b = other->point(f, i);
        ASSERT_EQ(a.has_value(), b.has_value()) << "frame " << f << " point " << i;
        if (!a) {
          ++invalid;
          continue;
        }
        for (int d = 0; d < 3; ++d) {
          // the VAX conversion is exact for these values: the same float
          ASSERT_EQ(static_cast<float>((*a)[d]), static_cast<float>((*b)[d])) << "frame " << f << " point " << i;
        }
      }
    }
  }
  // 226 invalid samples in each file (counted with a Python struct read of the PC file)
  EXPECT_EQ(invalid, 2 * 226);
}

// -- int16 files written by the test -----------------------------------------------------------

TEST_F(Samples, Int16RoundTripInThreeFormats) {
  const mc::C3d real = mc::readC3dFile(samplePath("pr"));
  WriteSpec w = c3dtest::specFrom(real);
  double max_abs = 0;
  for (const float v : real.xyz) {
    if (std::isfinite(v)) max_abs = std::max(max_abs, double(std::abs(v)));
  }
  w.scale = max_abs / 32000.0;  // the int16 range, the quantisation step of the written file
  for (const auto proc : {mc::C3dProcessor::kIntel, mc::C3dProcessor::kDec, mc::C3dProcessor::kMips}) {
    w.processor = proc;
    const mc::C3d c = mc::parseC3d(c3dtest::writeC3d(w), "int16.c3d");
    SCOPED_TRACE(mc::c3dProcessorName(proc));
    EXPECT_EQ(c.processor, proc);
    EXPECT_EQ(c.storage, mc::C3dStorage::kInt16);
    EXPECT_EQ(c.labels, real.labels);
    EXPECT_EQ(c.frames_present, 450);
    EXPECT_FALSE(c.truncated);
    EXPECT_EQ(c.analog_per_frame, 6);
    EXPECT_FLOAT_EQ(static_cast<float>(c.scale), static_cast<float>(w.scale));
    EXPECT_DOUBLE_EQ(c.rate, 50.0);
    for (int f = 0; f < real.frames_present; ++f) {
      for (int i = 0; i < real.points; ++i) {
        const auto a = real.point(f, i);
        const auto b = c.point(f, i);
        ASSERT_EQ(a.has_value(), b.has_value()) << "frame " << f << " point " << i;
        if (!a) continue;
        for (int d = 0; d < 3; ++d) {
          // half a quantisation step, plus float rounding of the scale and the product
          ASSERT_NEAR((*a)[d], (*b)[d], 0.5 * w.scale + 1e-4) << "frame " << f << " point " << i;
        }
      }
    }
  }
}

TEST(C3dWriter, FloatStorageInThreeFormatsIsExact) {
  WriteSpec w;
  w.labels = {"A", "B"};
  w.scale = 0.5;
  w.frames = {{{1.25f, -2.5f, 1e4f, true, 1.0f}, {0, 0, 0, false, 0}},
              {{-3.0f, 0.0f, 7.75f, true, 2.0f}, {123.5f, -0.125f, 9.0f, true, 0.5f}}};
  for (const auto proc : {mc::C3dProcessor::kIntel, mc::C3dProcessor::kDec, mc::C3dProcessor::kMips}) {
    w.processor = proc;
    w.float_storage = true;
    const mc::C3d c = mc::parseC3d(c3dtest::writeC3d(w), "f.c3d");
    ASSERT_EQ(c.frames_present, 2);
    EXPECT_EQ(c.storage, mc::C3dStorage::kFloat);
    EXPECT_EQ(*c.point(0, 0), (std::array<double, 3>{1.25, -2.5, 1e4}));
    EXPECT_FALSE(c.point(0, 1).has_value());
    EXPECT_EQ(*c.point(1, 1), (std::array<double, 3>{123.5, -0.125, 9.0}));
    EXPECT_FLOAT_EQ(c.residual[1 * 2 + 0], 2.0f);
    EXPECT_EQ(c.pointIndex("B"), 1);
  }
}

// -- truncated files -----------------------------------------------------------------------------

TEST_F(Samples, TruncatedFileGivesTheWholeFramesBeforeTheCut) {
  const std::string bytes = fileBytes(samplePath("pr"));
  const mc::C3d full = mc::parseC3d(bytes, "full.c3d");
  const std::size_t data = 10 * 512;
  const std::size_t frame = (26 * 4 + 64) * 4;  // 672 bytes
  for (const std::size_t cut : {data + 3 * frame + frame / 2, data + 3 * frame, data + 3 * frame + 1, data + 1, data}) {
    const mc::C3d c = mc::parseC3d(bytes.substr(0, cut), "cut.c3d");
    const int whole = static_cast<int>((cut - data) / frame);
    SCOPED_TRACE(cut);
    EXPECT_TRUE(c.truncated);
    EXPECT_EQ(c.frames_present, whole);
    EXPECT_EQ(c.framesDeclared(), 450);
    ASSERT_EQ(c.xyz.size(), static_cast<std::size_t>(whole) * 26 * 3);
    for (int f = 0; f < whole; ++f) {
      for (int i = 0; i < 26; ++i) EXPECT_EQ(c.point(f, i), full.point(f, i));
    }
    EXPECT_THROW((void)c.point(whole, 0), std::out_of_range);
    if (whole > 0) {
      EXPECT_EQ(mc::resolveC3dFrame(c, -1), whole - 1);
    }
    EXPECT_THROW((void)mc::resolveC3dFrame(c, whole), std::out_of_range);
  }
  // a file cut inside its parameter section is malformed, not truncated (the FORCE_PLATFORM group's
  // description, 25 bytes from byte 598, is cut at 600)
  expectError(bytes.substr(0, 600), 598, "a group description runs past the end of the file (25 bytes needed, 2 left)");
}

// -- malformed inputs -----------------------------------------------------------------------------

TEST_F(Samples, MalformedInputsNameTheOffset) {
  const std::string good = fileBytes(samplePath("pr"));
  // a cut header
  expectError(good.substr(0, 100), 0, "the 512-byte header runs past the end of the file");
  expectError("", 0, "header");
  // bad magic
  std::string b = good;
  b[1] = 0x51;
  expectError(b, 1, "bad magic");
  // bad parameter block pointer: 0, and past the end of the file
  b = good;
  b[0] = 0;
  expectError(b, 0, "bad parameter block pointer 0");
  b = good.substr(0, 6000);
  b[0] = static_cast<char>(250);
  expectError(b, 0, "bad parameter block pointer 250: the parameter section (byte 127488) is past the end of the file (6000 bytes)");
  // unknown processor type
  b = good;
  b[515] = 99;
  expectError(b, 515, "unknown processor type 99");
  // the POINT group record's name length made huge: it runs past the parameter section's 9 blocks
  b = good.substr(0, 600);
  b[516] = 127;
  expectError(b, 518, "name and its next-record offset runs past the end of the file (129 bytes needed, 82 left)");
  // a header point count the parameters contradict
  b = good;
  b[2] = 27;
  try {
    (void)mc::parseC3d(b, "bad.c3d");
    ADD_FAILURE() << "no error";
  } catch (const mc::C3dError& e) {
    EXPECT_NE(std::string(e.what()).find("POINT:USED = 26 but the header (byte 2) declares 27 points"), std::string::npos)
        << e.what();
    EXPECT_GT(e.offset(), 512u);
  }
  // a data start block inside the header
  b = good;
  const mc::C3d c = mc::parseC3d(good, "x");
  const std::size_t data_start_at = c.find("POINT", "DATA_START")->offset;
  // the parameter record: name length, group, "DATA_START", next (2), type, ndims, value
  const std::size_t value_at = data_start_at + 2 + 10 + 2 + 2;
  b[value_at] = 1;
  b[value_at + 1] = 0;
  expectError(b, 16, "data start block 1 is not after the parameter block 2");
}

TEST(C3dMalformed, HugeCountsAreCheckedBeforeAllocating) {
  WriteSpec w;
  w.labels = {"A"};
  w.frames = {{{1, 2, 3, true, 0}}};
  std::string b = c3dtest::writeC3d(w);
  // header: 65535 points, 65535 analog, frames 1..65535; POINT:USED made 65535 too
  b[2] = b[3] = b[4] = b[5] = b[8] = b[9] = static_cast<char>(0xff);
  const mc::C3d ok = mc::parseC3d(c3dtest::writeC3d(w), "ok.c3d");
  const std::size_t used = ok.find("POINT", "USED")->offset + 2 + 4 + 2 + 2;
  b[used] = b[used + 1] = static_cast<char>(0xff);
  const mc::C3d c = mc::parseC3d(b, "huge.c3d");
  EXPECT_EQ(c.points, 65535);
  EXPECT_EQ(c.framesDeclared(), 65535);
  EXPECT_EQ(c.frames_present, 0);  // one frame of 65535 points and 65535 analog words needs 640 KB
  EXPECT_TRUE(c.truncated);
  EXPECT_TRUE(c.xyz.empty());
  EXPECT_EQ(c.labels.size(), 65535u);  // "P2".. for the points without a label
  EXPECT_EQ(c.labels[1], "P2");

  // a parameter whose dimensions ask for 255^4 floats
  c3dtest::Bytes p(mc::C3dProcessor::kIntel);
  p.s = b.substr(0, 512);
  p.s[2] = 1;
  p.s[3] = 0;
  p.u8(1);
  p.u8(0x50);
  p.u8(1);
  p.u8(84);
  c3dtest::param(p, 1, "BIG", 4, {255, 255, 255, 255}, {}, "", true);
  p.padTo(4 * 512);
  expectError(p.s, 512 + 4 + 2 + 3 + 2 + 2, "parameter BIG: dimensions give more data than the parameter section holds");

  // a scale so large that int16 samples times it overflow a float (found by fuzz-c3d: 4.4e35): refused
  WriteSpec big = w;
  big.scale = 4.4e35;
  expectError(c3dtest::writeC3d(big), 12, "is too large");
  // a last frame before the first
  std::string d = c3dtest::writeC3d(w);
  d[6] = 5;  // first frame 5, last frame 1
  expectError(d, 8, "last frame 1 before first frame 5");
  // a bad parameter type
  c3dtest::Bytes q(mc::C3dProcessor::kIntel);
  q.s = c3dtest::writeC3d(w).substr(0, 512);
  q.u8(1);
  q.u8(0x50);
  q.u8(1);
  q.u8(84);
  c3dtest::param(q, 1, "T", 3, {}, {}, "", true);
  q.padTo(4 * 512);
  expectError(q.s, 512 + 4 + 2 + 1 + 2, "bad type 3");
  // a next-record offset pointing backwards
  c3dtest::Bytes n(mc::C3dProcessor::kIntel);
  n.s = c3dtest::writeC3d(w).substr(0, 512);
  n.u8(1);
  n.u8(0x50);
  n.u8(1);
  n.u8(84);
  n.u8(1);
  n.u8(-1);
  n.str("G");
  n.i16(-10);
  n.u8(0);
  n.padTo(4 * 512);
  expectError(n.s, 512 + 4 + 2 + 1, "negative next-record offset -10");
}

TEST(C3dMalformed, GarbageNeverCrashesAndAcceptedFilesAreConsistent) {
  // mutations of a small valid file (a deterministic LCG): each one either throws C3dError naming a
  // byte inside the input, or gives a consistent result
  WriteSpec w;
  w.labels = {"A", "B", "C"};
  for (int f = 0; f < 4; ++f) w.frames.push_back({{1.0f * f, 2, 3, true, 1}, {4, 5, 6, f % 2 == 0, 1}, {7, 8, 9, true, 0}});
  const std::string base = c3dtest::writeC3d(w);
  std::uint64_t state = 12345;
  auto next = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<std::uint32_t>(state >> 33);
  };
  int errors = 0, accepted = 0;
  for (int it = 0; it < 3000; ++it) {
    std::string b = base;
    const int flips = 1 + static_cast<int>(next() % 8);
    for (int k = 0; k < flips; ++k) {
      // most mutations in the header and parameters, where the structure is
      const std::size_t at = next() % (next() % 4 == 0 ? b.size() : 1024);
      b[at] = static_cast<char>(next() & 0xff);
    }
    if (next() % 5 == 0) b.resize(next() % b.size());
    try {
      const mc::C3d c = mc::parseC3d(b, "g.c3d");
      ++accepted;
      ASSERT_GE(c.frames_present, 0);
      ASSERT_LE(c.frames_present, std::max(0, c.framesDeclared()));
      ASSERT_EQ(c.xyz.size(), 3 * static_cast<std::size_t>(c.frames_present) * static_cast<std::size_t>(c.points));
      ASSERT_EQ(c.labels.size(), static_cast<std::size_t>(c.points));
      for (int f = 0; f < c.frames_present; ++f) {
        for (int i = 0; i < c.points; ++i) {
          if (const auto p = c.point(f, i)) {
            for (const double v : *p) ASSERT_TRUE(std::isfinite(v));
          }
        }
      }
    } catch (const mc::C3dError& e) {
      ++errors;
      ASSERT_LE(e.offset(), b.size()) << e.what();
    }
  }
  // both outcomes are exercised
  EXPECT_GT(errors, 100);
  EXPECT_GT(accepted, 100);
}

TEST(C3dFile, MissingFileNamesIt) {
  try {
    (void)mc::readC3dFile("/nonexistent/x.c3d");
    ADD_FAILURE() << "no error";
  } catch (const mc::C3dError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/x.c3d: byte 0: cannot open: No such file or directory");
  }
}

}  // namespace
