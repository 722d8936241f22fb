#include "mannequin/recording/mcap_reader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "wire.hpp"

namespace mannequin::recording {

namespace {

constexpr std::uint64_t kRecordHead = 9;     // opcode + uint64 length
constexpr std::uint64_t kFooterRecord = 29;  // 9 + 8 + 8 + 4

class FileSource : public ByteSource {
 public:
  explicit FileSource(const std::string& path) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw McapError(0, path + ": cannot open: " + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
      ::close(fd_);
      throw McapError(0, path + ": not a regular file");
    }
    size_ = static_cast<std::uint64_t>(st.st_size);
    path_ = path;
  }
  ~FileSource() override { ::close(fd_); }
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;
  std::uint64_t size() const override { return size_; }
  void read(std::uint64_t offset, std::size_t n, std::uint8_t* out) const override {
    std::size_t done = 0;
    while (done < n) {
      const ssize_t r = ::pread(fd_, out + done, n - done, static_cast<off_t>(offset + done));
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) {
        throw McapError(offset + done, path_ + ": byte " + std::to_string(offset + done) + ": read failed" +
                                           (r < 0 ? std::string(": ") + std::strerror(errno) : " (file shrank?)"));
      }
      done += static_cast<std::size_t>(r);
    }
  }

 private:
  int fd_ = -1;
  std::uint64_t size_ = 0;
  std::string path_;
};

class MemorySource : public ByteSource {
 public:
  explicit MemorySource(std::string bytes) : bytes_(std::move(bytes)) {}
  std::uint64_t size() const override { return bytes_.size(); }
  void read(std::uint64_t offset, std::size_t n, std::uint8_t* out) const override {
    if (n > 0) std::memcpy(out, bytes_.data() + offset, n);
  }

 private:
  std::string bytes_;
};

std::uint64_t le64(const std::string& s, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(static_cast<std::uint8_t>(s[at + i])) << (8 * i);
  return v;
}

const std::uint8_t* u8p(const std::string& s) { return reinterpret_cast<const std::uint8_t*>(s.data()); }

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

}  // namespace

McapReader::McapReader(std::shared_ptr<const ByteSource> src, std::string name, McapReaderOptions options)
    : src_(std::move(src)), name_(std::move(name)), options_(options) {}

McapReader McapReader::open(const std::string& path, McapReaderOptions options) {
  McapReader r(std::make_shared<FileSource>(path), path, options);
  r.openImpl();
  return r;
}

McapReader McapReader::fromBytes(std::string bytes, const std::string& name, McapReaderOptions options) {
  McapReader r(std::make_shared<MemorySource>(std::move(bytes)), name, options);
  r.openImpl();
  return r;
}

void McapReader::fail(std::uint64_t offset, const std::string& msg) const {
  throw McapError(offset, name_ + ": byte " + std::to_string(offset) + ": " + msg);
}

std::string McapReader::bytesAt(std::uint64_t offset, std::uint64_t n) const {
  const std::uint64_t size = src_->size();
  if (offset > size || n > size - offset) {
    fail(offset, "reading " + std::to_string(n) + " bytes runs past the end of the file (size " +
                     std::to_string(size) + ")");
  }
  std::string out(static_cast<std::size_t>(n), '\0');
  src_->read(offset, static_cast<std::size_t>(n), reinterpret_cast<std::uint8_t*>(out.data()));
  return out;
}

