#pragma once
// Shared helpers of the recording tests: temporary files and a deterministic message stream.
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "mannequin/recording/mcap_writer.hpp"

namespace mannequin::recording::testing {

inline std::filesystem::path tempPath(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("mannequin_recording_" + std::to_string(::getpid()) + "_" + name);
}

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void spit(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out << bytes;
}

/// Payload of message i on channel c: recognisable, varying length, not very compressible.
inline std::string payload(int c, int i) {
  std::string s = "ch" + std::to_string(c) + "#" + std::to_string(i) + ":";
  std::uint32_t x = static_cast<std::uint32_t>(i * 2654435761U + c * 40503U);
  const int n = 20 + (i * 7 + c * 3) % 90;
  for (int k = 0; k < n; ++k) {
    x = x * 1664525U + 1013904223U;
    s.push_back(static_cast<char>('a' + (x >> 27)));
  }
  return s;
}

/// Expected message of the stream below.
struct Sent {
  std::uint16_t channel;
  std::uint32_t sequence;
  Timestamp log_time;
  std::string data;
};

/// Writes n messages alternating over 3 topics "/a", "/b", "/c" (a gets 2 of every 4),
/// log_time = 1e9 + 1e6 * i ns, into w; returns what was written.
inline std::vector<Sent> writeStream(McapWriter& w, int n) {
  const std::uint16_t s = w.addSchema("test.Blob", "protobuf", std::string("\x0a\x03\x62\x2e\x70", 5));
  const std::uint16_t a = w.addChannel("/a", s, "protobuf", {{"k", "v"}});
  const std::uint16_t b = w.addChannel("/b", s, "protobuf");
  const std::uint16_t c = w.addChannel("/c", s, "protobuf");
  const std::uint16_t pick[4] = {a, b, a, c};
  std::vector<Sent> sent;
  for (int i = 0; i < n; ++i) {
    const std::uint16_t ch = pick[i % 4];
    const Timestamp t = 1'000'000'000ULL + 1'000'000ULL * static_cast<Timestamp>(i);
    sent.push_back({ch, static_cast<std::uint32_t>(i), t, payload(ch, i)});
    w.write(ch, static_cast<std::uint32_t>(i), t, t - 5, sent.back().data);
  }
  return sent;
}

}  // namespace mannequin::recording::testing
