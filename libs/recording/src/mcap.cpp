#include "mannequin/recording/mcap.hpp"

#include <zlib.h>

#include <cstdio>

#include "wire.hpp"

namespace mannequin::recording {

std::uint32_t crc32(const void* data, std::size_t n, std::uint32_t crc) {
  // zlib's: the same CRC (a running value continues across calls), several bytes per step
  return static_cast<std::uint32_t>(::crc32_z(crc, static_cast<const Bytef*>(data), n));
}

std::string opcodeName(std::uint8_t opcode) {
  switch (static_cast<Opcode>(opcode)) {
    case Opcode::kHeader: return "Header";
    case Opcode::kFooter: return "Footer";
    case Opcode::kSchema: return "Schema";
    case Opcode::kChannel: return "Channel";
    case Opcode::kMessage: return "Message";
    case Opcode::kChunk: return "Chunk";
    case Opcode::kMessageIndex: return "MessageIndex";
    case Opcode::kChunkIndex: return "ChunkIndex";
    case Opcode::kAttachment: return "Attachment";
    case Opcode::kAttachmentIndex: return "AttachmentIndex";
    case Opcode::kStatistics: return "Statistics";
    case Opcode::kMetadata: return "Metadata";
    case Opcode::kMetadataIndex: return "MetadataIndex";
    case Opcode::kSummaryOffset: return "SummaryOffset";
    case Opcode::kDataEnd: return "DataEnd";
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "opcode 0x%02X", opcode);
  return buf;
}

const char* compressionName(Compression compression) { return compression == Compression::kZstd ? "zstd" : ""; }

namespace wire {

void appendRecord(std::string& out, Opcode op, const std::string& content) {
  Out o(out);
  o.u8(static_cast<std::uint8_t>(op));
  o.u64(content.size());
  o.raw(content);
}

void writeSchema(std::string& out, const Schema& s) {
  Out o(out);
  o.u16(s.id);
  o.str(s.name);
  o.str(s.encoding);
  o.str(s.data);
}

void writeChannel(std::string& out, const Channel& c) {
  Out o(out);
  o.u16(c.id);
  o.u16(c.schema_id);
  o.str(c.topic);
  o.str(c.message_encoding);
  std::string map;
  Out m(map);
  for (const auto& [k, v] : c.metadata) {
    m.str(k);
    m.str(v);
  }
  o.str(map);
}

void writeMessage(std::string& out, const Message& msg) {
  Out o(out);
  o.u16(msg.channel_id);
  o.u32(msg.sequence);
  o.u64(msg.log_time);
  o.u64(msg.publish_time);
  o.raw(msg.data);
}

void writeChunkIndex(std::string& out, const ChunkIndex& c) {
  Out o(out);
  o.u64(c.message_start_time);
  o.u64(c.message_end_time);
  o.u64(c.chunk_start_offset);
  o.u64(c.chunk_length);
  std::string map;
  Out m(map);
  for (const auto& [ch, off] : c.message_index_offsets) {
    m.u16(ch);
    m.u64(off);
  }
  o.str(map);
  o.u64(c.message_index_length);
  o.str(c.compression);
  o.u64(c.compressed_size);
  o.u64(c.uncompressed_size);
}

void writeStatistics(std::string& out, const Statistics& s) {
  Out o(out);
  o.u64(s.message_count);
  o.u16(s.schema_count);
  o.u32(s.channel_count);
  o.u32(s.attachment_count);
  o.u32(s.metadata_count);
  o.u32(s.chunk_count);
  o.u64(s.message_start_time);
  o.u64(s.message_end_time);
  std::string map;
  Out m(map);
  for (const auto& [ch, n] : s.channel_message_counts) {
    m.u16(ch);
    m.u64(n);
  }
  o.str(map);
}

Schema readSchema(In& in) {
  Schema s;
  s.id = in.u16("id");
  s.name = in.str("name");
  s.encoding = in.str("encoding");
  s.data = in.str("data");
  if (s.id == 0) in.fail("schema id 0 is reserved (spec: must not be zero)");
  return s;
}

Channel readChannel(In& in) {
  Channel c;
  c.id = in.u16("id");
  c.schema_id = in.u16("schema_id");
  c.topic = in.str("topic");
  c.message_encoding = in.str("message_encoding");
  const std::uint32_t len = in.u32("metadata");
  In m = in.sub(len, "metadata");
  while (m.remaining() > 0) {
    std::string k = m.str("metadata key");
    c.metadata[k] = m.str("metadata value");
  }
  return c;
}

Message readMessage(In& in) {
  Message m;
  m.channel_id = in.u16("channel_id");
  m.sequence = in.u32("sequence");
  m.log_time = in.u64("log_time");
  m.publish_time = in.u64("publish_time");
  m.data = in.rest();
  return m;
}

ChunkIndex readChunkIndex(In& in) {
  ChunkIndex c;
  c.message_start_time = in.u64("message_start_time");
  c.message_end_time = in.u64("message_end_time");
  c.chunk_start_offset = in.u64("chunk_start_offset");
  c.chunk_length = in.u64("chunk_length");
  const std::uint32_t len = in.u32("message_index_offsets");
  In m = in.sub(len, "message_index_offsets");
  while (m.remaining() > 0) {
    const std::uint16_t ch = m.u16("message_index_offsets channel");
    c.message_index_offsets[ch] = m.u64("message_index_offsets offset");
  }
  c.message_index_length = in.u64("message_index_length");
  c.compression = in.str("compression");
  c.compressed_size = in.u64("compressed_size");
  c.uncompressed_size = in.u64("uncompressed_size");
  return c;
}

Statistics readStatistics(In& in) {
  Statistics s;
  s.message_count = in.u64("message_count");
  s.schema_count = in.u16("schema_count");
  s.channel_count = in.u32("channel_count");
  s.attachment_count = in.u32("attachment_count");
  s.metadata_count = in.u32("metadata_count");
  s.chunk_count = in.u32("chunk_count");
  s.message_start_time = in.u64("message_start_time");
  s.message_end_time = in.u64("message_end_time");
  const std::uint32_t len = in.u32("channel_message_counts");
  In m = in.sub(len, "channel_message_counts");
  while (m.remaining() > 0) {
    const std::uint16_t ch = m.u16("channel_message_counts channel");
    s.channel_message_counts[ch] = m.u64("channel_message_counts count");
  }
  return s;
}

}  // namespace wire
}  // namespace mannequin::recording
