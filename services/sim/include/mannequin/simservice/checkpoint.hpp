#pragma once
/// \file checkpoint.hpp
/// \brief The sim's checkpoint: a restarted sim resumes from its last published world state.
///
/// mannequin-sim --checkpoint FILE keeps in FILE the last sim.world it published (at most every
/// `--checkpoint-period` s) with what sim.world lacks to resume from it (each calibrated mannequin's
/// posture target q_c and control-frame offsets bMf): v1::SimCheckpoint. --resume FILE reads it at start
/// and puts the World back (sim::World::restore: step count, every mannequin's q and calibration, every
/// object's pose); the live mocap drives it again from its next frame. mannequin-launch passes both
/// (a deployment service's `checkpoint:` key, docs/cluster.md).
///
/// File: the 10 bytes "MQSIMCKPT1", the payload's size (8 bytes, little endian), its FNV-1a 64-bit hash
/// (8 bytes, little endian), the payload (v1::SimCheckpoint, protobuf). Written to FILE.tmp then renamed
/// over FILE, so a reader sees the previous checkpoint or the new one, never a partial one.
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <mannequin/v1/checkpoint.pb.h>

#include "mannequin/sim/world.hpp"

namespace mannequin::simservice {

/// The checkpoint of `world` whose state `published` (toWorldState of that World, just published) is.
void toCheckpoint(const sim::World& world, const v1::WorldState& published, std::int64_t written_ns, v1::SimCheckpoint& out);

/// The file's bytes (framing above).
std::string encodeCheckpoint(const v1::SimCheckpoint& checkpoint);
/// \throws std::runtime_error "WHERE: ..." for a bad magic, a truncated or hashed-wrong payload, or
/// bytes protobuf cannot parse.
v1::SimCheckpoint decodeCheckpoint(const std::string& bytes, const std::string& where);
/// \throws std::runtime_error "FILE: ..." (cannot read, or decodeCheckpoint's errors).
v1::SimCheckpoint readCheckpoint(const std::string& path);
/// Writes FILE.tmp and renames it over FILE. \throws std::runtime_error "FILE: ...".
void writeCheckpointFile(const std::string& path, const std::string& bytes);

/// The World state in a checkpoint (sim::World::restore's input). \throws std::invalid_argument naming
/// what is missing or malformed (a calibrated mannequin without its calibration, a pose without rotation).
sim::WorldCheckpoint fromCheckpoint(const v1::SimCheckpoint& checkpoint);

/// Restores `world` from a checkpoint. Returns what was not restored, one line each (the caller logs them):
/// velocities (zero), held objects (grasps), the scenario's state. \throws std::invalid_argument naming
/// the mismatch (fromCheckpoint, sim::World::restore); the World is unchanged then.
std::vector<std::string> restoreWorld(sim::World& world, const v1::SimCheckpoint& checkpoint);

/// Writes checkpoints on its own thread (the sim's step loop only hands over the bytes): the newest bytes
/// submitted win, older ones not yet written are dropped.
class CheckpointWriter {
 public:
  explicit CheckpointWriter(std::string path);
  ~CheckpointWriter();  ///< writes what is pending, then joins
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;
  void submit(std::string bytes);
  std::uint64_t written() const;
  std::uint64_t failed() const;
  /// The last write error ("" none).
  std::string lastError() const;

 private:
  void run();
  std::string path_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::string pending_;
  bool has_pending_ = false, stop_ = false;
  std::uint64_t written_ = 0, failed_ = 0;
  std::string error_;
  std::thread thread_;
};

}  // namespace mannequin::simservice
