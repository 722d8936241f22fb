#pragma once
/// \file schema.hpp
/// \brief Self-describing schemas of the mannequin.v1 messages (for MCAP "protobuf" schema records,
/// Foxglove, and any reader without our .proto files).
///
/// The generated code lives in the build dir; include messages as
/// `#include <mannequin/v1/mocap.pb.h>` (types mannequin::v1::MocapFrame, ...). Link mannequin::proto.
#include <string>
#include <vector>

namespace google::protobuf {
class Descriptor;
}

namespace mannequin::proto {

/// Serialized google.protobuf.FileDescriptorSet holding the .proto file that defines `type` and
/// every file it imports (transitively), dependencies first — exactly the "protobuf" schema
/// encoding of MCAP (schema.name = type->full_name(), e.g. "mannequin.v1.MocapFrame").
/// Built at run time from the generated descriptors, so it always matches the compiled code.
std::string fileDescriptorSet(const google::protobuf::Descriptor* type);

/// Same, from a fully qualified name ("mannequin.v1.WorldState"). \throws std::invalid_argument
/// naming the type when it is not linked into the program's generated pool.
std::string fileDescriptorSet(const std::string& full_name);

/// Fully qualified names of every message of package mannequin.v1 (top-level messages only).
std::vector<std::string> messageTypes();

}  // namespace mannequin::proto
