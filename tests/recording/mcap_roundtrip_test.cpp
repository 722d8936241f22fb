// Round trips (uncompressed and zstd, many chunks), statistics, seek by time, topic filter,
// time ordering across overlapping chunks.
#include <gtest/gtest.h>

#include <filesystem>

#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/recording/mcap_writer.hpp"
#include "test_files.hpp"

using namespace mannequin::recording;
using namespace mannequin::recording::testing;

namespace {

struct Written {
  std::vector<Sent> sent;
  std::string bytes;
};

Written writeFile(Compression compression, int n, std::uint64_t chunk_size) {
  const auto path = tempPath(std::string("rt_") + (compression == Compression::kZstd ? "zstd" : "none") + "_" +
                             std::to_string(n) + "_" + std::to_string(chunk_size) + ".mcap");
  Written out;
  {
    McapWriterOptions o;
    o.compression = compression;
    o.chunk_size = chunk_size;
    McapWriter w(path.string(), o);
    out.sent = writeStream(w, n);
    w.close();
  }
  out.bytes = slurp(path);
  std::filesystem::remove(path);
  return out;
}

void expectSame(const std::vector<Message>& got, const std::vector<Sent>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(got[i].channel_id, want[i].channel) << i;
    EXPECT_EQ(got[i].sequence, want[i].sequence) << i;
    EXPECT_EQ(got[i].log_time, want[i].log_time) << i;
    EXPECT_EQ(got[i].publish_time, want[i].log_time - 5) << i;
    ASSERT_EQ(got[i].data, want[i].data) << i;
  }
}

class RoundTrip : public ::testing::TestWithParam<Compression> {};