void McapReader::openImpl() {
  const std::uint64_t size = src_->size();
  if (size < kMcapMagic.size() || bytesAt(0, kMcapMagic.size()) != std::string(kMcapMagic.begin(), kMcapMagic.end())) {
    fail(0, "not an MCAP file: it does not start with the magic 89 4D 43 41 50 30 0D 0A");
  }
  // Header
  const std::uint64_t h = kMcapMagic.size();
  if (size - h < kRecordHead) fail(h, "Header record: the file ends inside the record (size " + std::to_string(size) + ")");
  const std::string head = bytesAt(h, kRecordHead);
  if (static_cast<std::uint8_t>(head[0]) != static_cast<std::uint8_t>(Opcode::kHeader)) {
    fail(h, "expected the Header record (opcode 0x01), found " + opcodeName(static_cast<std::uint8_t>(head[0])));
  }
  const std::uint64_t hlen = le64(head, 1);
  if (hlen > size - h - kRecordHead) {
    fail(h, "Header record: length " + std::to_string(hlen) + " runs past the end of the file (size " +
                std::to_string(size) + ")");
  }
  {
    const std::string content = bytesAt(h + kRecordHead, hlen);
    wire::In in(u8p(content), content.size(), h + kRecordHead, name_ + ": ", "Header");
    profile_ = in.str("profile");
    library_ = in.str("library");
  }
  data_start_ = h + kRecordHead + hlen;

  // Footer and trailing magic
  std::string why;
  const std::uint64_t tail = kFooterRecord + kMcapMagic.size();
  if (size < data_start_ + tail) {
    why = "no footer (the file ends at byte " + std::to_string(size) + ": truncated, or the writer was killed)";
  } else {
    const std::uint64_t footer_offset = size - tail;
    const std::string t = bytesAt(footer_offset, tail);
    if (t.compare(kFooterRecord, kMcapMagic.size(), std::string(kMcapMagic.begin(), kMcapMagic.end())) != 0) {
      why = "no footer (no trailing magic at the end: the file is truncated, or the writer was killed)";
    } else if (static_cast<std::uint8_t>(t[0]) != static_cast<std::uint8_t>(Opcode::kFooter) || le64(t, 1) != 20) {
      why = "byte " + std::to_string(footer_offset) + ": expected the Footer record (opcode 0x02, length 20)";
    } else if (le64(t, kRecordHead) == 0) {
      // valid file written without a summary: index it by scanning
      const std::string stop = linearScan(footer_offset);
      if (!stop.empty()) {
        recovered_ = true;
        note_ = "file has no summary; linear scan stopped early: " + stop;
      } else {
        note_ = "file has no summary; indexed by a linear scan";
      }
      return;
    } else if (readSummary(footer_offset, why)) {
      indexed_ = true;
      return;
    } else {
      why = "summary unusable (" + why + ")";
    }
  }
  // recovery: everything complete before the damage
  schemas_.clear();
  channels_.clear();
  chunk_indexes_.clear();
  chunk_channels_.clear();
  loose_.clear();
  stats_ = Statistics{};
  recovered_ = true;
  const std::string stop = linearScan(size);
  note_ = name_ + ": " + why + "; recovered " + std::to_string(stats_.chunk_count) + " chunks (" +
          std::to_string(stats_.message_count) + " messages) by linear scan" +
          (stop.empty() ? std::string() : "; stopped at " + stop);
}

