// mannequin-batch as a separate process (build/bin/mannequin-batch): --help; 3 s of the shipped demo
// capture (configs/sim/sim_demo.yaml, data/bvh/cmu_max_131_03.bvh): DIR/run.mcap read back,
// DIR/summary.json checked with python's json module (the documented keys, scores in their ranges,
// histograms summing to the samples, worst frames that are the series' maxima), the same summary twice
// but for the wall-clock keys, DIR/report.html parsed by python's html.parser; --compare on the C3D lab
// capture (two columns, one MCAP per mannequin); bad inputs: exit 2, the file named, no report left.
#include <gtest/gtest.h>
#include <mannequin/v1/world.pb.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <utility>

#include "../common/tool_run.hpp"
#include "mannequin/recording/mcap_reader.hpp"

namespace fs = std::filesystem;

namespace {

using mannequin::testutil::ToolResult;

fs::path toolPath() { return mannequin::testutil::binDir() / "mannequin-batch"; }

// Runs the tool under timeout(1) (a hung run fails at the deadline).
ToolResult run(const std::string& args, int timeout_s = 300) {
  return mannequin::testutil::runTool(toolPath().string() + " " + args, timeout_s);
}

// summary.json: the documented keys and values that make sense, for `runs` runs of `seconds` s at 60 Hz
// with the control frames `frames` (comma separated), at least `min_samples` scored.
const char* kSummaryCheck = R"PY(
import json, sys
d = json.load(open(sys.argv[1]))
labels, seconds, frames = sys.argv[2].split(','), float(sys.argv[3]), sorted(sys.argv[4].split(','))
min_samples = int(sys.argv[5])  # scored samples at least (before calibration a sample has no score)
assert d['tool'] == 'mannequin-batch' and d['sample_rate_hz'] == 60
assert [r['label'] for r in d['runs']] == labels, [r['label'] for r in d['runs']]
for r in d['runs']:
    assert abs(r['sim_time_s'] - seconds) < 1e-9 and r['steps'] == round(seconds * 1000), (r['sim_time_s'], r['steps'])
    assert r['nan_steps'] == 0
    s = r['series']
    n = len(s['time_s'])
    assert n == round(seconds * 60), n
    for k in ('rula', 'reba', 'balance_distance_m', 'contacts', 'contact_force_n', 'penetration_m', 'tracking_error_m'):
        assert len(s[k]) == n, k
    assert min_samples <= r['samples'] <= n, r['samples']
    for key, top in (('rula', 7), ('reba', 15)):
        e = r[key]
        h = e['histogram']
        assert sorted(int(k) for k in h) == list(range(1, top + 1))
        assert sum(h.values()) == r['samples'], (key, h)
        scores = [x for x in s[key] if x is not None]
        assert len(scores) == r['samples'] and all(1 <= x <= top for x in scores)
        assert e['max'] == max(scores) and 1 <= e['max'] <= top
        assert all(h[str(k)] == scores.count(k) for k in range(1, top + 1))
        w = e['worst_frames']
        assert 1 <= len(w) <= 10 and w[0]['score'] == e['max']
        assert all(a['score'] >= b['score'] for a, b in zip(w, w[1:]))
        for f in w:  # a worst frame is a sample of the series with that score
            i = min(range(n), key=lambda i: abs(s['time_s'][i] - f['time_s']))
            assert abs(s['time_s'][i] - f['time_s']) < 1e-9 and s[key][i] == f['score'], f
    assert abs(sum(r['rula_time_at_action_level_s']) - r['samples'] / 60.0) < 1e-6
    t = r['tracking_error']
    assert sorted(t['per_control_frame']) == frames, sorted(t['per_control_frame'])
    for f in t['per_control_frame'].values():
        assert 0 <= f['mean_m'] <= f['max_m'] < 0.5 and f['samples'] > 0, f
    # physics on (the floor): standing on it, less than 1 cm in it, the CoM within 0.2 m inside the support
    assert 0 <= r['max_penetration_m'] < 0.01 and r['max_contacts'] > 0 and r['foot_contact_fraction'] > 0.5
    assert -1.0 < r['min_balance_distance_m'] < 0.2
    c = r['contact_force_n']
    assert 0 < c['mean'] <= c['p95'] <= c['max'], c
    assert r['time_per_step_us']['mean'] > 0 and r['time_per_step_us']['max'] >= r['time_per_step_us']['mean']
    assert r['wall_s'] > 0 and r['realtime_factor'] > 0
print('ok')
)PY";

