// fuzz-transport: arbitrary bytes as the payload of every topic (what a Subscriber does before a
// handler sees a message: parse, header checks, the topic's validator) and as an ART DTrack2 datagram.
// Must never crash, hang or trip a sanitizer; accepted messages must be finite where validated.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "mannequin/mocap/dtrack2.hpp"
#include "mannequin/transport/convert.hpp"
#include "mannequin/transport/validate.hpp"

using namespace mannequin;

namespace {
template <class M>
void parseAndValidate(const std::uint8_t* data, std::size_t size, std::string (*validate)(const M&)) {
  M m;
  if (!m.ParseFromArray(data, static_cast<int>(size))) return;
  if (validate != nullptr) (void)validate(m);
  (void)m.SerializeAsString();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 1 << 16) return 0;
  parseAndValidate<v1::MocapFrame>(data, size, transport::validateMocapFrame);
  parseAndValidate<v1::ContactSet>(data, size, transport::validateContactSet);
  parseAndValidate<v1::CollisionQuery>(data, size, transport::validateCollisionQuery);
  parseAndValidate<v1::WorldState>(data, size, nullptr);
  parseAndValidate<v1::Heartbeat>(data, size, nullptr);
  v1::Pose pose;
  if (pose.ParseFromArray(data, static_cast<int>(size)) && transport::checkPose(pose).empty()) {
    const math::SE3 H = transport::fromMsg(pose);
    if (!H.R.allFinite() || !H.p.allFinite()) __builtin_trap();
  }
  mocap::DTrackDatagram frame;
  if (mocap::parseDTrack(std::string_view(reinterpret_cast<const char*>(data), size), frame).empty())
    for (const auto& b : frame.bodies)
      if (!b.position_mm.allFinite() || !b.rotation.allFinite()) __builtin_trap();
  return 0;
}
