#include "cluster_io.hpp"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/wire_format_lite.h>

#include <algorithm>
#include <stdexcept>

#include <mannequin/v1/header.pb.h>

#include "mannequin/deploy/deployment.hpp"

namespace mannequin::tools {

std::vector<std::string> publishEndpoints(const std::string& deployment_file, const std::string& run_dir,
                                          const std::vector<std::string>& names, bool bind) {
  const deploy::Deployment d = deploy::loadDeployment(deployment_file, run_dir);
  std::vector<std::string> out;
  if (names.empty()) {
    for (const deploy::ServiceSpec& s : d.services) out.push_back(bind ? s.publish : s.address);
    return out;
  }
  for (const std::string& n : names) {
    try {
      out.push_back(bind ? d.endpointOf(n) : d.addressOf(n));
    } catch (const std::out_of_range&) {
      std::string all;
      for (const deploy::ServiceSpec& s : d.services) all += (all.empty() ? "" : ", ") + s.name;
      throw std::runtime_error(deployment_file + ": no service '" + n + "' (services: " + all + ")");
    }
  }
  return out;
}

std::optional<RawHeader> parseHeader(std::string_view payload) {
  using google::protobuf::internal::WireFormatLite;
  google::protobuf::io::CodedInputStream in(reinterpret_cast<const std::uint8_t*>(payload.data()),
                                            static_cast<int>(payload.size()));
  while (true) {
    const std::uint32_t tag = in.ReadTag();
    if (tag == 0) return std::nullopt;
    if (WireFormatLite::GetTagFieldNumber(tag) == 1 &&
        WireFormatLite::GetTagWireType(tag) == WireFormatLite::WIRETYPE_LENGTH_DELIMITED) {
      std::uint32_t len = 0;
      if (!in.ReadVarint32(&len)) return std::nullopt;
      std::string bytes;
      if (!in.ReadString(&bytes, static_cast<int>(len))) return std::nullopt;
      v1::Header h;
      if (!h.ParseFromString(bytes)) return std::nullopt;
      return RawHeader{h.sequence(), h.stamp_ns(), h.send_time_ns(), h.source()};
    }
    if (!WireFormatLite::SkipField(&in, tag)) return std::nullopt;
  }
}

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  auto push = [&] {
    const auto b = cur.find_first_not_of(" \t");
    const auto e = cur.find_last_not_of(" \t");
    if (b != std::string::npos) out.push_back(cur.substr(b, e - b + 1));
    cur.clear();
  };
  for (char c : s) {
    if (c == ',') {
      push();
    } else {
      cur.push_back(c);
    }
  }
  push();
  return out;
}

}  // namespace mannequin::tools