// report.html: its svg elements, the worst-frames tables, the mannequins' columns, nothing from the network
const char* kHtmlCheck = R"PY(
import sys
from html.parser import HTMLParser
class P(HTMLParser):
    def __init__(self):
        super().__init__(); self.svg = 0; self.polylines = 0; self.worst = 0; self.rows = 0; self.cols = []; self.th = False
        self.scripts = 0; self.external = 0; self.in_worst = False
    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == 'svg': self.svg += 1
        if tag == 'polyline': self.polylines += 1
        if tag == 'script': self.scripts += 1
        if any(v and ('http://' in v or 'https://' in v) for k, v in attrs if k in ('src', 'href')): self.external += 1
        if tag == 'table' and 'worst-frames' in (a.get('class') or ''): self.worst += 1; self.in_worst = True
        if tag == 'tr' and self.in_worst: self.rows += 1
        if tag == 'th' and a.get('class') == 'mannequin': self.th = True
    def handle_endtag(self, tag):
        if tag == 'table': self.in_worst = False
        if tag == 'th': self.th = False
    def handle_data(self, data):
        if self.th: self.cols.append(data)
p = P(); p.feed(open(sys.argv[1]).read()); p.close()
labels = sys.argv[2].split(',')
assert p.cols == labels, p.cols
assert p.svg == 4 * len(labels) and p.polylines >= 4 * len(labels), (p.svg, p.polylines)
assert p.worst == len(labels) and p.rows >= 2 * len(labels), (p.worst, p.rows)
assert p.scripts == 0 and p.external == 0
print('ok')
)PY";

const char* kNoWallClock = R"PY(
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
for d in (a, b):
    for r in d['runs']:
        for k in d['wall_clock_keys']: del r[k]
assert a == b
print('ok')
)PY";

const std::string kDemo = "--config configs/sim/sim_demo.yaml --mocap data/bvh/cmu_max_131_03.bvh";
const std::string kSixFrames = "foot_l,foot_r,hand_l,hand_r,head,pelvis";

void expectNoReport(const fs::path& dir) {
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  EXPECT_FALSE(fs::exists(dir / "report.html"));
  EXPECT_FALSE(fs::exists(dir / ".partial"));
}

// Each test's files (temp(name)) in a directory of its own, removed after it.
class BatchTool : public mannequin::testutil::TempDirTest {
 protected:
  // Runs python3 `script` with sys.argv[1:] = args; its exit status and stdout+stderr.
  std::pair<int, std::string> python(const std::string& script, const std::string& args) const {
    const ToolResult r = mannequin::testutil::runPython(dir_, script, args);
    return {r.exit_code, r.out};
  }
};

}  // namespace

TEST_F(BatchTool, HelpExitsZero) {
  ASSERT_TRUE(fs::exists(toolPath())) << toolPath();
  const ToolResult r = run("--help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("--compare"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--mocap"), std::string::npos) << r.out;
}

TEST_F(BatchTool, DemoCaptureWritesMcapSummaryAndReportDeterministically) {
  const fs::path dir = temp("demo"), again = temp("demo_again");
  const std::string args = kDemo + " --mannequin configs/mannequins/male_50th.yaml --duration 3 --out ";
  const ToolResult a = run(args + dir.string());
  ASSERT_EQ(a.exit_code, 0) << a.err;
  ASSERT_TRUE(fs::exists(dir / "summary.json"));
  ASSERT_TRUE(fs::exists(dir / "report.html"));
  ASSERT_TRUE(fs::exists(dir / "run.mcap"));
  EXPECT_FALSE(fs::exists(dir / ".partial"));

  auto [s, out] = python(kSummaryCheck, (dir / "summary.json").string() + " male_50th 3 " + kSixFrames + " 175");  // calibrated at the BVH's first frames
  EXPECT_EQ(s, 0) << out;
  std::tie(s, out) = python(kHtmlCheck, (dir / "report.html").string() + " male_50th");
  EXPECT_EQ(s, 0) << out;

  // run.mcap: the sim.world messages at the world rate (3 s at 60 Hz)
  const auto reader = mannequin::recording::McapReader::open((dir / "run.mcap").string());
  ASSERT_EQ(reader.channels().size(), 1u);
  EXPECT_EQ(reader.channels().begin()->second.topic, "sim.world");
  const auto messages = reader.readAll();
  EXPECT_EQ(messages.size(), 180u);
  mannequin::v1::WorldState w;
  ASSERT_FALSE(messages.empty());
  ASSERT_TRUE(w.ParseFromString(messages.back().data));
  ASSERT_EQ(w.mannequins_size(), 1);

  const ToolResult b = run(args + again.string());
  ASSERT_EQ(b.exit_code, 0) << b.err;
  std::tie(s, out) = python(kNoWallClock, (dir / "summary.json").string() + " " + (again / "summary.json").string());
  EXPECT_EQ(s, 0) << out;
  fs::remove_all(dir);
  fs::remove_all(again);
}