bool McapReader::readSummary(std::uint64_t footer_offset, std::string& why) {
  try {
    const std::string footer = bytesAt(footer_offset, kFooterRecord);
    wire::In f(u8p(footer) + kRecordHead, 20, footer_offset + kRecordHead, name_ + ": ", "Footer");
    const std::uint64_t summary_start = f.u64("summary_start");
    const std::uint64_t summary_offset_start = f.u64("summary_offset_start");
    const std::uint32_t summary_crc = f.u32("summary_crc");
    if (summary_start < data_start_ || summary_start > footer_offset) {
      fail(footer_offset, "Footer record: summary_start " + std::to_string(summary_start) + " outside the file's body [" +
                              std::to_string(data_start_) + ", " + std::to_string(footer_offset) + "]");
    }
    const std::string summary = bytesAt(summary_start, footer_offset - summary_start);
    if (summary_crc != 0) {
      std::uint32_t crc = crc32(summary.data(), summary.size());
      crc = crc32(footer.data(), kRecordHead + 16, crc);
      if (crc != summary_crc) {
        fail(summary_start, "summary section: CRC mismatch (footer says " + hex32(summary_crc) + ", computed " +
                                hex32(crc) + ")");
      }
    }
    (void)summary_offset_start;
    bool have_stats = false;
    std::size_t pos = 0;
    while (pos < summary.size()) {
      const std::uint64_t at = summary_start + pos;
      if (summary.size() - pos < kRecordHead) fail(at, "summary section: truncated record header");
      const std::uint8_t op = static_cast<std::uint8_t>(summary[pos]);
      const std::uint64_t len = le64(summary, pos + 1);
      if (len > summary.size() - pos - kRecordHead) {
        fail(at, opcodeName(op) + " record: length " + std::to_string(len) + " runs past the summary section");
      }
      wire::In in(u8p(summary) + pos + kRecordHead, static_cast<std::size_t>(len), at + kRecordHead, name_ + ": ",
                  opcodeName(op));
      switch (static_cast<Opcode>(op)) {
        case Opcode::kSchema: {
          Schema s = wire::readSchema(in);
          schemas_[s.id] = std::move(s);
          break;
        }
        case Opcode::kChannel: {
          Channel c = wire::readChannel(in);
          if (c.schema_id != 0 && schemas_.count(c.schema_id) == 0) {
            fail(at, "Channel record: topic '" + c.topic + "' names schema " + std::to_string(c.schema_id) +
                         " that no Schema record before it defines");
          }
          channels_[c.id] = std::move(c);
          break;
        }
        case Opcode::kChunkIndex: {
          ChunkIndex c = wire::readChunkIndex(in);
          if (c.chunk_start_offset < data_start_ || c.chunk_length < kRecordHead ||
              c.chunk_start_offset > summary_start || c.chunk_length > summary_start - c.chunk_start_offset) {
            fail(at, "ChunkIndex record: chunk [" + std::to_string(c.chunk_start_offset) + ", +" +
                         std::to_string(c.chunk_length) + ") is not inside the data section");
          }
          chunk_indexes_.push_back(std::move(c));
          break;
        }
        case Opcode::kStatistics:
          stats_ = wire::readStatistics(in);
          have_stats = true;
          break;
        default:
          break;  // SummaryOffset, indexes of attachments/metadata, extensions
      }
      pos += static_cast<std::size_t>(kRecordHead + len);
    }
    std::stable_sort(chunk_indexes_.begin(), chunk_indexes_.end(), [](const ChunkIndex& a, const ChunkIndex& b) {
      return a.message_start_time != b.message_start_time ? a.message_start_time < b.message_start_time
                                                          : a.chunk_start_offset < b.chunk_start_offset;
    });
    for (const ChunkIndex& c : chunk_indexes_) {
      if (c.message_index_offsets.empty()) {
        chunk_channels_.emplace_back(std::nullopt);
      } else {
        std::set<std::uint16_t> ids;
        for (const auto& [ch, off] : c.message_index_offsets) {
          if (channels_.count(ch) == 0) {
            fail(c.chunk_start_offset, "ChunkIndex: channel " + std::to_string(ch) + " has no Channel record in the summary");
          }
          ids.insert(ch);
        }
        chunk_channels_.emplace_back(std::move(ids));
      }
    }
    if (!have_stats) {
      stats_ = Statistics{};
      stats_.chunk_count = static_cast<std::uint32_t>(chunk_indexes_.size());
      stats_.schema_count = static_cast<std::uint16_t>(schemas_.size());
      stats_.channel_count = static_cast<std::uint32_t>(channels_.size());
      for (const ChunkIndex& c : chunk_indexes_) {
        if (stats_.message_start_time == 0 || c.message_start_time < stats_.message_start_time) {
          stats_.message_start_time = c.message_start_time;
        }
        stats_.message_end_time = std::max(stats_.message_end_time, c.message_end_time);
      }
    }
    return true;
  } catch (const McapError& e) {
    why = e.what();
    return false;
  }
}

