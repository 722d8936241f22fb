#pragma once
// The states a demonstration's scenario went through, each with the span of sim time it lasted: what the
// demo tests assert the order of and print.
#include <string>
#include <vector>

#include "mannequin/scenario/engine.hpp"

namespace mannequin::demo_test {

struct StateSpan {
  std::string state;
  double from = 0, to = 0;  ///< s of sim time
};

class Timeline {
 public:
  /// Records the engine's state at sim time t (nothing while the scenario does not run yet).
  void see(const scenario::Engine* e, double t) {
    if (e == nullptr || e->state() < 0) return;
    if (spans_.empty() || spans_.back().state != e->stateName()) spans_.push_back({e->stateName(), t, t});
    spans_.back().to = t;
  }
  const std::vector<StateSpan>& spans() const { return spans_; }
  std::vector<std::string> states() const {
    std::vector<std::string> out;
    for (const StateSpan& s : spans_) out.push_back(s.state);
    return out;
  }
  /// "state [from, to] state [from, to] ..."
  std::string str() const {
    std::string out;
    for (const StateSpan& s : spans_) out += s.state + " [" + std::to_string(s.from) + ", " + std::to_string(s.to) + "] ";
    return out;
  }

 private:
  std::vector<StateSpan> spans_;
};

}  // namespace mannequin::demo_test
