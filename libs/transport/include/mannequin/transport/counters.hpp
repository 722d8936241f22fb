#pragma once
/// \file counters.hpp
/// \brief Per-topic message counters of a publisher or a subscriber (reported in heartbeats).
#include <cstdint>
#include <string>

namespace mannequin::transport {

struct TopicCounters {
  std::string topic;
  std::uint64_t received = 0;    ///< subscriber: frames that arrived with this topic (valid or not)
  std::uint64_t delivered = 0;   ///< subscriber: messages handed to the handler; publisher: messages sent
  std::uint64_t dropped = 0;     ///< subscriber: messages lost upstream, from gaps in Header.sequence
  std::uint64_t superseded = 0;  ///< subscriber (kLatest): older values replaced by a newer one before delivery
  std::uint64_t duplicates = 0;  ///< subscriber: re-sent last values already delivered (late-joiner resends)
  std::uint64_t malformed = 0;   ///< subscriber: unparsable payloads, missing/invalid headers, wrong schema version, failed validation
  std::uint64_t resent = 0;      ///< publisher: last values re-sent to new subscribers
};

}  // namespace mannequin::transport
