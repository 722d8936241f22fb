// mannequin-c3d run as a separate process: its JSON parsed by python3's json module, exit codes,
// one-line errors naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include "../common/tool_run.hpp"
#include "samples.hpp"
namespace fs = std::filesystem;

namespace {
using c3dtest::samplePath;

using mannequin::testutil::slurp;
using mannequin::testutil::ToolResult;

fs::path toolPath() { return mannequin::testutil::binDir() / "mannequin-c3d"; }

class C3dTool : public mannequin::testutil::TempDirTest {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(toolPath())) << toolPath();
    ASSERT_TRUE(fs::exists(samplePath("pr"))) << samplePath("pr");
  }

  // a deadline: a hung tool fails the test (exit 124 from timeout) instead of hanging ctest
  ToolResult run(const std::string& args) { return mannequin::testutil::runTool(toolPath().string() + " " + args, 60); }

  // runs python3 `script` with json.load(sys.stdin) as `d` on `json`; returns its stdout (and stderr)
  std::string python(const std::string& json, const std::string& script) {
    const fs::path in = dir_ / "in.json";
    std::ofstream(in, std::ios::binary) << json;
    const ToolResult r = mannequin::testutil::runPython(dir_, "import json, sys\nd = json.load(sys.stdin)\n" + script, "<" + in.string());
    EXPECT_EQ(r.exit_code, 0) << r.out << "\non:\n" << json;
    return r.out;
  }

  std::string write(const std::string& name, const std::string& bytes) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << bytes;
    return p.string();
  }

};

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

