// Byte-level check of a tiny file against the MCAP spec layout, written out by hand here
// (independent of the library's encoder): magic, opcodes, lengths, field order, CRCs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "mannequin/recording/mcap.hpp"
#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/recording/mcap_writer.hpp"

namespace fs = std::filesystem;
using namespace mannequin::recording;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// little-endian helpers, spelled out
std::string u8(unsigned v) { return std::string(1, static_cast<char>(v)); }
std::string le(std::uint64_t v, int n) {
  std::string s;
  for (int i = 0; i < n; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  return s;
}
std::string u16(std::uint64_t v) { return le(v, 2); }
std::string u32(std::uint64_t v) { return le(v, 4); }
std::string u64(std::uint64_t v) { return le(v, 8); }
std::string str(const std::string& s) { return u32(s.size()) + s; }
std::string record(unsigned op, const std::string& content) { return u8(op) + u64(content.size()) + content; }

fs::path tempFile(const std::string& name) {
  return fs::temp_directory_path() / ("mcap_layout_" + std::to_string(::getpid()) + "_" + name);
}

}  // namespace

TEST(Crc32, CheckValue) {
  // the standard check value of CRC-32/ISO-HDLC (zlib's crc32)
  EXPECT_EQ(crc32("123456789", 9), 0xCBF43926U);
  EXPECT_EQ(crc32("", 0), 0U);
  // incremental = one shot
  EXPECT_EQ(crc32("6789", 4, crc32("12345", 5)), 0xCBF43926U);
}

TEST(McapLayout, TinyUncompressedFileMatchesSpecByteForByte) {
  const fs::path path = tempFile("tiny.mcap");
  {
    McapWriterOptions o;
    o.library = "t";
    o.compression = Compression::kNone;
    McapWriter w(path.string(), o);
    const std::uint16_t s = w.addSchema("S", "protobuf", std::string("\x0a\x00", 2));
    const std::uint16_t c = w.addChannel("a", s, "protobuf");
    w.write(c, 7, 1000, 990, "abc");
    w.close();
  }
  const std::string file = slurp(path);
  fs::remove(path);

  const std::string magic("\x89MCAP0\r\n", 8);
  std::string x = magic;
  x += record(0x01, str("") + str("t"));                                                  // Header
  x += record(0x03, u16(1) + str("S") + str("protobuf") + str(std::string("\x0a\x00", 2)));  // Schema
  x += record(0x04, u16(0) + u16(1) + str("a") + str("protobuf") + u32(0));              // Channel, empty map
  const std::string msg = record(0x05, u16(0) + u32(7) + u64(1000) + u64(990) + "abc");  // Message
  ASSERT_EQ(msg.size(), 9U + 25U);
  const std::uint64_t chunk_at = x.size();
  const std::string chunk =
      record(0x06, u64(1000) + u64(1000) + u64(msg.size()) + u32(crc32(msg.data(), msg.size())) + str("") +
                       u64(msg.size()) + msg);
  x += chunk;
  const std::uint64_t index_at = x.size();
  const std::string mindex = record(0x07, u16(0) + u32(16) + u64(1000) + u64(0));  // offset 0 in the chunk
  x += mindex;
  const std::uint32_t data_crc = crc32(x.data(), x.size());
  x += record(0x0F, u32(data_crc));  // DataEnd
  const std::uint64_t summary_start = x.size();
  const std::string schema_rec = record(0x03, u16(1) + str("S") + str("protobuf") + str(std::string("\x0a\x00", 2)));
  const std::string channel_rec = record(0x04, u16(0) + u16(1) + str("a") + str("protobuf") + u32(0));
  const std::string stats_rec = record(0x0B, u64(1) + u16(1) + u32(1) + u32(0) + u32(0) + u32(1) + u64(1000) +
                                                 u64(1000) + u32(10) + u16(0) + u64(1));
  const std::string cindex_rec = record(0x08, u64(1000) + u64(1000) + u64(chunk_at) + u64(chunk.size()) + u32(10) +
                                                  u16(0) + u64(index_at) + u64(mindex.size()) + str("") +
                                                  u64(msg.size()) + u64(msg.size()));
  std::string summary = schema_rec + channel_rec + stats_rec + cindex_rec;
  const std::uint64_t summary_offset_start = summary_start + summary.size();
  std::uint64_t at = summary_start;
  for (const auto& [op, rec] : {std::pair<unsigned, std::string>{0x03, schema_rec}, {0x04, channel_rec},
                                {0x0B, stats_rec}, {0x08, cindex_rec}}) {
    summary += record(0x0E, u8(op) + u64(at) + u64(rec.size()));
    at += rec.size();
  }
  x += summary;
  std::string footer = u8(0x02) + u64(20) + u64(summary_start) + u64(summary_offset_start);
  const std::uint32_t summary_crc = crc32(footer.data(), footer.size(), crc32(summary.data(), summary.size()));
  footer += u32(summary_crc);
  x += footer + magic;

  ASSERT_EQ(file.size(), x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    ASSERT_EQ(static_cast<int>(static_cast<unsigned char>(file[i])), static_cast<int>(static_cast<unsigned char>(x[i])))
        << "first difference at byte " << i;
  }
  // and the reader agrees with it
  const McapReader r = McapReader::fromBytes(file, "tiny");
  EXPECT_TRUE(r.indexed());
  EXPECT_FALSE(r.recovered());
  EXPECT_EQ(r.library(), "t");
  ASSERT_EQ(r.schemas().size(), 1U);
  EXPECT_EQ(r.schemas().at(1).data, std::string("\x0a\x00", 2));
  ASSERT_EQ(r.channels().size(), 1U);
  EXPECT_EQ(r.channels().at(0).topic, "a");
  EXPECT_EQ(r.statistics().message_count, 1U);
  const auto msgs = r.readAll();
  ASSERT_EQ(msgs.size(), 1U);
  EXPECT_EQ(msgs[0].data, "abc");
  EXPECT_EQ(msgs[0].sequence, 7U);
  EXPECT_EQ(msgs[0].log_time, 1000U);
  EXPECT_EQ(msgs[0].publish_time, 990U);
}

TEST(McapLayout, EmptyFileIsHeaderDataEndSummaryFooter) {
  const fs::path path = tempFile("empty.mcap");
  {
    McapWriterOptions o;
    o.library = "";
    McapWriter w(path.string(), o);
  }  // destructor closes
  const std::string file = slurp(path);
  fs::remove(path);
  // magic 8 + Header 9+8 + DataEnd 9+4, Statistics 9+46, SummaryOffset 9+17, Footer 9+20, magic 8
  ASSERT_EQ(file.size(), 8U + 17U + 13U + 55U + 26U + 29U + 8U);
  EXPECT_EQ(file.substr(0, 8), std::string("\x89MCAP0\r\n", 8));
  EXPECT_EQ(static_cast<unsigned char>(file[8]), 0x01);
  EXPECT_EQ(static_cast<unsigned char>(file[25]), 0x0F);
  EXPECT_EQ(static_cast<unsigned char>(file[38]), 0x0B);
  EXPECT_EQ(file.substr(file.size() - 8), std::string("\x89MCAP0\r\n", 8));
  const McapReader r = McapReader::fromBytes(file, "empty");
  EXPECT_TRUE(r.indexed());
  EXPECT_EQ(r.statistics().message_count, 0U);
  EXPECT_TRUE(r.readAll().empty());
}
