// Damaged files: truncation at every byte offset, flipped bytes (chunk CRC, summary CRC),
// bad magic, unsupported compression, and a writer killed with SIGKILL mid-chunk.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <optional>

#include "../common/child_process.hpp"
#include "mannequin/core/process.hpp"
#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/recording/mcap_writer.hpp"
#include "test_files.hpp"

using namespace mannequin::recording;
using namespace mannequin::recording::testing;

namespace {

std::string smallFile(Compression compression, std::vector<Sent>* sent = nullptr) {
  const auto path = tempPath(std::string("small_") + compressionName(compression) + ".mcap");
  {
    McapWriterOptions o;
    o.compression = compression;
    o.chunk_size = 300;
    McapWriter w(path.string(), o);
    auto s = writeStream(w, 24);
    if (sent != nullptr) *sent = s;
  }
  std::string bytes = slurp(path);
  std::filesystem::remove(path);
  return bytes;
}

// "byte N" somewhere in the message
bool mentionsByte(const std::string& what) {
  for (std::size_t at = what.find("byte "); at != std::string::npos; at = what.find("byte ", at + 1)) {
    if (at + 5 < what.size() && std::isdigit(static_cast<unsigned char>(what[at + 5]))) return true;
  }
  return false;
}

class Truncation : public ::testing::TestWithParam<Compression> {};

TEST_P(Truncation, EveryPrefixIsAnErrorOrARecoveredPrefixOfCompleteChunks) {
  std::vector<Sent> sent;
  const std::string full = smallFile(GetParam(), &sent);
  const McapReader whole = McapReader::fromBytes(full, "full");
  ASSERT_GE(whole.chunkIndexes().size(), 4U);
  std::uint64_t data_end = 0;  // where the DataEnd record starts
  for (const ChunkIndex& c : whole.chunkIndexes()) data_end = std::max(data_end, c.chunk_start_offset + c.chunk_length + c.message_index_length);

  int errors = 0, recovered = 0;
  for (std::size_t n = 0; n < full.size(); ++n) {
    const std::string prefix = full.substr(0, n);
    std::optional<McapReader> r;
    try {
      r.emplace(McapReader::fromBytes(prefix, "cut"));
    } catch (const McapError& e) {
      ++errors;
      EXPECT_TRUE(mentionsByte(e.what())) << n << ": " << e.what();
      EXPECT_LE(n, 8U + 9U + 4U + 0U + 4U + std::string("mannequin-recording").size()) << "only a cut header may fail: " << e.what();
      continue;
    }
    ++recovered;
    EXPECT_TRUE(r->recovered()) << n;
    EXPECT_FALSE(r->indexed()) << n;
    EXPECT_NE(r->note().find("recovered"), std::string::npos) << r->note();
    // expected: the messages of every chunk that is complete in the prefix
    std::size_t complete = 0;
    for (const ChunkIndex& c : whole.chunkIndexes()) {
      if (c.chunk_start_offset + c.chunk_length <= n) {
        for (const auto& ci : c.message_index_offsets) (void)ci;
        ++complete;
      }
    }
    std::vector<Message> got;
    ASSERT_NO_THROW(got = r->readAll()) << n;
    EXPECT_EQ(r->chunkIndexes().size(), complete) << n;
    std::size_t expected_msgs = 0;
    for (const ChunkIndex& c : whole.chunkIndexes()) {
      if (c.chunk_start_offset + c.chunk_length <= n) {
        ReadFilter f;
        f.start = c.message_start_time;
        f.end = c.message_end_time;
        expected_msgs += whole.readAll(f).size();
      }
    }
    ASSERT_EQ(got.size(), expected_msgs) << n;
    for (std::size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i].data, sent[i].data) << n;  // a prefix of what was written
    }
    if (n >= data_end) {
      EXPECT_EQ(got.size(), sent.size()) << n;
    }
  }
  EXPECT_GT(errors, 0);
  EXPECT_GT(recovered, 0);
}

INSTANTIATE_TEST_SUITE_P(Compressions, Truncation, ::testing::Values(Compression::kNone, Compression::kZstd),
                         [](const auto& info) { return info.param == Compression::kZstd ? "zstd" : "none"; });

TEST(McapDamage, ChunkCrcCorruptionIsDetectedWithTheOffset) {
  const std::string full = smallFile(Compression::kNone);
  const McapReader whole = McapReader::fromBytes(full, "full");
  const ChunkIndex& c = whole.chunkIndexes().at(1);
  std::string bad = full;
  const std::uint64_t flip = c.chunk_start_offset + c.chunk_length - 3;  // inside a message payload
  bad[flip] ^= 0x20;
  const McapReader r = McapReader::fromBytes(bad, "flipped.mcap");
  EXPECT_TRUE(r.indexed());  // the summary is intact
  try {
    (void)r.readAll();
    FAIL() << "CRC mismatch not detected";
  } catch (const McapError& e) {
    const std::string want = "flipped.mcap: byte " + std::to_string(c.chunk_start_offset) + ": Chunk record: CRC mismatch";
    EXPECT_EQ(std::string(e.what()).rfind(want, 0), 0U) << e.what();
    EXPECT_EQ(e.offset(), c.chunk_start_offset);
  }
  EXPECT_THROW(r.verify(), McapError);
}

