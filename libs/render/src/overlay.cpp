#include "mannequin/render/overlay.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <map>

#include "mannequin/v1/world.pb.h"

namespace mannequin::render {
namespace {

// Each glyph: polylines separated by spaces; a polyline is a run of points "xy" with x in 0..2 and y in
// 0..4 (y up from the baseline).
const char* glyph(char c) {
  switch (std::toupper(static_cast<unsigned char>(c))) {
    case '0': return "0020240400 0420";
    case '1': return "1014 0314 0020";
    case '2': return "042422020020";
    case '3': return "04242000 0222";
    case '4': return "040222 2420";
    case '5': return "240402222000";
    case '6': return "240400202202";
    case '7': return "042410";
    case '8': return "0020240400 0222";
    case '9': return "220204242000";
    case '.': return "1011";
    case ':': return "1011 1314";
    case '-': return "0222";
    case '/': return "0024";
    case '%': return "0024 0314 1020";
    case '_': return "0020";
    case ',': return "1110";
    case 'A': return "0003142320 0222";
    case 'B': return "0004142312211000 0212";
    case 'C': return "24040020";
    case 'D': return "00041423211000";
    case 'E': return "24040020 0212";
    case 'F': return "240400 0212";
    case 'G': return "240400202212";
    case 'H': return "0400 2420 0222";
    case 'I': return "1014 0424 0020";
    case 'J': return "24200001";
    case 'K': return "0400 2402 0220";
    case 'L': return "040020";
    case 'M': return "0004122420";
    case 'N': return "00042024";
    case 'O': return "0020240400";
    case 'P': return "0004242202";
    case 'Q': return "0020240400 1120";
    case 'R': return "0004242202 1220";
    case 'S': return "240402222000";
    case 'T': return "0424 1410";
    case 'U': return "04002024";
    case 'V': return "041024";
    case 'W': return "0400122024";
    case 'X': return "0024 0420";
    case 'Y': return "0412 2412 1210";
    case 'Z': return "04242000";
    default: return nullptr;
  }
}

}  // namespace

bool hasGlyph(char c) { return glyph(c) != nullptr; }

std::vector<Segment2> strokeText(std::string_view text, float x, float y, float height) {
  std::vector<Segment2> out;
  const float u = height / 4.0f;
  float cx = x;
  for (char c : text) {
    if (const char* g = glyph(c)) {
      const std::size_t n = std::strlen(g);
      // runs of point pairs separated by spaces
      for (std::size_t i = 0; i < n;) {
        std::size_t j = i;
        while (j < n && g[j] != ' ') ++j;
        for (std::size_t k = i; k + 3 < j; k += 2) {
          const auto px = [&](std::size_t at) { return cx + static_cast<float>(g[at] - '0') * u; };
          const auto py = [&](std::size_t at) { return y + (4.0f - static_cast<float>(g[at + 1] - '0')) * u; };
          out.push_back({px(k), py(k), px(k + 2), py(k + 2)});
        }
        i = j + 1;
      }
    }
    cx += 3.0f * u;
  }
  return out;
}

namespace {
std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}
}  // namespace

std::vector<OverlayLine> overlayLines(const v1::WorldState& ws, const OverlayLive* live, const OverlayStyle& style) {
  std::vector<OverlayLine> out;
  char buf[200];
  const auto step = static_cast<unsigned long long>(ws.step());
  if (live == nullptr)
    std::snprintf(buf, sizeof buf, "FRAME %llu  T %.3f S", step, ws.sim_time());
  else
    std::snprintf(buf, sizeof buf, "FRAME %llu  FPS %.1f  LATE %.1f MS", step, live->fps, live->late_ms);
  std::string first = buf;
  // the sim's lateness behind mocap: this state's send time − the send time of the newest mocap frame it used
  const std::int64_t sent = ws.header().send_time_ns(), mocap_sent = ws.mocap().send_time_ns();
  if (sent > 0 && mocap_sent > 0) {
    std::snprintf(buf, sizeof buf, "  SIM LAG %.1f MS", static_cast<double>(sent - mocap_sent) * 1e-6);
    first += buf;
  }
  out.push_back({first, style.text});
  if (ws.contacts_stale()) {
    const std::uint64_t behind = ws.step() >= ws.contacts_step() ? ws.step() - ws.contacts_step() : 0;
    std::snprintf(buf, sizeof buf, "CONTACTS STALE  %llu STEPS OLD", static_cast<unsigned long long>(behind));
    out.push_back({buf, style.warning});
  }
  // the scenario as sim.world shows it: active mechanisms, control frames not in mode "free", occluded ones
  std::string scenario;
  if (ws.active_mechanisms_size() > 0) {
    scenario += "MECHANISMS";
    for (const std::string& m : ws.active_mechanisms()) {
      scenario.push_back(' ');
      scenario.append(upper(m));
    }
  }
  std::map<std::string, std::string> by_mode;  // mode → frames (ordered: deterministic)
  std::string occluded;
  const bool prefix = ws.mannequins_size() > 1;
  for (const v1::MannequinState& m : ws.mannequins())
    for (const v1::ControlFrameState& cf : m.control_frames()) {
      std::string name = " ";
      if (prefix) name.append(upper(m.name())).push_back('/');
      name.append(upper(cf.frame()));
      if (!cf.mode().empty() && cf.mode() != "free") by_mode[upper(cf.mode())].append(name);
      if (!cf.tracked() && !cf.body().empty()) occluded.append(name);
    }
  const auto group = [&scenario](const std::string& head, const std::string& names) {
    if (!scenario.empty()) scenario.append("  ");
    scenario.append(head).append(names);
  };
  for (const auto& [mode, frames] : by_mode) group(mode, frames);
  if (!occluded.empty()) group("OCCLUDED", occluded);
  if (!scenario.empty()) out.push_back({scenario, style.scenario});
  return out;
}

std::vector<std::pair<std::vector<Segment2>, Colour>> layoutOverlay(const std::vector<OverlayLine>& lines,
                                                                    int image_height) {
  const float h = std::max(8.0f, static_cast<float>(image_height) / 40.0f);
  std::vector<std::pair<std::vector<Segment2>, Colour>> out;
  for (std::size_t i = 0; i < lines.size(); ++i)
    out.emplace_back(strokeText(lines[i].text, h, h + 1.75f * h * static_cast<float>(i), h), lines[i].colour);
  return out;
}

}  // namespace mannequin::render
