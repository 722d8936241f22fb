#pragma once
// Little-endian encoding and bounds-checked decoding of MCAP record fields (internal).
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "mannequin/recording/mcap.hpp"

namespace mannequin::recording::wire {

/// Appends fields to a byte string.
class Out {
 public:
  explicit Out(std::string& buf) : buf_(buf) {}
  void u8(std::uint8_t v) { buf_.push_back(static_cast<char>(v)); }
  void u16(std::uint16_t v) { le(v, 2); }
  void u32(std::uint32_t v) { le(v, 4); }
  void u64(std::uint64_t v) { le(v, 8); }
  void raw(std::string_view s) { buf_.append(s); }
  void str(std::string_view s) {  // uint32 length prefix
    u32(static_cast<std::uint32_t>(s.size()));
    raw(s);
  }
  void bytes64(std::string_view s) {  // uint64 length prefix
    u64(s.size());
    raw(s);
  }

 private:
  void le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) buf_.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  }
  std::string& buf_;
};

/// Reads fields of one record's content; every read checks the bounds and throws McapError
/// naming the file offset, the record and the field.
class In {
 public:
  /// content: the record's bytes; base: file offset of content[0] (for messages);
  /// where: "FILE: " prefix; record: the record's name.
  In(const std::uint8_t* content, std::size_t size, std::uint64_t base, std::string where, std::string record)
      : p_(content), n_(size), base_(base), where_(std::move(where)), record_(std::move(record)) {}

  std::uint8_t u8(const char* field) { return static_cast<std::uint8_t>(le(1, field)); }
  std::uint16_t u16(const char* field) { return static_cast<std::uint16_t>(le(2, field)); }
  std::uint32_t u32(const char* field) { return static_cast<std::uint32_t>(le(4, field)); }
  std::uint64_t u64(const char* field) { return le(8, field); }
  std::string str(const char* field) { return take(u32(field), field); }
  std::string bytes64(const char* field) { return take(u64(field), field); }
  /// Everything left in the record.
  std::string rest() { return take(n_ - pos_, "data"); }
  /// Skips n bytes.
  void skip(std::uint64_t n, const char* field) { need(n, field); pos_ += n; }
  /// A sub-reader over the next n bytes (for maps and arrays).
  In sub(std::uint64_t n, const char* field) {
    need(n, field);
    In in(p_ + pos_, static_cast<std::size_t>(n), base_ + pos_, where_, record_);
    pos_ += n;
    return in;
  }
  std::size_t remaining() const { return n_ - pos_; }
  std::size_t position() const { return pos_; }
  std::uint64_t offset() const { return base_ + pos_; }
  const std::uint8_t* data() const { return p_ + pos_; }

  [[noreturn]] void fail(const std::string& msg) const { throw McapError(base_ + pos_, message(base_ + pos_, msg)); }
  std::string message(std::uint64_t at, const std::string& msg) const {
    return where_ + "byte " + std::to_string(at) + ": " + record_ + " record: " + msg;
  }

 private:
  void need(std::uint64_t n, const char* field) const {
    if (n > n_ - pos_) {
      fail(std::string("field '") + field + "' needs " + std::to_string(n) + " bytes but only " +
           std::to_string(n_ - pos_) + " remain in the record");
    }
  }
  std::uint64_t le(int n, const char* field) {
    need(static_cast<std::uint64_t>(n), field);
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= static_cast<std::uint64_t>(p_[pos_ + i]) << (8 * i);
    pos_ += static_cast<std::size_t>(n);
    return v;
  }
  std::string take(std::uint64_t n, const char* field) {
    need(n, field);
    std::string s(reinterpret_cast<const char*>(p_ + pos_), static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return s;
  }

  const std::uint8_t* p_;
  std::size_t n_;
  std::size_t pos_ = 0;
  std::uint64_t base_;
  std::string where_;
  std::string record_;
};

// Record contents (without opcode and length).
void writeSchema(std::string& out, const Schema& s);
void writeChannel(std::string& out, const Channel& c);
void writeMessage(std::string& out, const Message& m);
void writeChunkIndex(std::string& out, const ChunkIndex& c);
void writeStatistics(std::string& out, const Statistics& s);

Schema readSchema(In& in);
Channel readChannel(In& in);
/// Reads the fixed fields; the rest of the record is the data.
Message readMessage(In& in);
ChunkIndex readChunkIndex(In& in);
Statistics readStatistics(In& in);

/// Appends `<opcode><u64 length><content>` to out.
void appendRecord(std::string& out, Opcode op, const std::string& content);

}  // namespace mannequin::recording::wire
