// libFuzzer target for the MCAP reader: any input either throws McapError (naming a byte
// offset) or yields a reader whose messages can be iterated (again McapError at worst), in
// non-decreasing log_time order, each on a known channel.
#include <cstddef>
#include <cstdint>
#include <string>

#include "mannequin/recording/mcap_reader.hpp"

namespace rec = mannequin::recording;

namespace {

void check(bool ok) {
  if (!ok) __builtin_trap();
}

bool namesByte(const rec::McapError& e) { return std::string(e.what()).find("byte ") != std::string::npos; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  rec::McapReaderOptions options;
  options.max_chunk_bytes = std::uint64_t{1} << 22;  // keep declared sizes within the fuzzer's memory
  try {
    const rec::McapReader r =
        rec::McapReader::fromBytes(std::string(reinterpret_cast<const char*>(data), size), "fuzz.mcap", options);
    try {
      rec::MessageCursor c = r.messages();
      rec::Message m;
      rec::Timestamp last = 0;
      while (c.next(m)) {
        check(m.log_time >= last);
        last = m.log_time;
        check(r.channels().count(m.channel_id) == 1);
      }
    } catch (const rec::McapError& e) {
      check(namesByte(e));
    }
    if (!r.channels().empty()) {
      rec::ReadFilter f;
      f.topics = {r.channels().begin()->second.topic};
      f.start = r.statistics().message_start_time;
      f.end = f.start + 1000;
      try {
        (void)r.readAll(f);
      } catch (const rec::McapError& e) {
        check(namesByte(e));
      }
    }
    try {
      r.verify();
    } catch (const rec::McapError& e) {
      check(namesByte(e));
    }
  } catch (const rec::McapError& e) {
    check(namesByte(e));
  }
  return 0;
}
