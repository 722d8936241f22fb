#pragma once
/// \file mcap_writer.hpp
/// \brief Writes an MCAP file: Schema and Channel records straight into the data section as
/// they are added, Messages batched into Chunks (optionally zstd-compressed) each followed by
/// its Message Index records, then on close() DataEnd, the summary (Schemas, Channels,
/// Statistics, Chunk Indexes), Summary Offsets and the Footer.
///
/// Crash safety: every finished chunk and every Schema/Channel record is handed to the
/// operating system (fflush; fsync too with sync_each_chunk) before write() returns, so a
/// killed writer loses at most the messages of the open chunk, and McapReader recovers the
/// rest of the file by a linear scan.
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "mannequin/recording/mcap.hpp"

namespace mannequin::recording {

/// Options of McapWriter.
struct McapWriterOptions {
  std::string profile;                       ///< Header profile ("" = none; ROS 2 uses "ros2")
  std::string library = "mannequin-recording";  ///< Header library
  Compression compression = Compression::kZstd;
  int zstd_level = 3;                        ///< 1 (fast) .. 19 (small)
  std::uint64_t chunk_size = 1 << 20;        ///< a chunk closes once its records reach this many bytes
  bool sync_each_chunk = false;              ///< fsync after each chunk (survives power loss, slower)
};

/// Sequential MCAP writer. Not thread-safe. Every method throws McapError (naming the file
/// and byte offset) when the file cannot be written or arguments are invalid.
class McapWriter {
 public:
  /// Creates (truncates) path and writes the magic and the Header record.
  explicit McapWriter(const std::string& path, McapWriterOptions options = {});
  /// Calls close(); errors are swallowed here, call close() yourself to see them.
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Adds a schema and returns its id (1, 2, ...). For protobuf: name = full message name
  /// ("mannequin.v1.WorldState"), encoding = "protobuf", data = serialized FileDescriptorSet.
  std::uint16_t addSchema(const std::string& name, const std::string& encoding, const std::string& data);
  /// Adds a channel on a topic and returns its id (0, 1, ...). schema_id 0 = no schema,
  /// otherwise an id returned by addSchema.
  std::uint16_t addChannel(const std::string& topic, std::uint16_t schema_id, const std::string& message_encoding,
                           const std::map<std::string, std::string>& metadata = {});
  /// Appends a message to the open chunk; closes the chunk when it reaches chunk_size.
  void write(std::uint16_t channel_id, std::uint32_t sequence, Timestamp log_time, Timestamp publish_time,
             std::string_view data);
  /// Writes the open chunk (if any) and its message indexes now, and flushes.
  void flushChunk();
  /// Flushes the open chunk and writes DataEnd, summary, summary offsets, footer and magic.
  /// Idempotent.
  void close();

  /// Bytes written to the file so far.
  std::uint64_t bytesWritten() const { return offset_; }
  /// Messages written (including the open chunk).
  std::uint64_t messageCount() const { return stats_.message_count; }
  /// Chunks written.
  std::uint32_t chunkCount() const { return stats_.chunk_count; }

 private:
  void put(const std::string& bytes);
  void flushFile();
  [[noreturn]] void fail(const std::string& msg) const;

  std::string path_;
  McapWriterOptions options_;
  std::FILE* file_ = nullptr;
  void* zstd_ctx_ = nullptr;  // ZSTD_CCtx*
  std::uint64_t offset_ = 0;
  std::uint32_t data_crc_ = 0;
  bool in_data_section_ = true;

  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::vector<ChunkIndex> chunk_indexes_;
  Statistics stats_;

  // open chunk
  std::string chunk_records_;
  std::map<std::uint16_t, std::vector<std::pair<Timestamp, std::uint64_t>>> chunk_message_index_;
  Timestamp chunk_start_ = 0;
  Timestamp chunk_end_ = 0;
  bool chunk_has_messages_ = false;
  std::string scratch_;
};

}  // namespace mannequin::recording
