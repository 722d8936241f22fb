// MCAP write and read throughput (MB/s of message payload) with and without zstd, on payloads
// shaped like sim.world: protobuf-style tagged doubles of a smooth motion (compressible as real
// data is, not as constant bytes are). Files go to $TMPDIR (default /tmp).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_main.hpp"
#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/recording/mcap_writer.hpp"

namespace rec = mannequin::recording;

namespace {

constexpr int kMessages = 20000;

// 1 233 bytes: 43 joint values and 18 segment poses (position + quaternion) as tagged doubles
std::string worldLike(int i) {
  std::string s;
  const double t = i * 0.016;
  auto put = [&s](int field, double v) {
    s.push_back(static_cast<char>((field << 3) | 1));
    char b[8];
    std::memcpy(b, &v, 8);
    s.append(b, 8);
  };
  for (int k = 0; k < 43; ++k) put(1, 0.3 * std::sin(t * (1 + 0.1 * k) + k));
  for (int k = 0; k < 18; ++k) {
    for (int c = 0; c < 7; ++c) put(2 + c % 3, 0.5 * std::cos(t * (0.5 + 0.05 * k) + c) + k * 0.1);
  }
  return s;
}

const std::vector<std::string>& payloads() {
  static const std::vector<std::string> p = [] {
    std::vector<std::string> v;
    for (int i = 0; i < kMessages; ++i) v.push_back(worldLike(i));  // all distinct: no free repeats for zstd
    return v;
  }();
  return p;
}

std::string path(const char* name) {
  const char* tmp = std::getenv("TMPDIR");
  return std::string(tmp ? tmp : "/tmp") + "/bench_recording_" + std::to_string(::getpid()) + "_" + name + ".mcap";
}

void writeFile(const std::string& file, rec::Compression c, std::uint64_t chunk, std::int64_t& bytes) {
  rec::McapWriterOptions o;
  o.compression = c;
  o.chunk_size = chunk;
  rec::McapWriter w(file, o);
  const auto s = w.addSchema("mannequin.v1.WorldState", "protobuf", std::string(200, 'x'));
  const auto ch = w.addChannel("sim.world", s, "protobuf");
  for (int i = 0; i < kMessages; ++i) {
    const std::string& p = payloads()[static_cast<std::size_t>(i) % payloads().size()];
    w.write(ch, static_cast<std::uint32_t>(i), 1'000'000'000ULL + 16'666'667ULL * i, 0, p);
    bytes += static_cast<std::int64_t>(p.size());
  }
  w.close();
}

void BM_Write(benchmark::State& state) {
  const auto c = static_cast<rec::Compression>(state.range(0));
  const std::string file = path("write");
  std::int64_t bytes = 0;
  for (auto _ : state) writeFile(file, c, static_cast<std::uint64_t>(state.range(1)), bytes);
  state.SetBytesProcessed(bytes);
  state.counters["file_MB"] = static_cast<double>(std::filesystem::file_size(file)) / 1e6;
  state.counters["payload_MB"] = static_cast<double>(bytes / state.iterations()) / 1e6;
  std::filesystem::remove(file);
}

void BM_Read(benchmark::State& state) {
  const auto c = static_cast<rec::Compression>(state.range(0));
  const std::string file = path("read");
  std::int64_t written = 0;
  writeFile(file, c, 1 << 20, written);
  std::int64_t bytes = 0;
  for (auto _ : state) {
    const rec::McapReader r = rec::McapReader::open(file);
    rec::MessageCursor cursor = r.messages();
    rec::Message m;
    while (cursor.next(m)) bytes += static_cast<std::int64_t>(m.data.size());
  }
  state.SetBytesProcessed(bytes);
  std::filesystem::remove(file);
}

void BM_SeekOneSecond(benchmark::State& state) {
  // open + read the messages of one second in the middle of a 333 s file (index seek)
  const std::string file = path("seek");
  std::int64_t written = 0;
  writeFile(file, rec::Compression::kZstd, 1 << 18, written);
  for (auto _ : state) {
    const rec::McapReader r = rec::McapReader::open(file);
    rec::ReadFilter f;
    f.start = 1'000'000'000ULL + 150'000'000'000ULL;
    f.end = f.start + 1'000'000'000ULL;
    benchmark::DoNotOptimize(r.readAll(f).size());
  }
  std::filesystem::remove(file);
}

}  // namespace

// args: compression (0 none, 1 zstd), chunk size
BENCHMARK(BM_Write)->ArgNames({"zstd", "chunk"})->Args({0, 1 << 20})->Args({1, 1 << 20})->Args({1, 1 << 16})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Read)->ArgNames({"zstd"})->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SeekOneSecond)->Unit(benchmark::kMillisecond)->UseRealTime();

MANNEQUIN_BENCHMARK_MAIN("bench-recording")