std::string McapReader::linearScan(std::uint64_t limit) {
  std::uint64_t pos = data_start_;
  bool first_message = true;
  auto count = [&](std::uint16_t channel, Timestamp t) {
    ++stats_.message_count;
    ++stats_.channel_message_counts[channel];
    if (first_message || t < stats_.message_start_time) stats_.message_start_time = t;
    if (first_message || t > stats_.message_end_time) stats_.message_end_time = t;
    first_message = false;
  };
  std::string stop;
  while (pos < limit) {
    if (limit - pos < kRecordHead) {
      stop = "byte " + std::to_string(pos) + ": record header truncated (" + std::to_string(limit - pos) +
             " of 9 bytes present)";
      break;
    }
    const std::string head = bytesAt(pos, kRecordHead);
    const std::uint8_t op = static_cast<std::uint8_t>(head[0]);
    const std::uint64_t len = le64(head, 1);
    if (len > limit - pos - kRecordHead) {
      stop = "byte " + std::to_string(pos) + ": " + opcodeName(op) + " record: length " + std::to_string(len) +
             " runs past the end (" + std::to_string(limit - pos - kRecordHead) + " bytes left)";
      break;
    }
    try {
      if (op == static_cast<std::uint8_t>(Opcode::kDataEnd) || op == static_cast<std::uint8_t>(Opcode::kFooter)) break;
      if (op == static_cast<std::uint8_t>(Opcode::kChunk)) {
        ChunkScan scan;
        std::vector<Message> msgs = loadChunk(pos, kRecordHead + len, nullptr, &scan, nullptr);
        for (Schema& s : scan.schemas) schemas_.emplace(s.id, std::move(s));
        for (Channel& c : scan.channels) channels_.emplace(c.id, std::move(c));
        const ChunkIndex& ci = scan.header;
        std::set<std::uint16_t> ids;
        for (const Message& m : msgs) {
          ids.insert(m.channel_id);
          count(m.channel_id, m.log_time);
        }
        chunk_indexes_.push_back(ci);
        chunk_channels_.emplace_back(std::move(ids));
        ++stats_.chunk_count;
      } else if (op == static_cast<std::uint8_t>(Opcode::kSchema) || op == static_cast<std::uint8_t>(Opcode::kChannel) ||
                 op == static_cast<std::uint8_t>(Opcode::kMessage)) {
        const std::string content = bytesAt(pos + kRecordHead, len);
        wire::In in(u8p(content), content.size(), pos + kRecordHead, name_ + ": ", opcodeName(op));
        if (op == static_cast<std::uint8_t>(Opcode::kSchema)) {
          Schema s = wire::readSchema(in);
          schemas_.emplace(s.id, std::move(s));
        } else if (op == static_cast<std::uint8_t>(Opcode::kChannel)) {
          Channel c = wire::readChannel(in);
          channels_.emplace(c.id, std::move(c));
        } else {
          Message m = wire::readMessage(in);
          if (channels_.count(m.channel_id) == 0) {
            in.fail("channel " + std::to_string(m.channel_id) + " has no Channel record before it");
          }
          count(m.channel_id, m.log_time);
          loose_.push_back(std::move(m));
        }
      }
    } catch (const McapError& e) {
      stop = e.what();
      break;
    }
    pos += kRecordHead + len;
  }
  std::stable_sort(loose_.begin(), loose_.end(), [](const Message& a, const Message& b) { return a.log_time < b.log_time; });
  // chunk order by start time, keeping chunk_channels_ aligned
  std::vector<std::size_t> order(chunk_indexes_.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return chunk_indexes_[a].message_start_time < chunk_indexes_[b].message_start_time;
  });
  std::vector<ChunkIndex> ci;
  std::vector<std::optional<std::set<std::uint16_t>>> cc;
  for (std::size_t i : order) {
    ci.push_back(std::move(chunk_indexes_[i]));
    cc.push_back(std::move(chunk_channels_[i]));
  }
  chunk_indexes_ = std::move(ci);
  chunk_channels_ = std::move(cc);
  stats_.schema_count = static_cast<std::uint16_t>(schemas_.size());
  stats_.channel_count = static_cast<std::uint32_t>(channels_.size());
  return stop;
}

