#include "cluster_io.hpp"

#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/wire_format_lite.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <csignal>
#include <stdexcept>

#include <mannequin/v1/header.pb.h>

namespace mannequin::tools {

namespace {

void collect(const YAML::Node& node, const std::string& file, std::vector<std::string>& out) {
  if (node.IsMap()) {
    for (const auto& kv : node) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string();
      if (key == "publish") {
        const YAML::Node& v = kv.second;
        std::vector<std::string> eps;
        if (v.IsScalar()) {
          eps.push_back(v.Scalar());
        } else if (v.IsSequence()) {
          for (const auto& e : v) {
            if (!e.IsScalar()) {
              throw std::runtime_error(file + ":" + std::to_string(e.Mark().line + 1) +
                                       ": field 'publish': expected an endpoint string");
            }
            eps.push_back(e.Scalar());
          }
        } else {
          throw std::runtime_error(file + ":" + std::to_string(v.Mark().line + 1) +
                                   ": field 'publish': expected an endpoint or a list of endpoints");
        }
        for (const std::string& e : eps) {
          if (std::find(out.begin(), out.end(), e) == out.end()) out.push_back(e);
        }
      } else {
        collect(kv.second, file, out);
      }
    }
  } else if (node.IsSequence()) {
    for (const auto& e : node) collect(e, file, out);
  }
}

std::atomic<bool> g_stop{false};  // lock-free: safe to set from a signal handler

void onSignal(int) {
  g_stop.store(true);
}

}  // namespace

std::vector<std::string> publishEndpoints(const std::string& deployment_file) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(deployment_file);
  } catch (const YAML::BadFile&) {
    throw std::runtime_error(deployment_file + ": cannot read the deployment file");
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(deployment_file + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  std::vector<std::string> out;
  collect(root, deployment_file, out);
  if (out.empty()) throw std::runtime_error(deployment_file + ": no 'publish' endpoint in the deployment file");
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

const std::atomic<bool>& stopOnSignals() {
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::signal(SIGPIPE, SIG_IGN);
  return g_stop;
}

}  // namespace mannequin::tools
