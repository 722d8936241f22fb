#pragma once
/// \file mcap_reader.hpp
/// \brief Reads MCAP files: from the summary (Footer -> Schemas, Channels, Statistics, Chunk
/// Indexes) when the file has one, otherwise by a linear scan of the data section, which is
/// also how a file whose writer was killed (no summary, no footer, maybe a torn last record)
/// is recovered: every complete, CRC-valid chunk before the damage is kept and recovered()
/// says so. Messages come out in log_time order, filtered by time range and topic; chunks
/// outside the range or without the wanted channels are never read (seek by index).
///
/// Errors (McapError) name the file, the byte offset and the record, e.g.
/// "run.mcap: byte 4711: Chunk record: CRC mismatch (stored 0x1a2b3c4d, computed 0x...)".
/// Reads chunks "" (uncompressed) and "zstd"; other compressions are reported as errors.
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <queue>
#include <set>
#include <string>
#include <vector>

#include "mannequin/recording/mcap.hpp"

namespace mannequin::recording {

/// Limits that protect the reader from absurd sizes in a corrupt or hostile file.
struct McapReaderOptions {
  std::uint64_t max_chunk_bytes = std::uint64_t{1} << 30;  ///< largest uncompressed chunk accepted
};

/// Which messages a cursor yields.
struct ReadFilter {
  Timestamp start = 0;                                    ///< first log_time, inclusive
  Timestamp end = std::numeric_limits<Timestamp>::max();  ///< last log_time, inclusive
  std::vector<std::string> topics;                        ///< empty = every topic
};

class McapReader;

/// Messages of one McapReader in log_time order (ties: file order). The reader must outlive
/// the cursor. Holds in memory only the chunks overlapping the current time.
class MessageCursor {
 public:
  /// Next message into out; false at the end. Throws McapError on a corrupt chunk.
  bool next(Message& out);

 private:
  friend class McapReader;
  MessageCursor(const McapReader& reader, const ReadFilter& filter);
  void refill();

  struct Head {
    Timestamp time;
    std::size_t load;
    std::size_t pos;
    bool operator>(const Head& o) const {
      return time != o.time ? time > o.time : load != o.load ? load > o.load : pos > o.pos;
    }
  };
  const McapReader* reader_;
  Timestamp start_;
  Timestamp end_;
  std::optional<std::set<std::uint16_t>> channels_;  // nullopt = all channels
  std::vector<std::size_t> chunks_;                  // chunks to visit, by start time
  std::size_t next_chunk_ = 0;
  std::vector<std::vector<Message>> loaded_;
  std::priority_queue<Head, std::vector<Head>, std::greater<>> heap_;
};

/// Random-access bytes (a file, or memory for tests and fuzzing).
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  virtual std::uint64_t size() const = 0;
  /// Reads n bytes at offset into out; offset + n <= size() is checked by the caller.
  virtual void read(std::uint64_t offset, std::size_t n, std::uint8_t* out) const = 0;
};

/// Read-only view of an MCAP file. Opening reads the footer and summary (or scans the data
/// section); message data is read on demand by cursors.
class McapReader {
 public:
  /// Opens path. Throws McapError when it is not an MCAP file (bad magic, no Header) or
  /// cannot be read; a file with a damaged end is recovered (see recovered()).
  static McapReader open(const std::string& path, McapReaderOptions options = {});
  /// Same, over bytes in memory; name is used in messages.
  static McapReader fromBytes(std::string bytes, const std::string& name = "<memory>",
                              McapReaderOptions options = {});

  const std::string& profile() const { return profile_; }
  const std::string& library() const { return library_; }
  const std::map<std::uint16_t, Schema>& schemas() const { return schemas_; }
  const std::map<std::uint16_t, Channel>& channels() const { return channels_; }
  /// One per chunk, sorted by message_start_time (then offset).
  const std::vector<ChunkIndex>& chunkIndexes() const { return chunk_indexes_; }
  /// From the summary, or counted during the linear scan.
  const Statistics& statistics() const { return stats_; }
  /// True when the file had a usable summary (indexed access).
  bool indexed() const { return indexed_; }
  /// True when the file's end was missing or damaged and its readable prefix was recovered
  /// by a linear scan.
  bool recovered() const { return recovered_; }
  /// How the file was read when not from its summary: "no footer: ... recovered 12 chunks by
  /// linear scan, stopped at byte 4711: Chunk record: ...". Empty for a clean indexed file.
  const std::string& note() const { return note_; }

  /// Channel ids of the given topics; throws McapError listing the file's topics when one is
  /// not in the file.
  std::set<std::uint16_t> channelsOf(const std::vector<std::string>& topics) const;
  /// Channel by id; throws McapError when unknown.
  const Channel& channel(std::uint16_t id) const;

  /// Cursor over the messages matching filter.
  MessageCursor messages(const ReadFilter& filter = {}) const;
  /// Every message matching filter (convenience for small files and tests).
  std::vector<Message> readAll(const ReadFilter& filter = {}) const;
  /// Decodes every chunk and checks its CRC; throws McapError on the first bad one.
  void verify() const;

 private:
  friend class MessageCursor;
  McapReader(std::shared_ptr<const ByteSource> src, std::string name, McapReaderOptions options);
  void openImpl();
  bool readSummary(std::uint64_t footer_offset, std::string& why);
  /// Scans records from data_start_ to limit; returns why it stopped early ("" when it reached
  /// DataEnd or limit cleanly).
  std::string linearScan(std::uint64_t limit);
  std::string bytesAt(std::uint64_t offset, std::uint64_t n) const;
  /// What a linear scan learns from a chunk besides its messages.
  struct ChunkScan {
    ChunkIndex header;  // without message index offsets
    std::vector<Schema> schemas;
    std::vector<Channel> channels;
  };
  /// Messages of the chunk record at offset (length bytes) that pass keep (all when null);
  /// with scan set, also the chunk's header fields and the Schema/Channel records inside;
  /// with index set, the chunk's header must agree with it. Every message must lie in the
  /// chunk's time range (so that the cursor's merge by chunk start time is sound).
  std::vector<Message> loadChunk(std::uint64_t offset, std::uint64_t length,
                                 const std::function<bool(std::uint16_t, Timestamp)>* keep, ChunkScan* scan,
                                 const ChunkIndex* index) const;
  [[noreturn]] void fail(std::uint64_t offset, const std::string& msg) const;

  std::shared_ptr<const ByteSource> src_;
  std::string name_;
  McapReaderOptions options_;
  std::string profile_;
  std::string library_;
  std::uint64_t data_start_ = 0;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
  std::vector<ChunkIndex> chunk_indexes_;
  std::vector<std::optional<std::set<std::uint16_t>>> chunk_channels_;  // per chunk; nullopt = unknown
  std::vector<Message> loose_;                           // messages outside chunks
  Statistics stats_;
  bool indexed_ = false;
  bool recovered_ = false;
  std::string note_;
};

}  // namespace mannequin::recording