TEST_P(RoundTrip, ManyChunksEveryMessageBack) {
  const Written f = writeFile(GetParam(), 2000, 4096);
  const McapReader r = McapReader::fromBytes(f.bytes, "rt");
  EXPECT_TRUE(r.indexed());
  EXPECT_FALSE(r.recovered());
  EXPECT_TRUE(r.note().empty());
  EXPECT_GT(r.chunkIndexes().size(), 20U);
  for (const ChunkIndex& c : r.chunkIndexes()) {
    EXPECT_EQ(c.compression, GetParam() == Compression::kZstd ? "zstd" : "");
    EXPECT_EQ(c.message_index_offsets.empty(), false);
    if (GetParam() == Compression::kNone) {
      EXPECT_EQ(c.compressed_size, c.uncompressed_size);
    }
  }
  const Statistics& s = r.statistics();
  EXPECT_EQ(s.message_count, 2000U);
  EXPECT_EQ(s.schema_count, 1U);
  EXPECT_EQ(s.channel_count, 3U);
  EXPECT_EQ(s.chunk_count, r.chunkIndexes().size());
  EXPECT_EQ(s.message_start_time, 1'000'000'000U);
  EXPECT_EQ(s.message_end_time, 1'000'000'000U + 1999U * 1'000'000U);
  EXPECT_EQ(s.channel_message_counts.at(0), 1000U);
  EXPECT_EQ(s.channel_message_counts.at(1), 500U);
  EXPECT_EQ(s.channel_message_counts.at(2), 500U);
  EXPECT_EQ(r.channels().at(0).metadata.at("k"), "v");
  EXPECT_EQ(r.schemas().at(1).name, "test.Blob");
  expectSame(r.readAll(), f.sent);
  EXPECT_NO_THROW(r.verify());
  // the same through a real file
  const auto path = tempPath("rt_file.mcap");
  spit(path, f.bytes);
  const McapReader rf = McapReader::open(path.string());
  expectSame(rf.readAll(), f.sent);
  std::filesystem::remove(path);
}

INSTANTIATE_TEST_SUITE_P(Compressions, RoundTrip, ::testing::Values(Compression::kNone, Compression::kZstd),
                         [](const auto& info) { return info.param == Compression::kZstd ? "zstd" : "none"; });

TEST(McapRoundTrip, ZstdIsSmallerOnCompressibleData) {
  const Written plain = writeFile(Compression::kNone, 2000, 1 << 16);
  const Written zstd = writeFile(Compression::kZstd, 2000, 1 << 16);
  EXPECT_LT(zstd.bytes.size(), plain.bytes.size() * 3 / 4);
}

TEST(McapRoundTrip, SeekByTimeReadsOnlyOverlappingChunks) {
  const Written f = writeFile(Compression::kZstd, 2000, 4096);
  const McapReader r = McapReader::fromBytes(f.bytes, "seek");
  ReadFilter filter;
  filter.start = 1'000'000'000ULL + 1'000'000ULL * 1234;
  filter.end = 1'000'000'000ULL + 1'000'000ULL * 1300;  // inclusive
  std::vector<Sent> want(f.sent.begin() + 1234, f.sent.begin() + 1301);
  expectSame(r.readAll(filter), want);
  // past the end, before the start
  filter.start = 5'000'000'000ULL;
  filter.end = 6'000'000'000ULL;
  EXPECT_TRUE(r.readAll(filter).empty());
  filter.start = 0;
  filter.end = 999'999'999ULL;
  EXPECT_TRUE(r.readAll(filter).empty());
  // the chunks the cursor reads: corrupt every chunk outside the range; a ranged read still works
  std::string damaged = f.bytes;
  ReadFilter late;
  late.start = 1'000'000'000ULL + 1'000'000ULL * 1900;
  for (const ChunkIndex& c : r.chunkIndexes()) {
    if (c.message_end_time < late.start) damaged[c.chunk_start_offset + 9 + 8 + 8 + 8 + 4 + 4 + 8 + 5] ^= 0x55;
  }
  const McapReader rd = McapReader::fromBytes(damaged, "seek-damaged");
  EXPECT_TRUE(rd.indexed());
  expectSame(rd.readAll(late), std::vector<Sent>(f.sent.begin() + 1900, f.sent.end()));
  EXPECT_THROW(rd.readAll(), McapError);
}

TEST(McapRoundTrip, TopicFilter) {
  const Written f = writeFile(Compression::kNone, 400, 2048);
  const McapReader r = McapReader::fromBytes(f.bytes, "topics");
  ReadFilter filter;
  filter.topics = {"/b", "/c"};
  std::vector<Sent> want;
  for (const Sent& s : f.sent) {
    if (s.channel != 0) want.push_back(s);
  }
  expectSame(r.readAll(filter), want);
  filter.topics = {"/nope"};
  try {
    (void)r.readAll(filter);
    FAIL() << "unknown topic accepted";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("topic '/nope' is not in the file (topics: /a, /b, /c)"), std::string::npos)
        << e.what();
  }
}

TEST(McapRoundTrip, TopicFilterSkipsChunksWithoutTheTopic) {
  // topic /x only in the second half; damage every chunk of the first half: reading /x works
  const auto path = tempPath("skip.mcap");
  {
    McapWriterOptions o;
    o.compression = Compression::kNone;
    o.chunk_size = 512;
    McapWriter w(path.string(), o);
    const std::uint16_t a = w.addChannel("/a", 0, "json");
    const std::uint16_t x = w.addChannel("/x", 0, "json");
    for (int i = 0; i < 100; ++i) w.write(a, i, 1000 + i, 1000 + i, payload(a, i));
    w.flushChunk();
    for (int i = 100; i < 200; ++i) w.write(x, i, 1000 + i, 1000 + i, payload(x, i));
  }
  std::string bytes = slurp(path);
  std::filesystem::remove(path);
  const McapReader r = McapReader::fromBytes(bytes, "skip");
  for (const ChunkIndex& c : r.chunkIndexes()) {
    if (c.message_index_offsets.count(0) > 0) bytes[c.chunk_start_offset + 60] ^= 0x01;
  }
  const McapReader rd = McapReader::fromBytes(bytes, "skip-damaged");
  ReadFilter filter;
  filter.topics = {"/x"};
  const auto got = rd.readAll(filter);
  ASSERT_EQ(got.size(), 100U);
  EXPECT_EQ(got.front().sequence, 100U);
}

TEST(McapRoundTrip, OverlappingChunksComeOutInTimeOrder) {
  // two writers' worth of out-of-order log times: chunk 1 holds even times, chunk 2 odd times
  const auto path = tempPath("overlap.mcap");
  {
    McapWriterOptions o;
    o.chunk_size = 1 << 20;
    McapWriter w(path.string(), o);
    const std::uint16_t a = w.addChannel("/a", 0, "json");
    for (int i = 0; i < 50; ++i) w.write(a, i, 2 * i, 2 * i, "e");
    w.flushChunk();
    for (int i = 0; i < 50; ++i) w.write(a, 100 + i, 2 * (49 - i) + 1, 0, "o");  // descending within the chunk
  }
  const McapReader r = McapReader::open(path.string());
  std::filesystem::remove(path);
  const auto got = r.readAll();
  ASSERT_EQ(got.size(), 100U);
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i].log_time, i);
}

TEST(McapRoundTrip, WriterRejectsBadArguments) {
  const auto path = tempPath("bad.mcap");
  McapWriter w(path.string());
  EXPECT_THROW(w.addChannel("/a", 3, "protobuf"), McapError);  // no schema 3
  EXPECT_THROW(w.write(0, 0, 0, 0, "x"), McapError);           // no channel 0
  w.close();
  EXPECT_THROW(w.write(0, 0, 0, 0, "x"), McapError);  // closed
  std::filesystem::remove(path);
  McapWriterOptions o;
  o.zstd_level = 99;
  EXPECT_THROW(McapWriter(path.string(), o), McapError);
  EXPECT_THROW(McapWriter("/nonexistent-dir/x.mcap"), McapError);
}

}  // namespace