std::vector<Message> McapReader::loadChunk(std::uint64_t offset, std::uint64_t length,
                                           const std::function<bool(std::uint16_t, Timestamp)>* keep,
                                           ChunkScan* scan, const ChunkIndex* index) const {
  if (length < kRecordHead) fail(offset, "Chunk record: length " + std::to_string(length) + " is too short");
  const std::string rec = bytesAt(offset, length);
  if (static_cast<std::uint8_t>(rec[0]) != static_cast<std::uint8_t>(Opcode::kChunk)) {
    fail(offset, "expected a Chunk record (opcode 0x06), found " + opcodeName(static_cast<std::uint8_t>(rec[0])));
  }
  if (le64(rec, 1) != length - kRecordHead) {
    fail(offset, "Chunk record: its length " + std::to_string(le64(rec, 1)) + " disagrees with the chunk index (" +
                     std::to_string(length - kRecordHead) + ")");
  }
  wire::In in(u8p(rec) + kRecordHead, rec.size() - kRecordHead, offset + kRecordHead, name_ + ": ", "Chunk");
  ChunkIndex ci;
  ci.chunk_start_offset = offset;
  ci.chunk_length = length;
  ci.message_start_time = in.u64("message_start_time");
  ci.message_end_time = in.u64("message_end_time");
  ci.uncompressed_size = in.u64("uncompressed_size");
  const std::uint32_t crc = in.u32("uncompressed_crc");
  ci.compression = in.str("compression");
  ci.compressed_size = in.u64("records");
  if (ci.compressed_size > in.remaining()) {
    in.fail("records length " + std::to_string(ci.compressed_size) + " runs past the record (" +
            std::to_string(in.remaining()) + " bytes left)");
  }
  if (ci.uncompressed_size > options_.max_chunk_bytes) {
    in.fail("uncompressed_size " + std::to_string(ci.uncompressed_size) + " exceeds the reader's limit of " +
            std::to_string(options_.max_chunk_bytes) + " bytes");
  }
  if (!ci.compression.empty() && ci.compression != "zstd") {
    fail(offset, "Chunk record: unsupported compression '" + ci.compression + "' (this reader handles \"\" and \"zstd\")");
  }
  if (index != nullptr &&
      (index->message_start_time != ci.message_start_time || index->message_end_time != ci.message_end_time ||
       index->compression != ci.compression || index->uncompressed_size != ci.uncompressed_size ||
       index->compressed_size != ci.compressed_size)) {
    fail(offset, "Chunk record: its times, sizes or compression disagree with its ChunkIndex in the summary");
  }
  const std::uint64_t records_at = offset + kRecordHead + in.position();
  std::string plain;
  if (ci.compression.empty()) {
    if (ci.compressed_size != ci.uncompressed_size) {
      in.fail("uncompressed chunk: records length " + std::to_string(ci.compressed_size) +
              " differs from uncompressed_size " + std::to_string(ci.uncompressed_size));
    }
    plain.assign(reinterpret_cast<const char*>(in.data()), static_cast<std::size_t>(ci.compressed_size));
  } else if (ci.compression == "zstd") {
    plain.resize(static_cast<std::size_t>(ci.uncompressed_size));
    const std::size_t n =
        ZSTD_decompress(plain.data(), plain.size(), in.data(), static_cast<std::size_t>(ci.compressed_size));
    if (ZSTD_isError(n)) {
      fail(records_at, "Chunk record: zstd decompression failed: " + std::string(ZSTD_getErrorName(n)));
    }
    if (n != plain.size()) {
      fail(records_at, "Chunk record: zstd records decompress to " + std::to_string(n) + " bytes, uncompressed_size says " +
                           std::to_string(plain.size()));
    }
  } else {
    fail(offset, "Chunk record: unsupported compression '" + ci.compression + "' (this reader handles \"\" and \"zstd\")");
  }
  if (crc != 0) {
    const std::uint32_t got = crc32(plain.data(), plain.size());
    if (got != crc) {
      fail(offset, "Chunk record: CRC mismatch (stored " + hex32(crc) + ", computed " + hex32(got) +
                       " over the uncompressed records)");
    }
  }
  // inner records
  const std::string where = name_ + ": chunk at byte " + std::to_string(offset) + ", uncompressed ";
  std::vector<Message> out;
  std::size_t pos = 0;
  while (pos < plain.size()) {
    if (plain.size() - pos < kRecordHead) {
      fail(offset, "Chunk record: uncompressed byte " + std::to_string(pos) + ": record header truncated");
    }
    const std::uint8_t op = static_cast<std::uint8_t>(plain[pos]);
    const std::uint64_t len = le64(plain, pos + 1);
    if (len > plain.size() - pos - kRecordHead) {
      fail(offset, "Chunk record: uncompressed byte " + std::to_string(pos) + ": " + opcodeName(op) + " record length " +
                       std::to_string(len) + " runs past the chunk");
    }
    wire::In r(u8p(plain) + pos + kRecordHead, static_cast<std::size_t>(len), pos + kRecordHead, where, opcodeName(op));
    switch (static_cast<Opcode>(op)) {
      case Opcode::kSchema:
        if (scan != nullptr) scan->schemas.push_back(wire::readSchema(r));
        break;
      case Opcode::kChannel:
        if (scan != nullptr) scan->channels.push_back(wire::readChannel(r));
        break;
      case Opcode::kMessage: {
        const std::uint16_t ch = r.u16("channel_id");
        const std::uint32_t seq = r.u32("sequence");
        const Timestamp t = r.u64("log_time");
        const Timestamp pt = r.u64("publish_time");
        const bool known = channels_.count(ch) > 0 ||
                           (scan != nullptr && std::any_of(scan->channels.begin(), scan->channels.end(),
                                                           [ch](const Channel& c) { return c.id == ch; }));
        if (!known) r.fail("channel " + std::to_string(ch) + " has no Channel record before it");
        if (t < ci.message_start_time || t > ci.message_end_time) {
          r.fail("log_time " + std::to_string(t) + " outside the chunk's [message_start_time, message_end_time] = [" +
                 std::to_string(ci.message_start_time) + ", " + std::to_string(ci.message_end_time) + "]");
        }
        if (keep == nullptr || (*keep)(ch, t)) out.push_back(Message{ch, seq, t, pt, r.rest()});
        break;
      }
      default:
        break;
    }
    pos += static_cast<std::size_t>(kRecordHead + len);
  }
  if (scan != nullptr) scan->header = ci;
  return out;
}

