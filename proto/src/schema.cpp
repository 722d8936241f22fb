#include "mannequin/proto/schema.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>

#include <functional>
#include <set>
#include <stdexcept>

// the generated files register themselves in the generated pool when linked; including their headers
// makes sure every file of the package is linked into any program that uses this helper
#include <mannequin/v1/collision.pb.h>
#include <mannequin/v1/health.pb.h>
#include <mannequin/v1/header.pb.h>
#include <mannequin/v1/mocap.pb.h>
#include <mannequin/v1/scenario.pb.h>
#include <mannequin/v1/world.pb.h>

namespace mannequin::proto {

namespace gp = google::protobuf;

std::string fileDescriptorSet(const gp::Descriptor* type) {
  if (type == nullptr) throw std::invalid_argument("fileDescriptorSet: null descriptor");
  gp::FileDescriptorSet set;
  std::set<std::string> seen;
  std::function<void(const gp::FileDescriptor*)> add = [&](const gp::FileDescriptor* file) {
    if (!seen.insert(file->name()).second) return;
    for (int i = 0; i < file->dependency_count(); ++i) add(file->dependency(i));
    file->CopyTo(set.add_file());
  };
  add(type->file());
  return set.SerializeAsString();
}

std::string fileDescriptorSet(const std::string& full_name) {
  // touch one message of each file so that the linker keeps them all
  (void)v1::Header::descriptor();
  (void)v1::MocapFrame::descriptor();
  (void)v1::WorldState::descriptor();
  (void)v1::CollisionQuery::descriptor();
  (void)v1::ScenarioState::descriptor();
  (void)v1::Heartbeat::descriptor();
  const gp::Descriptor* type = gp::DescriptorPool::generated_pool()->FindMessageTypeByName(full_name);
  if (type == nullptr) throw std::invalid_argument("fileDescriptorSet: unknown message type '" + full_name + "'");
  return fileDescriptorSet(type);
}

std::vector<std::string> messageTypes() {
  const gp::FileDescriptor* files[] = {v1::Header::descriptor()->file(),         v1::MocapFrame::descriptor()->file(),
                                       v1::WorldState::descriptor()->file(),     v1::CollisionQuery::descriptor()->file(),
                                       v1::ScenarioState::descriptor()->file(),  v1::Heartbeat::descriptor()->file()};
  std::vector<std::string> names;
  for (const gp::FileDescriptor* f : files)
    for (int i = 0; i < f->message_type_count(); ++i) names.push_back(f->message_type(i)->full_name());
  return names;
}

}  // namespace mannequin::proto
