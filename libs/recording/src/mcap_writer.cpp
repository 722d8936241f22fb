#include "mannequin/recording/mcap_writer.hpp"

#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <tuple>
#include <cerrno>
#include <cstring>

#include "wire.hpp"

namespace mannequin::recording {

McapWriter::McapWriter(const std::string& path, McapWriterOptions options) : path_(path), options_(std::move(options)) {
  if (options_.chunk_size == 0) fail("chunk_size must be positive");
  if (options_.compression == Compression::kZstd &&
      (options_.zstd_level < 1 || options_.zstd_level > ZSTD_maxCLevel())) {
    fail("zstd_level " + std::to_string(options_.zstd_level) + " outside 1.." + std::to_string(ZSTD_maxCLevel()));
  }
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) fail(std::string("cannot create file: ") + std::strerror(errno));
  if (options_.compression == Compression::kZstd) zstd_ctx_ = ZSTD_createCCtx();
  std::string head(reinterpret_cast<const char*>(kMcapMagic.data()), kMcapMagic.size());
  std::string content;
  wire::Out o(content);
  o.str(options_.profile);
  o.str(options_.library);
  wire::appendRecord(head, Opcode::kHeader, content);
  put(head);
  flushFile();
}

McapWriter::~McapWriter() {
  try {
    close();
  } catch (const McapError&) {
  }
  if (file_ != nullptr) std::fclose(file_);
  if (zstd_ctx_ != nullptr) ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_ctx_));
}

void McapWriter::fail(const std::string& msg) const {
  throw McapError(offset_, path_ + ": byte " + std::to_string(offset_) + ": " + msg);
}

void McapWriter::put(const std::string& bytes) {
  if (file_ == nullptr) fail("writer is closed");
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    fail(std::string("write failed: ") + std::strerror(errno));
  }
  if (in_data_section_) data_crc_ = crc32(bytes.data(), bytes.size(), data_crc_);
  offset_ += bytes.size();
}

void McapWriter::flushFile() {
  if (std::fflush(file_) != 0) fail(std::string("flush failed: ") + std::strerror(errno));
  if (options_.sync_each_chunk && ::fsync(::fileno(file_)) != 0) {
    fail(std::string("fsync failed: ") + std::strerror(errno));
  }
}

std::uint16_t McapWriter::addSchema(const std::string& name, const std::string& encoding, const std::string& data) {
  if (schemas_.size() >= 0xFFFE) fail("too many schemas (the format allows 65535)");
  Schema s{static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, data};
  std::string content;
  wire::writeSchema(content, s);
  std::string rec;
  wire::appendRecord(rec, Opcode::kSchema, content);
  put(rec);
  flushFile();
  schemas_.push_back(std::move(s));
  return schemas_.back().id;
}

std::uint16_t McapWriter::addChannel(const std::string& topic, std::uint16_t schema_id,
                                     const std::string& message_encoding,
                                     const std::map<std::string, std::string>& metadata) {
  if (schema_id > schemas_.size()) fail("addChannel(" + topic + "): unknown schema id " + std::to_string(schema_id));
  if (channels_.size() >= 0xFFFF) fail("too many channels (the format allows 65536)");
  Channel c{static_cast<std::uint16_t>(channels_.size()), schema_id, topic, message_encoding, metadata};
  std::string content;
  wire::writeChannel(content, c);
  std::string rec;
  wire::appendRecord(rec, Opcode::kChannel, content);
  put(rec);
  flushFile();
  channels_.push_back(std::move(c));
  return channels_.back().id;
}

void McapWriter::write(std::uint16_t channel_id, std::uint32_t sequence, Timestamp log_time, Timestamp publish_time,
                       std::string_view data) {
  if (file_ == nullptr) fail("writer is closed");
  if (channel_id >= channels_.size()) fail("write(): unknown channel id " + std::to_string(channel_id));
  const std::uint64_t offset_in_chunk = chunk_records_.size();
  wire::Out o(chunk_records_);
  o.u8(static_cast<std::uint8_t>(Opcode::kMessage));
  o.u64(2 + 4 + 8 + 8 + data.size());
  o.u16(channel_id);
  o.u32(sequence);
  o.u64(log_time);
  o.u64(publish_time);
  o.raw(data);
  chunk_message_index_[channel_id].emplace_back(log_time, offset_in_chunk);
  if (!chunk_has_messages_) {
    chunk_start_ = chunk_end_ = log_time;
    chunk_has_messages_ = true;
  } else {
    chunk_start_ = std::min(chunk_start_, log_time);
    chunk_end_ = std::max(chunk_end_, log_time);
  }
  if (stats_.message_count == 0) {
    stats_.message_start_time = stats_.message_end_time = log_time;
  } else {
    stats_.message_start_time = std::min(stats_.message_start_time, log_time);
    stats_.message_end_time = std::max(stats_.message_end_time, log_time);
  }
  ++stats_.message_count;
  ++stats_.channel_message_counts[channel_id];
  if (chunk_records_.size() >= options_.chunk_size) flushChunk();
}

