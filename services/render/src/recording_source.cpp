// Frames of a recording's sim.world (every Nth message, or at the recording's pace) and of the static
// scene (mannequin/renderservice/frame_source.hpp).
#include <cmath>
#include <stdexcept>

#include "mannequin/recording/mcap_reader.hpp"
#include "mannequin/renderservice/frame_source.hpp"

namespace mannequin::renderservice {

std::vector<v1::WorldState> readRecording(const std::string& path) {
  const recording::McapReader reader = recording::McapReader::open(path);
  recording::ReadFilter filter;
  filter.topics = {"sim.world"};
  (void)reader.channelsOf(filter.topics);  // throws listing the file's topics when it has no sim.world
  std::vector<v1::WorldState> out;
  recording::MessageCursor cursor = reader.messages(filter);
  recording::Message msg;
  while (cursor.next(msg)) {
    v1::WorldState ws;
    if (!ws.ParseFromString(msg.data))
      throw std::runtime_error(path + ": sim.world message " + std::to_string(out.size()) + " is not a WorldState");
    out.push_back(std::move(ws));
  }
  return out;
}

RecordingSource::RecordingSource(std::vector<v1::WorldState> states, Pace pace, int every)
    : states_(std::move(states)), pace_(pace), every_(static_cast<std::size_t>(every)), start_(std::chrono::steady_clock::now()) {}

bool RecordingSource::finished() const { return pace_ == Pace::kEveryMessage && next_ >= states_.size(); }

std::optional<Frame> RecordingSource::next() {
  if (pace_ == Pace::kEveryMessage) {
    if (next_ >= states_.size()) return std::nullopt;
    const std::size_t i = next_;
    next_ += every_;
    return Frame{&states_[i], i, false};
  }
  if (states_.empty()) return std::nullopt;
  // the state at the recording's sim time now (wall time since the start), looping
  const double span = std::max(1e-9, states_.back().sim_time() - states_.front().sim_time());
  const double t = std::fmod(std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(), span) +
                   states_.front().sim_time();
  std::size_t i = 0;
  while (i + 1 < states_.size() && states_[i + 1].sim_time() <= t) ++i;
  return Frame{&states_[i], i, false};
}

std::optional<Frame> StaticSource::next() {
  if (given_) return std::nullopt;
  given_ = true;
  return Frame{};
}

}  // namespace mannequin::renderservice
