#pragma once
/// \file mcap.hpp
/// \brief MCAP records (format version 0, https://mcap.dev/spec) as plain structs, the
/// error type of the reader and writer, and the CRC-32 they use.
///
/// An MCAP file is `<magic><Header><data section>[<summary>][<summary offsets>]<Footer><magic>`;
/// every record is `<opcode u8><content length u64><content>`, integers little-endian,
/// strings and maps prefixed by their uint32 byte length. Timestamps are uint64 nanoseconds
/// (this project: since the Unix epoch, from the recording host's system clock).
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>

namespace mannequin::recording {

/// Nanoseconds since the Unix epoch.
using Timestamp = std::uint64_t;

/// The 8 bytes that start and end every MCAP file: 0x89 'M' 'C' 'A' 'P' '0' '\r' '\n'.
inline constexpr std::array<std::uint8_t, 8> kMcapMagic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

/// Record opcodes of the spec.
enum class Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// "Header", "Chunk", ... for opcodes of the spec, "opcode 0xNN" otherwise.
std::string opcodeName(std::uint8_t opcode);

/// Chunk compression this library reads and writes.
enum class Compression { kNone, kZstd };

/// The spec's name of a compression: "" or "zstd".
const char* compressionName(Compression compression);

/// Schema (op 0x03): how to decode the messages of the channels that use it. For protobuf,
/// encoding = "protobuf", name = full message name, data = serialized FileDescriptorSet.
struct Schema {
  std::uint16_t id = 0;  ///< never 0
  std::string name;
  std::string encoding;
  std::string data;
};

/// Channel (op 0x04): a topic and how its messages are encoded.
struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  ///< 0 = no schema
  std::string topic;
  std::string message_encoding;  ///< "protobuf" here
  std::map<std::string, std::string> metadata;
};

/// Message (op 0x05).
struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  Timestamp log_time = 0;      ///< when the recorder received it
  Timestamp publish_time = 0;  ///< when the publisher sent it (= log_time if unknown)
  std::string data;            ///< the serialized message, bytes
};

/// Chunk Index (op 0x08): where a chunk and its message indexes are in the file.
struct ChunkIndex {
  Timestamp message_start_time = 0;
  Timestamp message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;  ///< file offset of the Chunk record's opcode
  std::uint64_t chunk_length = 0;        ///< whole record, opcode and length included
  std::map<std::uint16_t, std::uint64_t> message_index_offsets;  ///< channel -> file offset
  std::uint64_t message_index_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

/// Statistics (op 0x0B).
struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  Timestamp message_start_time = 0;
  Timestamp message_end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
};

/// Footer (op 0x02).
struct Footer {
  std::uint64_t summary_start = 0;
  std::uint64_t summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
};

/// Any failure to read or write an MCAP file. what() names the file, the byte offset and the
/// record, e.g. "run.mcap: byte 1234: Chunk record: CRC mismatch (stored 0x..., computed 0x...)".
class McapError : public std::runtime_error {
 public:
  McapError(std::uint64_t offset, const std::string& what) : std::runtime_error(what), offset_(offset) {}
  /// File offset the error is about.
  std::uint64_t offset() const { return offset_; }

 private:
  std::uint64_t offset_;
};

/// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, as zlib's crc32) of n bytes,
/// continuing from crc (0 to start).
std::uint32_t crc32(const void* data, std::size_t n, std::uint32_t crc = 0);

}  // namespace mannequin::recording