TEST_F(BatchTool, CompareOnTheC3dCaptureGivesTwoColumns) {
  // the c3d.org lab walk through `source: c3d` (configs/mappings/c3d_sample01.yaml: pelvis and feet)
  const fs::path dir = temp("compare");
  const ToolResult r = run("--mocap data/c3d/sample01_Eb015pr.c3d --mannequin configs/mannequins/male_50th.yaml "
                        "--compare configs/mannequins/female_05th.yaml --duration 2 --out " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "male_50th" / "run.mcap"));
  EXPECT_TRUE(fs::exists(dir / "female_05th" / "run.mcap"));
  EXPECT_FALSE(fs::exists(dir / "run.mcap"));
  for (const char* m : {"male_50th", "female_05th"})  // 2 s of sim.world at 60 Hz each
    EXPECT_EQ(mannequin::recording::McapReader::open((dir / m / "run.mcap").string()).readAll().size(), 120u) << m;
  auto [s, out] = python(kSummaryCheck, (dir / "summary.json").string() + " male_50th,female_05th 2 foot_l,foot_r,pelvis 1");
  EXPECT_EQ(s, 0) << out;
  std::tie(s, out) = python(kHtmlCheck, (dir / "report.html").string() + " male_50th,female_05th");
  EXPECT_EQ(s, 0) << out;
  fs::remove_all(dir);
}

TEST_F(BatchTool, BadInputsNameTheFileExitTwoAndLeaveNoReport) {
  const fs::path dir = temp("bad");
  const std::string m = " --mannequin configs/mannequins/male_50th.yaml --duration 1 --out " + dir.string();
  // an unreadable capture
  const fs::path missing = temp("missing.c3d");
  ToolResult r = run("--mocap " + missing.string() + m);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(missing.string()), std::string::npos) << r.err;
  expectNoReport(dir);

  // a truncated C3D file
  const fs::path truncated = temp("truncated.c3d");
  {
    std::ifstream in("data/c3d/sample01_Eb015pr.c3d", std::ios::binary);
    std::string bytes(3000, '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    std::ofstream(truncated, std::ios::binary) << bytes;
  }
  r = run("--mocap " + truncated.string() + m);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(truncated.string()), std::string::npos) << r.err;
  expectNoReport(dir);

  // a NaN sample in a BVH capture: its line
  const fs::path nan = temp("nan.bvh");
  {
    std::ifstream in("data/bvh/cmu_max_131_03.bvh");
    std::ofstream o(nan);
    std::string line;
    int after_frame_time = -1, lineno = 0;
    while (std::getline(in, line)) {
      ++lineno;
      if (line.rfind("Frame Time", 0) == 0) after_frame_time = 0;
      else if (after_frame_time >= 0 && ++after_frame_time == 20) line = "nan " + line.substr(line.find(' ') + 1);
      o << line << '\n';
    }
  }
  r = run("--mocap " + nan.string() + " --config configs/sim/sim_demo.yaml" + m);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(nan.string() + ":"), std::string::npos) << r.err;
  expectNoReport(dir);

  // a mannequin config with a typo on line 3
  const fs::path mannequin = temp("bad_mannequin.yaml");
  std::ofstream(mannequin) << "name: m\nstature_m: 1.75\nmass_kgg: 70\n";
  r = run(kDemo + " --mannequin configs/mannequins/male_50th.yaml --compare " + mannequin.string() + " --out " + dir.string());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(mannequin.string() + ":3"), std::string::npos) << r.err;
  expectNoReport(dir);
  // nothing of the good mannequin's run either (every input is read before the first run)
  EXPECT_FALSE(fs::exists(dir / "male_50th"));

  // a complete earlier report in DIR is not left looking like this run's
  const ToolResult good = run(kDemo + m);
  ASSERT_EQ(good.exit_code, 0) << good.err;
  ASSERT_TRUE(fs::exists(dir / "summary.json"));
  r = run("--mocap " + missing.string() + m);
  EXPECT_EQ(r.exit_code, 2);
  expectNoReport(dir);
  for (const fs::path& p : {truncated, nan, mannequin}) fs::remove(p);
  fs::remove_all(dir);
}
