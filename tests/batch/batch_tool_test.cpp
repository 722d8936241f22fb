// mannequin-batch as a separate process (build/bin/mannequin-batch): --help; 3 s of the shipped demo
// capture (configs/sim/sim_demo.yaml, data/bvh/cmu_max_131_03.bvh): DIR/run.mcap read back,
// DIR/summary.json checked with python's json module (the documented keys, scores in their ranges,
// histograms summing to the samples, worst frames that are the series' maxima), the same summary twice
// but for the wall-clock keys, DIR/report.html parsed by python's html.parser; --compare on the C3D lab
// capture (two columns, one MCAP per mannequin); bad inputs: exit 2, the file named, no report left.
#include <gtest/gtest.h>
#include <mannequin/v1/world.pb.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <utility>

#include "../common/tool_run.hpp"
#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/skeleton/anthropometry.hpp"
#include "mannequin/skeleton/kinematics.hpp"

namespace fs = std::filesystem;

namespace {

using mannequin::testutil::ToolResult;

fs::path toolPath() { return mannequin::testutil::binDir() / "mannequin-batch"; }

// Runs the tool under timeout(1) (a hung run fails at the deadline).
ToolResult run(const std::string& args, int timeout_s = 300, const std::string& env = "") {
  return mannequin::testutil::runTool((env.empty() ? "" : env + " ") + toolPath().string() + " " + args, timeout_s);
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
    for k in ('rula', 'reba', 'balance_distance_m', 'contacts', 'contact_force_n', 'penetration_m', 'tracking_error_m',
              'hand_force_l_n', 'hand_force_r_n'):
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
    for key in ('rula', 'reba'):  # at or above level i: the times at level i and higher
        at, above = r[key + '_time_at_action_level_s'], r[key + '_time_at_or_above_action_level_s']
        assert len(above) == len(at) and all(abs(above[i] - sum(at[i:])) < 1e-9 for i in range(len(at))), (at, above)
    for side, k in (('left', 'hand_force_l_n'), ('right', 'hand_force_r_n')):  # hand forces: the series' mean and max
        h, f = r['hand_force_n'][side], [x for x in s[k] if x is not None]
        assert len(f) == r['samples'] and all(x >= 0 for x in f), side
        assert abs(h['mean'] - sum(f) / len(f)) < 1e-6 * (1 + h['mean']) and h['max'] == max(f), (side, h)
        assert abs(h['max_load_kg'] - h['max'] / 9.80665) < 1e-9, h
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
assert p.svg == 6 * len(labels) and p.polylines >= 6 * len(labels), (p.svg, p.polylines)
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

// The snapshots of the worst postures: summary.json's `snapshots` (per_run, size, rendered) and each run's
// list; every file a valid PNG (signature, chunk CRCs, IHDR of the requested size, 8-bit RGB, the zlib
// data unfiltered to width x height pixels), not blank: the mannequin's colour (render::Style, first
// mannequin: blue (0.20, 0.45, 0.95), shaded) on at least 1 % of the pixels, centred horizontally (the
// view follows the pelvis); the samples the worst of the series, at least 0.5 s apart; report.html holds
// each picture inline, its base64 decoding to the file's bytes. argv: DIR, count per run, WIDTH, HEIGHT.
// Prints "no-gl: <error>" and exits 3 when the summary says no OpenGL context could be made.
const char* kSnapshotCheck = R"PY(
import base64, json, os, re, struct, sys, zlib
d, n, W, H = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
s = json.load(open(os.path.join(d, 'summary.json')))
sn = s['snapshots']
assert sn['per_run'] == n and sn['size'] == [W, H], sn
if not sn['rendered']:
    print('no-gl: %s' % sn['error']); sys.exit(3)
assert sn['error'] is None
html = open(os.path.join(d, 'report.html')).read()
inline = re.findall(r'<img src="data:image/png;base64,([A-Za-z0-9+/=]+)" width="(\d+)" height="(\d+)"', html)
assert len(inline) == n * len(s['runs']), len(inline)

def pixels(data):
    assert data[:8] == b'\x89PNG\r\n\x1a\n', 'not a PNG signature'
    pos, idat, ihdr = 8, b'', None
    while pos < len(data):
        length, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        crc, = struct.unpack('>I', data[pos + 8 + length:pos + 12 + length])
        assert zlib.crc32(kind + body) & 0xffffffff == crc, 'bad CRC in %r' % kind
        if kind == b'IHDR': ihdr = struct.unpack('>IIBBBBB', body)
        if kind == b'IDAT': idat += body
        pos += 12 + length
        if kind == b'IEND': break
    w, h, depth, colour, _, _, interlace = ihdr
    assert (w, h) == (W, H), (w, h)
    assert depth == 8 and colour == 2 and interlace == 0, ihdr
    raw, stride, rows, prev = zlib.decompress(idat), 3 * w, [], bytearray(3 * w)
    assert len(raw) == h * (stride + 1), len(raw)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - 3] if i >= 3 else 0
            b = prev[i]
            c = prev[i - 3] if i >= 3 else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c; pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
            else: assert f == 0, 'filter %d' % f
        rows.append(line); prev = line
    return rows

k = 0
for r in s['runs']:
    shots, ser = r['snapshots'], r['series']
    assert len(shots) == n, len(shots)
    assert shots[0]['rula'] == r['rula']['max'], (shots[0], r['rula']['max'])
    for a in shots:
        i = min(range(len(ser['time_s'])), key=lambda i: abs(ser['time_s'][i] - a['time_s']))
        assert abs(ser['time_s'][i] - a['time_s']) < 1e-9 and ser['rula'][i] == a['rula'] and ser['reba'][i] == a['reba'], a
        assert all(abs(a['time_s'] - b['time_s']) >= 0.5 for b in shots if b is not a), shots
    assert all((x['rula'], x['reba']) >= (y['rula'], y['reba']) for x, y in zip(shots, shots[1:])), shots
    for a in shots:
        data = open(os.path.join(d, a['file']), 'rb').read()
        b64, w, h = inline[k]; k += 1
        assert base64.b64decode(b64) == data and (int(w), int(h)) == (W, H), a['file']
        rows = pixels(data)
        blue = [(x, y) for y, row in enumerate(rows) for x in range(W)
                if row[3 * x + 2] > 90 and row[3 * x + 2] > 1.6 * row[3 * x] and row[3 * x + 2] > 1.25 * row[3 * x + 1]]
        assert len(blue) >= 0.01 * W * H, ('too few mannequin pixels', a['file'], len(blue))
        cx = sum(x for x, _ in blue) / len(blue)
        assert 0.25 * W < cx < 0.75 * W, ('mannequin not centred', a['file'], cx)
        assert len({bytes(row[3 * x:3 * x + 3]) for row in rows for x in range(0, W, 7)}) > 20, 'too few colours'
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

TEST_F(BatchTool, SnapshotsOfTheWorstPosturesArePngsOfTheRequestedSizeShowingTheMannequin) {
  const fs::path dir = temp("snapshots");
  const ToolResult r = run(kDemo + " --mannequin configs/mannequins/male_50th.yaml --duration 3 --snapshots 2 "
                                   "--snapshot-size 320x200 --out " + dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto [s, out] = python(kSnapshotCheck, dir.string() + " 2 320 200");
  if (s == 3) GTEST_SKIP() << "no headless OpenGL here (" << out << "); tools/setup installs Mesa's EGL";
  EXPECT_EQ(s, 0) << out;
  EXPECT_TRUE(fs::exists(dir / "snapshots" / "male_50th_1.png"));
  EXPECT_TRUE(fs::exists(dir / "snapshots" / "male_50th_2.png"));
  EXPECT_FALSE(fs::exists(dir / "snapshots" / "male_50th_3.png"));
  fs::remove_all(dir);
}

TEST_F(BatchTool, WithoutAnOpenGlContextTheReportSaysSoAndTheRunSucceeds) {
  // no EGL vendor library for glvnd to load: HeadlessContext cannot be made
  const fs::path dir = temp("no_gl");
  const ToolResult r = run("--snapshots 2 " + kDemo + " --mannequin configs/mannequins/male_50th.yaml --duration 1 --out " + dir.string(),
                           300, "env __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/egl_vendor.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto [s, out] = python(kSnapshotCheck, dir.string() + " 2 640 360");
  if (s == 0) GTEST_SKIP() << "the EGL driver could not be taken away with __EGL_VENDOR_LIBRARY_FILENAMES (libEGL is not glvnd's?)";
  EXPECT_EQ(s, 3) << out;
  EXPECT_NE(out.find("no-gl: headless"), std::string::npos) << out;
  EXPECT_NE(r.err.find("no snapshots"), std::string::npos) << r.err;
  const std::string report = mannequin::testutil::slurp(dir / "report.html");
  EXPECT_NE(report.find("class=\"no-snapshots\""), std::string::npos);
  EXPECT_NE(report.find("were not rendered"), std::string::npos);
  EXPECT_EQ(report.find("<img"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "snapshots"));
  EXPECT_TRUE(fs::exists(dir / "summary.json"));
  fs::remove_all(dir);
}

// The left shoulder joint centre (world) of every calibrated sim.world state of a recording, by forward
// kinematics of the model built here from the mannequin config and the state's q (not the batch's numbers).
std::vector<Eigen::Vector3d> shoulders(const fs::path& mcap, const mannequin::skeleton::Model& model, const std::string& joint) {
  mannequin::skeleton::Data data(model);
  const int j = model.findJoint(joint);
  std::vector<Eigen::Vector3d> out;
  for (const auto& m : mannequin::recording::McapReader::open(mcap.string()).readAll()) {
    mannequin::v1::WorldState w;
    if (!w.ParseFromString(m.data) || w.mannequins_size() != 1 || !w.mannequins(0).calibrated()) continue;
    Eigen::VectorXd q(w.mannequins(0).q_size());
    for (int i = 0; i < q.size(); ++i) q(i) = w.mannequins(0).q(i);
    mannequin::skeleton::forwardKinematics(model, data, q);
    out.push_back(data.oMi[static_cast<std::size_t>(j)].p);
  }
  return out;
}

TEST_F(BatchTool, ReachTargetBeyondArmsLengthIsAMissByTheModelsDistanceAndOneInsideIsReached) {
  namespace sk = mannequin::skeleton;
  const sk::Model model = sk::buildMannequin(sk::loadMannequinSpec("configs/mannequins/male_50th.yaml"));
  // the left arm's length, straight in the anatomical posture: shoulder -> elbow -> wrist -> palm point
  sk::Data data(model);
  sk::forwardKinematics(model, data, model.neutralConfiguration());
  const auto at = [&](const char* joint) { return data.oMi[static_cast<std::size_t>(model.findJoint(joint))].p; };
  const Eigen::Vector3d palm = data.oMf[static_cast<std::size_t>(model.findFrame("palm_l"))].p;
  const double arm = (at("elbow_l") - at("shoulder_l")).norm() + (at("wrist_l") - at("elbow_l")).norm() + (palm - at("wrist_l")).norm();
  ASSERT_GT(arm, 0.5);
  ASSERT_LT(arm, 0.8);

  // where the shoulder goes in this capture (a first run; the batch is deterministic)
  const std::string args = kDemo + " --mannequin configs/mannequins/male_50th.yaml --duration 3 --snapshots 0 --out ";
  const fs::path first = temp("reach_first");
  ToolResult r = run(args + first.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::vector<Eigen::Vector3d> s = shoulders(first / "run.mcap", model, "shoulder_l");
  ASSERT_GT(s.size(), 100u);
  const Eigen::Vector3d mid = s[s.size() / 2];
  // beyond: 0.3 m more than the arm above the shoulder at mid-run; inside: 0.2 m in front of it
  const Eigen::Vector3d far = mid + Eigen::Vector3d(0, 0, arm + 0.3), near = mid + Eigen::Vector3d(0.2, 0, 0);
  const fs::path targets = temp("targets.yaml");
  std::ofstream(targets) << "targets:\n"
                         << "  - {name: above, hand: left, point: [" << far.x() << ", " << far.y() << ", " << far.z() << "]}\n"
                         << "  - {name: front, hand: left, point: [" << near.x() << ", " << near.y() << ", " << near.z() << "]}\n";
  const fs::path dir = temp("reach");
  r = run(args + dir.string() + " --reach " + targets.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  s = shoulders(dir / "run.mcap", model, "shoulder_l");
  double best_far = -1e9, best_near = -1e9;  // max over samples of arm length - distance
  for (const Eigen::Vector3d& p : s) {
    best_far = std::max(best_far, arm - (far - p).norm());
    best_near = std::max(best_near, arm - (near - p).norm());
  }
  ASSERT_LT(best_far, -0.1);  // the target is out of reach in every sample
  ASSERT_GT(best_near, 0.1);

  const YAML::Node summary = YAML::LoadFile((dir / "summary.json").string());  // JSON is YAML
  const YAML::Node reach = summary["runs"][0]["reach"];
  ASSERT_TRUE(reach.IsSequence());
  ASSERT_EQ(reach.size(), 2u);
  EXPECT_EQ(reach[0]["name"].as<std::string>(), "above");
  EXPECT_EQ(reach[0]["hand"].as<std::string>(), "left");
  EXPECT_FALSE(reach[0]["reached"].as<bool>());
  EXPECT_NEAR(reach[0]["miss_m"].as<double>(), -best_far, 0.01);
  EXPECT_NEAR(reach[0]["arm_length_m"].as<double>(), arm, 0.01);
  EXPECT_EQ(reach[0]["reached_samples"].as<long long>(), 0);
  EXPECT_EQ(reach[0]["samples"].as<std::size_t>(), s.size());
  EXPECT_EQ(reach[1]["name"].as<std::string>(), "front");
  EXPECT_TRUE(reach[1]["reached"].as<bool>());
  EXPECT_EQ(reach[1]["miss_m"].as<double>(), 0.0);
  EXPECT_NEAR(reach[1]["best_margin_m"].as<double>(), best_near, 0.01);
  EXPECT_GT(reach[1]["reached_samples"].as<long long>(), 0);

  // the report's reach table: one row per target, "missed by" / "reached"
  const std::string report = mannequin::testutil::slurp(dir / "report.html");
  EXPECT_NE(report.find("<table id=\"reach\">"), std::string::npos);
  char missed[64];
  std::snprintf(missed, sizeof missed, "missed by %.3f m", reach[0]["miss_m"].as<double>());
  EXPECT_NE(report.find(missed), std::string::npos) << missed;
  EXPECT_NE(report.find("<td class=\"reached\">reached"), std::string::npos);

  // a target file with a typo: FILE:LINE, exit 2, no report
  const fs::path bad = temp("bad_targets.yaml");
  std::ofstream(bad) << "targets:\n  - name: a\n    point: [0, 0, 1]\n    hand: middle\n";
  const fs::path bad_dir = temp("reach_bad");
  r = run(args + bad_dir.string() + " --reach " + bad.string());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find(bad.string() + ":4"), std::string::npos) << r.err;
  expectNoReport(bad_dir);
  fs::remove_all(first);
  fs::remove_all(dir);
}

// The report in a browser: headless Chromium driven over the DevTools protocol (tests/batch/console_check.py)
// loads report.html and fails on any console error (console.error, an uncaught exception, a resource that
// does not load). The check itself is shown to fail on a page with a deliberate error.
TEST_F(BatchTool, ReportOpensInHeadlessChromiumWithoutConsoleErrors) {
  std::string chromium;
  for (const char* name : {"chromium", "chromium-browser"}) {
    const ToolResult which = mannequin::testutil::runTool(std::string("sh -c 'command -v ") + name + "'", 10);
    if (which.exit_code == 0 && !which.out.empty()) {
      chromium = which.out.substr(0, which.out.find('\n'));
      break;
    }
  }
  if (chromium.empty()) GTEST_SKIP() << "chromium is not installed (tools/setup installs Debian's chromium): report.html not opened";
  const fs::path dir = temp("browser");
  const ToolResult r = run(kDemo + " --mannequin configs/mannequins/male_50th.yaml --compare configs/mannequins/female_05th.yaml "
                                   "--duration 2 --snapshots 1 --snapshot-size 240x160 --reach configs/reach/demo.yaml --out " +
                           dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path bad = temp("deliberate_error.html");
  std::ofstream(bad) << "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>x</title></head><body>\n"
                     << "<script>undefinedFunction();</script></body></html>\n";
  const std::string check = "python3 tests/batch/console_check.py " + chromium + " ";
  ToolResult c = mannequin::testutil::runTool(check + bad.string(), 120);
  EXPECT_EQ(c.exit_code, 1) << c.out << c.err;  // the check catches an error
  EXPECT_NE(c.out.find("ReferenceError: undefinedFunction is not defined"), std::string::npos) << c.out << c.err;
  c = mannequin::testutil::runTool(check + (dir / "report.html").string(), 120);
  EXPECT_EQ(c.exit_code, 0) << c.out << c.err;
  EXPECT_NE(c.out.find("report.html: no console errors"), std::string::npos) << c.out << c.err;
  fs::remove_all(dir);
}

TEST_F(BatchTool, CompareOnTheC3dCaptureGivesTwoColumns) {
  // the c3d.org lab walk through `source: c3d` (configs/mappings/c3d_sample01.yaml: pelvis and feet)
  const fs::path dir = temp("compare");
  const ToolResult r = run("--mocap data/c3d/sample01_Eb015pr.c3d --mannequin configs/mannequins/male_50th.yaml "
                        "--compare configs/mannequins/female_05th.yaml --duration 2 --snapshots 2 --snapshot-size 240x160 --out " +
                           dir.string());
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
  std::tie(s, out) = python(kSnapshotCheck, dir.string() + " 2 240 160");  // both mannequins pictured
  EXPECT_TRUE(s == 0 || s == 3) << out;
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
