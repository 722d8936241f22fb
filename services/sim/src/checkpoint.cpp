#include "mannequin/simservice/checkpoint.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "mannequin/scenario/engine.hpp"
#include "mannequin/transport/convert.hpp"

namespace mannequin::simservice {

namespace {
constexpr char kMagic[] = "MQSIMCKPT1";
constexpr std::size_t kMagicSize = sizeof(kMagic) - 1;
constexpr std::size_t kHeaderSize = kMagicSize + 16;

std::uint64_t fnv1a(const std::string& bytes, std::size_t from) {
  std::uint64_t h = 14695981039346656037ULL;
  for (std::size_t i = from; i < bytes.size(); ++i) {
    h ^= static_cast<unsigned char>(bytes[i]);
    h *= 1099511628211ULL;
  }
  return h;
}
void putU64(std::string& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
std::uint64_t getU64(const std::string& in, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(static_cast<unsigned char>(in[at + static_cast<std::size_t>(i)])) << (8 * i);
  return v;
}
skeleton::VectorX vectorOf(const google::protobuf::RepeatedField<double>& r) {
  skeleton::VectorX v(r.size());
  for (int i = 0; i < r.size(); ++i) v(i) = r.Get(i);
  return v;
}
void checkedPose(const v1::Pose& p, const std::string& what) {
  const std::string bad = transport::checkPose(p);
  if (!bad.empty()) throw std::invalid_argument("checkpoint: " + what + ": " + bad);
}
}  // namespace

void toCheckpoint(const sim::World& world, const v1::WorldState& published, std::int64_t written_ns, v1::SimCheckpoint& out) {
  out.Clear();
  *out.mutable_world() = published;
  out.set_written_ns(written_ns);
  // q_c and the offsets: from the World's own checkpoint (the same state as `published`)
  const sim::WorldCheckpoint wc = world.checkpoint();
  for (const sim::MannequinCheckpoint& mc : wc.mannequins) {
    if (!mc.calibrated) continue;
    v1::MannequinCalibration* c = out.add_calibration();
    c->set_name(mc.name);
    for (Eigen::Index k = 0; k < mc.q_posture.size(); ++k) c->add_q_posture(mc.q_posture(k));
    for (const sim::MannequinCheckpoint::Frame& f : mc.frames) {
      v1::NamedPose* np = c->add_offsets();
      np->set_name(f.frame);
      transport::toMsg(f.offset, *np->mutable_pose());
    }
  }
  if (const scenario::Engine* e = world.scenarioEngine(); e != nullptr) {
    out.set_scenario(e->scenario().name);
    if (e->state() >= 0) {
      out.set_scenario_state(e->stateName());
      out.set_scenario_time_in_state(e->timeInState());
    }
  }
}

std::string encodeCheckpoint(const v1::SimCheckpoint& checkpoint) {
  std::string payload;
  if (!checkpoint.SerializeToString(&payload)) throw std::runtime_error("checkpoint: cannot serialize");
  std::string out(kMagic, kMagicSize);
  putU64(out, payload.size());
  out += std::string(8, '\0');
  out += payload;
  const std::uint64_t h = fnv1a(out, kHeaderSize);
  std::string hash;
  putU64(hash, h);
  out.replace(kMagicSize + 8, 8, hash);
  return out;
}

v1::SimCheckpoint decodeCheckpoint(const std::string& bytes, const std::string& where) {
  if (bytes.size() < kHeaderSize || bytes.compare(0, kMagicSize, kMagic) != 0)
    throw std::runtime_error(where + ": not a mannequin-sim checkpoint (no MQSIMCKPT1 header)");
  const std::uint64_t size = getU64(bytes, kMagicSize);
  if (size != bytes.size() - kHeaderSize)
    throw std::runtime_error(fmt::format("{}: truncated or padded: the header says {} payload bytes, the file has {}", where, size,
                                         bytes.size() - kHeaderSize));
  if (getU64(bytes, kMagicSize + 8) != fnv1a(bytes, kHeaderSize))
    throw std::runtime_error(where + ": corrupt: the payload's hash does not match the header's");
  v1::SimCheckpoint c;
  if (!c.ParseFromArray(bytes.data() + kHeaderSize, static_cast<int>(size)))
    throw std::runtime_error(where + ": corrupt: the payload is not a SimCheckpoint message");
  return c;
}

v1::SimCheckpoint readCheckpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  std::stringstream ss;
  ss << in.rdbuf();
  return decodeCheckpoint(ss.str(), path);
}

void writeCheckpointFile(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) throw std::runtime_error(path + ": cannot write " + tmp + ": " + std::strerror(errno));
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  const int err = errno;
  if (std::fclose(f) != 0 || !ok) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot write " + tmp + ": " + std::strerror(ok ? errno : err));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": cannot rename " + tmp + " over it: " + std::strerror(e));
  }
}