void McapWriter::flushChunk() {
  if (file_ == nullptr || chunk_records_.empty()) return;
  ChunkIndex index;
  index.message_start_time = chunk_has_messages_ ? chunk_start_ : 0;
  index.message_end_time = chunk_has_messages_ ? chunk_end_ : 0;
  index.chunk_start_offset = offset_;
  index.compression = compressionName(options_.compression);
  index.uncompressed_size = chunk_records_.size();
  const std::uint32_t crc = crc32(chunk_records_.data(), chunk_records_.size());

  const std::string* payload = &chunk_records_;
  if (options_.compression == Compression::kZstd) {
    scratch_.resize(ZSTD_compressBound(chunk_records_.size()));
    const std::size_t n = ZSTD_compressCCtx(static_cast<ZSTD_CCtx*>(zstd_ctx_), scratch_.data(), scratch_.size(),
                                            chunk_records_.data(), chunk_records_.size(), options_.zstd_level);
    if (ZSTD_isError(n)) fail(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
    scratch_.resize(n);
    payload = &scratch_;
  }
  index.compressed_size = payload->size();

  std::string content;
  wire::Out o(content);
  o.u64(index.message_start_time);
  o.u64(index.message_end_time);
  o.u64(index.uncompressed_size);
  o.u32(crc);
  o.str(index.compression);
  o.u64(payload->size());
  // the record is assembled without copying the payload twice
  std::string rec;
  rec.reserve(9 + content.size() + payload->size());
  wire::Out r(rec);
  r.u8(static_cast<std::uint8_t>(Opcode::kChunk));
  r.u64(content.size() + payload->size());
  r.raw(content);
  r.raw(*payload);
  index.chunk_length = rec.size();

  // message indexes, one per channel, in channel order
  std::string indexes;
  std::uint64_t at = offset_ + rec.size();
  for (const auto& [channel, entries] : chunk_message_index_) {
    std::string mi;
    wire::Out m(mi);
    m.u16(channel);
    m.u32(static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [t, off] : entries) {
      m.u64(t);
      m.u64(off);
    }
    index.message_index_offsets[channel] = at + indexes.size();
    wire::appendRecord(indexes, Opcode::kMessageIndex, mi);
  }
  index.message_index_length = indexes.size();

  put(rec);
  put(indexes);
  flushFile();

  chunk_indexes_.push_back(std::move(index));
  ++stats_.chunk_count;
  chunk_records_.clear();
  chunk_message_index_.clear();
  chunk_has_messages_ = false;
}

void McapWriter::close() {
  if (file_ == nullptr) return;
  flushChunk();
  // the data section CRC covers every byte from the start of the file (magic included) up to
  // the DataEnd record, as the reference implementations compute it
  std::string tail;
  {
    std::string content;
    wire::Out o(content);
    o.u32(data_crc_);
    wire::appendRecord(tail, Opcode::kDataEnd, content);
  }
  const std::uint64_t summary_start = offset_ + tail.size();
  std::string summary;
  std::vector<std::tuple<Opcode, std::uint64_t, std::uint64_t>> groups;
  auto group = [&](Opcode op, auto&& emit) {
    const std::uint64_t begin = summary.size();
    emit();
    if (summary.size() > begin) groups.emplace_back(op, summary_start + begin, summary.size() - begin);
  };
  group(Opcode::kSchema, [&] {
    for (const Schema& s : schemas_) {
      std::string c;
      wire::writeSchema(c, s);
      wire::appendRecord(summary, Opcode::kSchema, c);
    }
  });
  group(Opcode::kChannel, [&] {
    for (const Channel& ch : channels_) {
      std::string c;
      wire::writeChannel(c, ch);
      wire::appendRecord(summary, Opcode::kChannel, c);
    }
  });
  group(Opcode::kStatistics, [&] {
    Statistics s = stats_;
    s.schema_count = static_cast<std::uint16_t>(schemas_.size());
    s.channel_count = static_cast<std::uint32_t>(channels_.size());
    std::string c;
    wire::writeStatistics(c, s);
    wire::appendRecord(summary, Opcode::kStatistics, c);
  });
  group(Opcode::kChunkIndex, [&] {
    for (const ChunkIndex& ci : chunk_indexes_) {
      std::string c;
      wire::writeChunkIndex(c, ci);
      wire::appendRecord(summary, Opcode::kChunkIndex, c);
    }
  });
  const std::uint64_t summary_offset_start = summary_start + summary.size();
  for (const auto& [op, start, length] : groups) {
    std::string c;
    wire::Out o(c);
    o.u8(static_cast<std::uint8_t>(op));
    o.u64(start);
    o.u64(length);
    wire::appendRecord(summary, Opcode::kSummaryOffset, c);
  }
  std::string footer;
  wire::Out f(footer);
  f.u8(static_cast<std::uint8_t>(Opcode::kFooter));
  f.u64(20);
  f.u64(summary_start);
  f.u64(summary_offset_start);
  std::uint32_t summary_crc = crc32(summary.data(), summary.size());
  summary_crc = crc32(footer.data(), footer.size(), summary_crc);
  f.u32(summary_crc);
  footer.append(reinterpret_cast<const char*>(kMcapMagic.data()), kMcapMagic.size());

  in_data_section_ = false;
  put(tail);
  put(summary);
  put(footer);
  flushFile();
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) fail(std::string("close failed: ") + std::strerror(errno));
}

}  // namespace mannequin::recording
