// mannequin-record and mannequin-replay as processes: command lines, --info, damaged files
// (clear errors, the receiving process keeps running), and a replay into a recorder over ipc (the
// recorder is stopped once its file holds what was replayed, a wait with a deadline).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "../common/child_process.hpp"
#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/recording/mcap_writer.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;
using namespace mannequin::recording;
using namespace mannequin::recording::testing;

namespace {

fs::path binDir() { return fs::read_symlink("/proc/self/exe").parent_path().parent_path(); }

struct ToolRun {
  int status = -1;
  std::string out, err;
};

class ToolTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(binDir() / "mannequin-replay")) << binDir();
    ASSERT_TRUE(fs::exists(binDir() / "mannequin-record")) << binDir();
    dir_ = tempPath(std::string("tool_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  ToolRun run(const std::string& tool, const std::string& args) {
    const fs::path out = dir_ / (tool + ".out"), err = dir_ / (tool + ".err");
    const std::string cmd = (binDir() / ("mannequin-" + tool)).string() + " " + args + " </dev/null >" + out.string() +
                            " 2>" + err.string();
    const int raw = std::system(cmd.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(out), slurp(err)};
  }

  // A file of mocap.frame-like messages with real mannequin.v1 headers is not needed: the tools
  // carry payloads as bytes. Topic names must exist for the recorder to attach schemas.
  fs::path makeFile(const std::string& name, int n, Compression c = Compression::kZstd) {
    const fs::path p = dir_ / name;
    McapWriterOptions o;
    o.compression = c;
    o.chunk_size = 2048;
    McapWriter w(p.string(), o);
    const std::uint16_t ch = w.addChannel("mocap.frame", 0, "protobuf");
    for (int i = 0; i < n; ++i) {
      // a minimal MocapFrame: field 1 (Header) { sequence = i+1 (field 2), stamp_ns = i ms (field 4) }
      std::string header;
      header += '\x10';
      header += static_cast<char>((i + 1) & 0x7F);
      std::string msg;
      msg.push_back('\x0a');
      msg.push_back(static_cast<char>(header.size()));
      msg.append(header);
      msg.append(payload(0, i));
      w.write(ch, static_cast<std::uint32_t>(i), 1'000'000'000ULL + 1'000'000ULL * i, 0, msg);
    }
    return p;
  }

  fs::path dir_;
};

TEST_F(ToolTest, HelpAndBadCommandLines) {
  EXPECT_EQ(run("replay", "--help").status, 0);
  EXPECT_EQ(run("record", "--help").status, 0);
  EXPECT_EQ(run("replay", "").status, 2);
  EXPECT_EQ(run("record", "--out x.mcap").status, 2);  // no deployment, no --connect
  const fs::path f = makeFile("a.mcap", 10);
  EXPECT_EQ(run("replay", f.string()).status, 2);  // no --publish
  EXPECT_EQ(run("replay", f.string() + " --publish ipc:///tmp/x --rate 0").status, 2);
  EXPECT_EQ(run("replay", f.string() + " --publish ipc:///tmp/x --start 2 --end 1").status, 2);
  const ToolRun r = run("replay", f.string() + " --publish ipc://" + (dir_ / "x").string() + " --topics nope --wait-subscribers 0");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("topic 'nope' is not in the file (topics: mocap.frame)"), std::string::npos) << r.err;
}

TEST_F(ToolTest, InfoOfCleanTruncatedAndGarbageFiles) {
  const fs::path f = makeFile("clean.mcap", 300);
  ToolRun r = run("replay", f.string() + " --info");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("indexed (summary)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("messages   300 in"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mocap.frame"), std::string::npos) << r.out;

  const std::string bytes = slurp(f);
  const fs::path cut = dir_ / "cut.mcap";
  spit(cut, bytes.substr(0, bytes.size() * 2 / 3));
  r = run("replay", cut.string() + " --info");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("RECOVERED by linear scan"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("no footer"), std::string::npos) << r.out;

  const fs::path junk = dir_ / "junk.mcap";
  spit(junk, "this is not an mcap file at all");
  r = run("replay", junk.string() + " --info");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("junk.mcap: byte 0: not an MCAP file"), std::string::npos) << r.err;
}

using namespace std::chrono_literals;
using mannequin::testutil::Child;

// mannequin-record in the background, until stopped (flushing every 0.1 s: its file can be read back
// while it records).
std::vector<std::string> recorderArgs(const fs::path& bin, const std::string& endpoint, const fs::path& out) {
  return {bin.string(), "--connect", endpoint, "--out", out.string(), "--duration", "120", "--progress", "0", "--flush-interval", "0.1"};
}