TEST(McapDamage, ZstdPayloadCorruptionIsDetected) {
  const std::string full = smallFile(Compression::kZstd);
  const McapReader whole = McapReader::fromBytes(full, "full");
  const ChunkIndex& c = whole.chunkIndexes().at(0);
  for (std::uint64_t k : {std::uint64_t{2}, c.compressed_size / 2, c.compressed_size - 2}) {
    std::string bad = full;
    bad[c.chunk_start_offset + c.chunk_length - c.compressed_size + k] ^= 0x5A;
    const McapReader r = McapReader::fromBytes(bad, "z.mcap");
    try {
      (void)r.readAll();
      ADD_FAILURE() << "corruption at +" << k << " not detected";
    } catch (const McapError& e) {
      EXPECT_TRUE(mentionsByte(e.what())) << e.what();
      EXPECT_NE(std::string(e.what()).find("Chunk record"), std::string::npos) << e.what();
    }
  }
}

TEST(McapDamage, CorruptSummaryFallsBackToLinearScan) {
  std::vector<Sent> sent;
  const std::string full = smallFile(Compression::kZstd, &sent);
  std::string bad = full;
  bad[bad.size() - 8 - 29 - 30] ^= 0x01;  // inside the summary offsets: summary CRC mismatch
  const McapReader r = McapReader::fromBytes(bad, "s.mcap");
  EXPECT_FALSE(r.indexed());
  EXPECT_TRUE(r.recovered());
  EXPECT_NE(r.note().find("summary section: CRC mismatch"), std::string::npos) << r.note();
  EXPECT_EQ(r.readAll().size(), sent.size());
}

TEST(McapDamage, NotAnMcapFile) {
  for (const std::string& bytes : {std::string(), std::string("hello"), std::string("\x89MCAP1\r\nxxxxxxxxxxxxxxxxxxx", 27),
                                   std::string("\x89MCAP0\r\n\x05\x00", 10)}) {
    try {
      (void)McapReader::fromBytes(bytes, "x.mcap");
      ADD_FAILURE() << "accepted " << bytes.size() << " bytes";
    } catch (const McapError& e) {
      EXPECT_TRUE(mentionsByte(e.what())) << e.what();
    }
  }
  try {
    (void)McapReader::fromBytes(std::string("\x89MCAP0\r\n\x05\x00\x00\x00\x00\x00\x00\x00\x00", 17), "x.mcap");
    FAIL();
  } catch (const McapError& e) {
    EXPECT_STREQ(e.what(), "x.mcap: byte 8: expected the Header record (opcode 0x01), found Message");
  }
  EXPECT_THROW((void)McapReader::open("/nonexistent/file.mcap"), McapError);
}

TEST(McapDamage, UnsupportedCompressionIsNamed) {
  const std::string full = smallFile(Compression::kZstd);
  const McapReader whole = McapReader::fromBytes(full, "full");
  std::string bad = full;
  // "zstd" -> "lz4\0"... keep the length: call it "lz4x"
  const std::uint64_t at = whole.chunkIndexes().at(0).chunk_start_offset + 9 + 28 + 4;
  ASSERT_EQ(bad.substr(at, 4), "zstd");
  bad.replace(at, 4, "lz4x");
  const McapReader r = McapReader::fromBytes(bad, "c.mcap");
  try {
    (void)r.readAll();
    FAIL();
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("unsupported compression 'lz4x'"), std::string::npos) << e.what();
  }
}

TEST(McapDamage, AbsurdSizesAreRejectedNotAllocated) {
  const std::string full = smallFile(Compression::kZstd);
  const McapReader whole = McapReader::fromBytes(full, "full");
  std::string bad = full;
  const std::uint64_t at = whole.chunkIndexes().at(0).chunk_start_offset + 9 + 16;  // uncompressed_size
  for (int i = 0; i < 8; ++i) bad[at + i] = static_cast<char>(0x7F);
  const McapReader r = McapReader::fromBytes(bad, "big.mcap");
  try {
    (void)r.readAll();
    FAIL();
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("exceeds the reader's limit"), std::string::npos) << e.what();
  }
}

TEST(McapCrash, WriterKilledMidChunkLosesAtMostTheOpenChunk) {
  const auto path = tempPath("killed.mcap");
  const int n = 1000;
  const pid_t pid = ::fork();
  ASSERT_NE(pid, -1) << "fork: " << std::strerror(errno);
  if (pid == 0) {
    McapWriterOptions o;
    o.chunk_size = 2000;
    McapWriter w(path.string(), o);
    writeStream(w, n);  // the last chunk stays open
    mannequin::core::signalProcess(::getpid(), SIGKILL);
    ::_exit(0);
  }
  const std::optional<int> code = mannequin::testutil::waitExitWithin(pid, std::chrono::seconds(30));
  if (!code) {
    mannequin::testutil::killAndReap(pid);
    FAIL() << "the writer process " << pid << " did not end within 30 s";
  }
  ASSERT_EQ(*code, 128 + SIGKILL) << "the writer process should die of SIGKILL";
  const McapReader r = McapReader::open(path.string());
  std::filesystem::remove(path);
  EXPECT_TRUE(r.recovered());
  EXPECT_NE(r.note().find("no footer"), std::string::npos) << r.note();
  const auto got = r.readAll();
  // every message of a finished chunk is there; the open chunk held < 2000 bytes (< 30 messages)
  EXPECT_GT(got.size(), static_cast<std::size_t>(n - 30));
  EXPECT_LT(got.size(), static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < got.size(); ++i) {
    ASSERT_EQ(got[i].sequence, i);
    ASSERT_EQ(got[i].data, payload(got[i].channel_id, static_cast<int>(i)));
  }
  EXPECT_EQ(r.channels().size(), 3U);
  EXPECT_EQ(r.schemas().size(), 1U);
}

}  // namespace