std::set<std::uint16_t> McapReader::channelsOf(const std::vector<std::string>& topics) const {
  std::set<std::uint16_t> ids;
  for (const std::string& t : topics) {
    bool found = false;
    for (const auto& [id, c] : channels_) {
      if (c.topic == t) {
        ids.insert(id);
        found = true;
      }
    }
    if (!found) {
      std::string all;
      for (const auto& [id, c] : channels_) all += (all.empty() ? "" : ", ") + c.topic;
      throw McapError(0, name_ + ": topic '" + t + "' is not in the file (topics: " + (all.empty() ? "none" : all) + ")");
    }
  }
  return ids;
}

const Channel& McapReader::channel(std::uint16_t id) const {
  auto it = channels_.find(id);
  if (it == channels_.end()) throw McapError(0, name_ + ": no channel with id " + std::to_string(id));
  return it->second;
}

MessageCursor McapReader::messages(const ReadFilter& filter) const { return MessageCursor(*this, filter); }

std::vector<Message> McapReader::readAll(const ReadFilter& filter) const {
  std::vector<Message> out;
  MessageCursor c = messages(filter);
  Message m;
  while (c.next(m)) out.push_back(std::move(m));
  return out;
}

void McapReader::verify() const {
  static const std::function<bool(std::uint16_t, Timestamp)> none = [](std::uint16_t, Timestamp) { return false; };
  for (const ChunkIndex& c : chunk_indexes_) {
    loadChunk(c.chunk_start_offset, c.chunk_length, &none, nullptr, &c);
  }
}

// ---- cursor ----------------------------------------------------------------------------

MessageCursor::MessageCursor(const McapReader& reader, const ReadFilter& filter)
    : reader_(&reader), start_(filter.start), end_(filter.end) {
  if (!filter.topics.empty()) channels_ = reader.channelsOf(filter.topics);
  for (std::size_t i = 0; i < reader.chunk_indexes_.size(); ++i) {
    const ChunkIndex& c = reader.chunk_indexes_[i];
    const auto& ids = reader.chunk_channels_[i];
    if (ids && ids->empty()) continue;  // no messages
    if (c.message_end_time < start_ || c.message_start_time > end_) continue;
    if (channels_ && ids &&
        std::none_of(ids->begin(), ids->end(), [&](std::uint16_t id) { return channels_->count(id) > 0; })) {
      continue;
    }
    chunks_.push_back(i);
  }
  std::vector<Message> loose;
  for (const Message& m : reader.loose_) {
    if (m.log_time >= start_ && m.log_time <= end_ && (!channels_ || channels_->count(m.channel_id) > 0)) {
      loose.push_back(m);
    }
  }
  if (!loose.empty()) {
    heap_.push(Head{loose.front().log_time, loaded_.size(), 0});
    loaded_.push_back(std::move(loose));
  }
}

void MessageCursor::refill() {
  const std::function<bool(std::uint16_t, Timestamp)> keep = [this](std::uint16_t ch, Timestamp time) {
    return time >= start_ && time <= end_ && (!channels_ || channels_->count(ch) > 0);
  };
  // a chunk that starts no later than the earliest pending message may hold earlier ones
  while (next_chunk_ < chunks_.size()) {
    const ChunkIndex& c = reader_->chunk_indexes_[chunks_[next_chunk_]];
    if (!heap_.empty() && c.message_start_time > heap_.top().time) break;
    ++next_chunk_;
    std::vector<Message> msgs = reader_->loadChunk(c.chunk_start_offset, c.chunk_length, &keep, nullptr, &c);
    if (msgs.empty()) continue;
    std::stable_sort(msgs.begin(), msgs.end(), [](const Message& a, const Message& b) { return a.log_time < b.log_time; });
    heap_.push(Head{msgs.front().log_time, loaded_.size(), 0});
    loaded_.push_back(std::move(msgs));
  }
}

bool MessageCursor::next(Message& out) {
  refill();
  if (heap_.empty()) return false;
  const Head h = heap_.top();
  heap_.pop();
  std::vector<Message>& v = loaded_[h.load];
  out = std::move(v[h.pos]);
  if (h.pos + 1 < v.size()) {
    heap_.push(Head{v[h.pos + 1].log_time, h.load, h.pos + 1});
  } else {
    std::vector<Message>().swap(v);
  }
  return true;
}

}  // namespace mannequin::recording