// Waits until `file` (being written: read by the recovery scan) holds `n` messages; false after 30 s.
bool waitForMessages(const fs::path& file, std::size_t n) {
  const auto until = std::chrono::steady_clock::now() + 30s;
  for (;;) {
    std::size_t have = 0;
    try {
      have = McapReader::open(file.string()).readAll().size();
    } catch (const McapError&) {
      // nothing readable yet
    }
    if (have >= n) return true;
    if (std::chrono::steady_clock::now() >= until) {
      ADD_FAILURE() << file << " holds " << have << " of " << n << " messages after 30 s";
      return false;
    }
    std::this_thread::sleep_for(50ms);
  }
}

TEST_F(ToolTest, ReplayIntoRecorderKeepsEveryPayload) {
  const fs::path f = makeFile("src.mcap", 500);
  const std::string ep = "ipc://" + (dir_ / "replay.ipc").string();
  const fs::path back = dir_ / "back.mcap";
  Child rec(recorderArgs(binDir() / "mannequin-record", ep, back), (dir_ / "record.log").string());
  ASSERT_TRUE(rec.started());
  const ToolRun r = run("replay", f.string() + " --publish " + ep + " --fast --wait-subscribers 20");
  EXPECT_EQ(r.status, 0) << r.err;
  const McapReader a = McapReader::open(f.string());
  const auto ma = a.readAll();
  waitForMessages(back, ma.size());
  EXPECT_EQ(rec.stop(20s), 0) << slurp(dir_ / "record.log");
  const McapReader b = McapReader::open(back.string());
  const auto mb = b.readAll();
  ASSERT_EQ(mb.size(), ma.size()) << slurp(dir_ / "record.log");
  for (std::size_t i = 0; i < ma.size(); ++i) ASSERT_EQ(mb[i].data, ma[i].data) << i;
  // the recorder attached the mannequin.v1 schema of the topic
  ASSERT_EQ(b.channels().size(), 1U);
  const Channel& c = b.channels().begin()->second;
  EXPECT_EQ(c.topic, "mocap.frame");
  EXPECT_EQ(b.schemas().at(c.schema_id).name, "mannequin.v1.MocapFrame");
  EXPECT_EQ(b.schemas().at(c.schema_id).encoding, "protobuf");
  EXPECT_EQ(mb.front().sequence, 1U);  // from the payload's Header.sequence
}

TEST_F(ToolTest, DamagedFilesGiveClearErrorsAndTheReceiverKeepsRunning) {
  const fs::path f = makeFile("src.mcap", 400, Compression::kNone);
  const McapReader whole = McapReader::open(f.string());
  ASSERT_GE(whole.chunkIndexes().size(), 4U);
  const std::string bytes = slurp(f);
  // truncated in the middle of the third chunk: replays the first two, says so, exits 0
  const ChunkIndex& third = whole.chunkIndexes().at(2);
  const fs::path cut = dir_ / "cut.mcap";
  spit(cut, bytes.substr(0, third.chunk_start_offset + third.chunk_length / 2));
  // a flipped byte in the fourth chunk (summary intact): publishes up to it, then exit 1 naming the offset
  const ChunkIndex& fourth = whole.chunkIndexes().at(3);
  std::string flipped = bytes;
  flipped[fourth.chunk_start_offset + fourth.chunk_length - 2] ^= 0x01;
  const fs::path bad = dir_ / "bad.mcap";
  spit(bad, flipped);

  const std::string ep = "ipc://" + (dir_ / "replay.ipc").string();
  const fs::path back = dir_ / "back.mcap";
  Child rec(recorderArgs(binDir() / "mannequin-record", ep, back), (dir_ / "record.log").string());
  ASSERT_TRUE(rec.started());
  ToolRun r = run("replay", cut.string() + " --publish " + ep + " --fast --wait-subscribers 20");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("recovered 2 chunks"), std::string::npos) << r.err;
  r = run("replay", bad.string() + " --publish " + ep + " --fast --wait-subscribers 20");
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("bad.mcap: byte " + std::to_string(fourth.chunk_start_offset) + ": Chunk record: CRC mismatch"),
            std::string::npos)
      << r.err;
  // the receiving process was not disturbed and got the complete messages of both replays
  std::size_t first_two = 0, first_three = 0;
  for (int k = 0; k < 3; ++k) {
    ReadFilter rf;
    rf.start = whole.chunkIndexes()[k].message_start_time;
    rf.end = whole.chunkIndexes()[k].message_end_time;
    const std::size_t n = whole.readAll(rf).size();
    if (k < 2) first_two += n;
    first_three += n;
  }
  waitForMessages(back, first_two + first_three);
  EXPECT_EQ(rec.stop(20s), 0) << slurp(dir_ / "record.log");
  EXPECT_EQ(McapReader::open(back.string()).readAll().size(), first_two + first_three);
}

}  // namespace