TEST_F(C3dTool, InfoJsonHasTheDocumentedKeys) {
  for (const char* kind : {"pr", "sr", "vr"}) {
    const ToolResult r = run("info " + samplePath(kind) + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(lines(r.out), 1);
    EXPECT_EQ(python(r.out,
                     "print(d['points'], d['frames'], d['rate'], d['first_frame'], d['analog_per_frame'], "
                     "len(d['labels']), d['labels'][0], d['labels'][-1], d['units'], d['storage'], d['truncated'], "
                     "d['frames_present'])"),
              "26 450 50 1 64 26 RFT1 pv4 mm float False 450\n");
  }
  EXPECT_EQ(python(run("info " + samplePath("vr") + " --json").out, "print(d['processor'])"), "dec\n");
  EXPECT_EQ(python(run("info " + samplePath("sr") + " --json").out, "print(d['processor'])"), "mips\n");
}

TEST_F(C3dTool, PointsJsonAtFramesFromBothEnds) {
  const ToolResult r = run("points " + samplePath("pr") + " --frames 0,250,-1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines(r.out), 1);
  // frame 0 RFT1 as read by hand (see c3d_test.cpp), LFT1 invalid; -1 is frame 449
  EXPECT_EQ(python(r.out,
                   "print(sorted(d.keys(), key=int), len(d['0']), [round(v, 4) for v in d['0']['RFT1']], "
                   "d['0']['LFT1'], 'truncated' in d)"),
            "['0', '250', '449'] 26 [248.5833, 226.8333, 37.4167] None False\n");
  // a lone negative frame after a space
  const ToolResult last = run("points " + samplePath("pr") + " --frames -1 --json");
  ASSERT_EQ(last.exit_code, 0) << last.err;
  EXPECT_EQ(python(last.out, "print(list(d.keys()), d['449']['RFT1'])"), "['449'] [324.583344, 2248, 33.75]\n");
  // the three formats print the same thing
  EXPECT_EQ(run("points " + samplePath("sr") + " --frames 0,250,-1 --json").out, r.out);
  EXPECT_EQ(run("points " + samplePath("vr") + " --frames 0,250,-1 --json").out, r.out);
  // text form
  const ToolResult t = run("points " + samplePath("pr") + " --frames 0");
  EXPECT_EQ(t.exit_code, 0);
  EXPECT_NE(t.out.find("LFT1             invalid"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("RFT1             (    248.5833,     226.8333,      37.4167)"), std::string::npos) << t.out;
}

TEST_F(C3dTool, TruncatedFileIsReportedAndReadToItsLastWholeFrame) {
  const std::string bytes = slurp(samplePath("pr"));
  const std::string cut = write("cut.c3d", bytes.substr(0, 10 * 512 + 3 * 672 + 100));
  const ToolResult i = run("info " + cut + " --json");
  ASSERT_EQ(i.exit_code, 0) << i.err;
  EXPECT_EQ(python(i.out, "print(d['frames'], d['truncated'], d['frames_present'])"), "450 True 3\n");
  const ToolResult p = run("points " + cut + " --frames 0,-1 --json");
  ASSERT_EQ(p.exit_code, 0) << p.err;
  EXPECT_EQ(python(p.out, "print(sorted(k for k in d if k.isdigit()), d['truncated'], d['frames_present'])"),
            "['0', '2'] True 3\n");
  EXPECT_NE(run("info " + cut).out.find("TRUNCATED:  only 3 whole frames present of 450 declared"), std::string::npos);
  const ToolResult out = run("points " + cut + " --frames 3 --json");
  EXPECT_EQ(out.exit_code, 2);
  EXPECT_NE(out.err.find("frame 3 outside the 3 frames present"), std::string::npos) << out.err;
  EXPECT_NE(out.err.find("truncated"), std::string::npos) << out.err;
}

TEST_F(C3dTool, BadInputExitsTwoWithOneLineNamingTheFile) {
  const std::string missing = (dir_ / "missing.c3d").string();
  ToolResult r = run("info " + missing + " --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(r.out.empty());
  EXPECT_EQ(r.err, "mannequin-c3d: " + missing + ": byte 0: cannot open: No such file or directory\n");

  const std::string bytes = slurp(samplePath("pr"));
  const std::string short_header = write("short.c3d", bytes.substr(0, 100));
  r = run("points " + short_header + " --frames 0 --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err), 1);
  EXPECT_NE(r.err.find(short_header + ": byte 0: the 512-byte header runs past the end of the file"), std::string::npos)
      << r.err;

  std::string bad = bytes;
  bad[515] = 77;
  const std::string bad_proc = write("proc.c3d", bad);
  r = run("info " + bad_proc);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "mannequin-c3d: " + bad_proc + ": byte 515: unknown processor type 77 (84 Intel, 85 DEC, 86 SGI/MIPS)\n");

  r = run("points " + samplePath("pr") + " --frames 0,x --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "mannequin-c3d: --frames: expected a comma-separated list of integers, got 'x'\n");
  r = run("points " + samplePath("pr") + " --frames 450 --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(lines(r.err), 1);
  EXPECT_NE(r.err.find(samplePath("pr") + ": --frames: frame 450 outside the 450 frames present"), std::string::npos)
      << r.err;
  r = run("points " + samplePath("pr") + " --frames -451");
  EXPECT_EQ(r.exit_code, 2);
  r = run("points " + samplePath("pr"));  // --frames missing
  EXPECT_EQ(r.exit_code, 2);
  r = run("--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("info"), std::string::npos);
}

TEST_F(C3dTool, PlatesJsonPerFrameAndPerAnalogSample) {
  const ToolResult r = run("plates " + samplePath("pr") + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines(r.out), 1);
  // two type-2 plates, one entry per frame; the CoP null while a plate is unloaded, on the plate while loaded
  EXPECT_EQ(python(r.out,
                   "p = d['plates']\n"
                   "print(d['per'], d['rate'], d['count'], d['units'], len(p), [q['type'] for q in p], p[0]['channels'],\n"
                   "      [len(q['force']) for q in p], [len(q['cop']) for q in p], [len(q['free_moment']) for q in p],\n"
                   "      p[0]['cop'][0], any(c is not None for c in p[0]['cop']), [round(q['normal'][2], 3) for q in p])"),
            "frame 50 450 mm 2 [2, 2] ['FX1', 'FY1', 'FZ1', 'MX1', 'MY1', 'MZ1'] [450, 450] [450, 450] [450, 450] None True "
            "[1.0, 1.0]\n");
  const ToolResult analog = run("plates " + samplePath("vr") + " --json --analog");
  ASSERT_EQ(analog.exit_code, 0) << analog.err;
  EXPECT_EQ(python(analog.out, "print(d['per'], d['rate'], d['count'], len(d['plates'][1]['force']))"),
            "analog sample 200 1800 1800\n");
  // the text form names the plates and their load
  const ToolResult text = run("plates " + samplePath("sr"));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("plate 2:    type 2, channels FX2 FY2 FZ2 MX2 MY2 MZ2"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("mean normal force while loaded"), std::string::npos) << text.out;
  // a plate with an unknown type: exit 2, one line naming the file and the parameter
  std::string bytes = slurp(samplePath("pr"));
  const std::size_t at = bytes.find("TYPE");
  ASSERT_NE(at, std::string::npos);
  // TYPE's values: after the name, the next offset (2), the type (1), one dimension (1 + 1)
  bytes[at + 4 + 2 + 1 + 1 + 1] = 9;
  bytes[at + 4 + 2 + 1 + 1 + 2] = 0;
  const std::string bad = write("bad_type.c3d", bytes);
  const ToolResult e = run("plates " + bad);
  EXPECT_EQ(e.exit_code, 2);
  EXPECT_EQ(lines(e.err), 1) << e.err;
  EXPECT_NE(e.err.find(bad + ": byte "), std::string::npos) << e.err;
  EXPECT_NE(e.err.find("FORCE_PLATFORM:TYPE of plate 1 is 9"), std::string::npos) << e.err;
}

}  // namespace
