// The FileDescriptorSet helper (MCAP schema records) and the topic table.
#include <google/protobuf/descriptor.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/dynamic_message.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "mannequin/proto/schema.hpp"
#include "mannequin/transport/topics.hpp"

namespace gp = google::protobuf;
using namespace mannequin;

TEST(Schema, FileDescriptorSetHasDependenciesFirstAndRebuildsTheType) {
  const std::string bytes = proto::fileDescriptorSet(v1::MocapFrame::descriptor());
  gp::FileDescriptorSet set;
  ASSERT_TRUE(set.ParseFromString(bytes));
  ASSERT_EQ(set.file_size(), 2);
  EXPECT_EQ(set.file(0).name(), "mannequin/v1/header.proto");
  EXPECT_EQ(set.file(1).name(), "mannequin/v1/mocap.proto");
  // a reader without our generated code rebuilds the type and parses a real message with it
  gp::DescriptorPool pool;
  for (const auto& f : set.file()) ASSERT_NE(pool.BuildFile(f), nullptr) << f.name();
  const gp::Descriptor* type = pool.FindMessageTypeByName("mannequin.v1.MocapFrame");
  ASSERT_NE(type, nullptr);
  v1::MocapFrame frame;
  frame.set_frame_number(42);
  frame.add_bodies()->set_name("hand_l");
  gp::DynamicMessageFactory factory(&pool);
  std::unique_ptr<gp::Message> dyn(factory.GetPrototype(type)->New());
  ASSERT_TRUE(dyn->ParseFromString(frame.SerializeAsString()));
  EXPECT_EQ(dyn->GetReflection()->GetUInt64(*dyn, type->FindFieldByName("frame_number")), 42u);
}

TEST(Schema, ByNameAndEveryTopicTypeExists) {
  EXPECT_EQ(proto::fileDescriptorSet("mannequin.v1.WorldState"), proto::fileDescriptorSet(v1::WorldState::descriptor()));
  EXPECT_THROW(proto::fileDescriptorSet("mannequin.v1.Nope"), std::invalid_argument);
  const auto names = proto::messageTypes();
  for (const auto& t : transport::topics::kAll) {
    EXPECT_NE(std::find(names.begin(), names.end(), std::string(t.type)), names.end()) << t.type;
    EXPECT_FALSE(proto::fileDescriptorSet(std::string(t.type)).empty());
  }
  for (const char* n : {"mannequin.v1.Header", "mannequin.v1.MocapFrame", "mannequin.v1.WorldState",
                        "mannequin.v1.CollisionQuery", "mannequin.v1.ContactSet", "mannequin.v1.ModeCommand",
                        "mannequin.v1.ScenarioState", "mannequin.v1.Trigger", "mannequin.v1.Heartbeat"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
}

TEST(Topics, TableMatchesTypedConstants) {
  using namespace transport::topics;
  EXPECT_EQ(std::size(kAll), 9u);
  EXPECT_EQ(find("sim.world")->type, v1::WorldState::descriptor()->full_name());
  EXPECT_EQ(find("mocap.frame")->type, v1::MocapFrame::descriptor()->full_name());
  EXPECT_EQ(find(kHeartbeat.name)->delivery, transport::Delivery::kLatest);
  EXPECT_EQ(find(kMocapFrame.name)->delivery, transport::Delivery::kQueue);
  EXPECT_EQ(find("sim"), nullptr);
  EXPECT_EQ(find("sim.world.x"), nullptr);
}