sim::WorldCheckpoint fromCheckpoint(const v1::SimCheckpoint& checkpoint) {
  const v1::WorldState& w = checkpoint.world();
  sim::WorldCheckpoint out;
  out.step = w.step();
  for (const v1::MannequinState& ms : w.mannequins()) {
    sim::MannequinCheckpoint mc;
    mc.name = ms.name();
    mc.model = ms.model();
    mc.q = vectorOf(ms.q());
    mc.calibrated = ms.calibrated();
    if (mc.calibrated) {
      const v1::MannequinCalibration* cal = nullptr;
      for (const v1::MannequinCalibration& c : checkpoint.calibration())
        if (c.name() == ms.name()) cal = &c;
      if (cal == nullptr) throw std::invalid_argument("checkpoint: mannequin '" + ms.name() + "' is calibrated but has no calibration");
      mc.q_posture = vectorOf(cal->q_posture());
      for (const v1::ControlFrameState& cf : ms.control_frames()) {
        const v1::NamedPose* off = nullptr;
        for (const v1::NamedPose& np : cal->offsets())
          if (np.name() == cf.frame()) off = &np;
        if (off == nullptr)
          throw std::invalid_argument("checkpoint: mannequin '" + ms.name() + "': no offset of control frame '" + cf.frame() + "'");
        const std::string who = "mannequin '" + ms.name() + "' frame '" + cf.frame() + "'";
        checkedPose(off->pose(), who + " offset");
        checkedPose(cf.target(), who + " target");
        mc.frames.push_back({cf.frame(), cf.body(), transport::fromMsg(off->pose()), transport::fromMsg(cf.target()), cf.weight()});
      }
    }
    out.mannequins.push_back(std::move(mc));
  }
  for (const v1::ObjectState& os : w.objects()) {
    if (!os.hinged()) checkedPose(os.pose(), "object '" + os.name() + "'");
    out.objects.push_back({os.name(), os.hinged(), transport::fromMsg(os.pose()), os.angle()});
  }
  return out;
}

std::vector<std::string> restoreWorld(sim::World& world, const v1::SimCheckpoint& checkpoint) {
  std::vector<std::string> notes = world.restore(fromCheckpoint(checkpoint));
  notes.insert(notes.begin(), "velocities start at zero (mannequins and objects)");
  for (const v1::ObjectState& os : checkpoint.world().objects())
    if (os.held()) notes.push_back("object '" + os.name() + "' was held: the grasp is not restored (the object is released)");
  if (!checkpoint.scenario().empty()) {
    const scenario::Engine* e = world.scenarioEngine();
    notes.push_back(fmt::format("scenario '{}' was in state '{}' for {:.3f} s: not restored, it starts again from '{}'",
                                checkpoint.scenario(), checkpoint.scenario_state().empty() ? "(not started)" : checkpoint.scenario_state(),
                                checkpoint.scenario_time_in_state(),
                                e != nullptr && !e->scenario().states.empty() ? e->scenario().states.front().name : std::string("?")));
  }
  return notes;
}

CheckpointWriter::CheckpointWriter(std::string path) : path_(std::move(path)), thread_([this] { run(); }) {}

CheckpointWriter::~CheckpointWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_one();
  thread_.join();
}

void CheckpointWriter::submit(std::string bytes) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.swap(bytes);
    has_pending_ = true;
  }
  cv_.notify_one();
}

std::uint64_t CheckpointWriter::written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return written_;
}
std::uint64_t CheckpointWriter::failed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failed_;
}
std::string CheckpointWriter::lastError() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

void CheckpointWriter::run() {
  std::string bytes;
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [this] { return has_pending_ || stop_; });
      if (!has_pending_) return;  // stop, nothing pending
      bytes.swap(pending_);
      has_pending_ = false;
    }
    std::string error;
    try {
      writeCheckpointFile(path_, bytes);
    } catch (const std::runtime_error& e) {
      error = e.what();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (error.empty()) ++written_;
    else {
      ++failed_;
      error_ = error;
    }
  }
}

}  // namespace mannequin::simservice
