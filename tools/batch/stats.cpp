// mannequin-batch: statistics of the per-sample series (run.hpp).
#include <algorithm>

#include <fmt/format.h>

#include "run.hpp"

namespace mannequin::batch {

std::string num(double v) { return std::isfinite(v) ? fmt::format("{:.17g}", v) : "null"; }
std::string shortNum(double v, int digits) { return std::isfinite(v) ? fmt::format("{:.{}f}", v, digits) : "–"; }

double mean(const std::vector<double>& v) {
  double s = 0;
  long long n = 0;
  for (double x : v)
    if (std::isfinite(x)) s += x, ++n;
  return n ? s / static_cast<double>(n) : kNaN;
}
double maxOf(const std::vector<double>& v) {
  double m = kNaN;
  for (double x : v)
    if (std::isfinite(x) && !(x <= m)) m = x;
  return m;
}
double minOf(const std::vector<double>& v) {
  double m = kNaN;
  for (double x : v)
    if (std::isfinite(x) && !(x >= m)) m = x;
  return m;
}
double percentile(std::vector<double> v, double p) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::min<double>(static_cast<double>(v.size() - 1), std::floor(p * static_cast<double>(v.size()))))];
}

std::vector<Worst> worst(std::vector<Worst> all) {
  std::stable_sort(all.begin(), all.end(), [](const Worst& a, const Worst& b) { return a.score > b.score; });
  if (all.size() > kWorst) all.resize(kWorst);
  return all;
}

}  // namespace mannequin::batch
