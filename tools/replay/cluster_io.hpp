#pragma once
// What mannequin-record and mannequin-replay share: endpoints from a deployment file, the Header
// of a raw payload, the schema of a topic.
#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mannequin::tools {

/// Endpoints of the deployment file's services (deploy::loadDeployment, ${RUN_DIR} expanded with
/// run_dir, "" = the file's default): `names` empty = every service, else the named ones; `bind`: the
/// endpoints they bind (to stand in for them), else the addresses others connect to (the same on a
/// single host; multi-host: tcp://HOST_ADDRESS:PORT for a service binding tcp://*:PORT).
/// \throws core::ConfigError "FILE:LINE: ..." for a bad file, std::runtime_error naming
/// an unknown service (with the deployment's services).
std::vector<std::string> publishEndpoints(const std::string& deployment_file, const std::string& run_dir,
                                          const std::vector<std::string>& names = {}, bool bind = false);

/// Header fields of a raw mannequin.v1 payload (field 1 of every top-level message).
struct RawHeader {
  std::uint64_t sequence = 0;
  std::int64_t stamp_ns = 0;
  std::int64_t send_time_ns = 0;
  std::string source;
};
/// nullopt when the payload is not a protobuf message with a Header in field 1.
std::optional<RawHeader> parseHeader(std::string_view payload);

/// "a,b , c" -> {"a","b","c"} (empty parts dropped).
std::vector<std::string> splitList(const std::string& s);

}  // namespace mannequin::tools
