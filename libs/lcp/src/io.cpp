#include "mannequin/lcp/io.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <vector>

namespace mannequin::lcp {

bool parseLcpText(const std::string& text, LcpProblem& problem, std::string& error) {
  problem = LcpProblem{};
  // numbers with the line each came from
  std::vector<double> values;
  std::vector<int> lines;
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream tokens(line);
    std::string tok;
    while (tokens >> tok) {
      errno = 0;
      char* end = nullptr;
      const double v = std::strtod(tok.c_str(), &end);
      if (end == tok.c_str() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
        error = "line " + std::to_string(line_no) + ": '" + tok + "' is not a finite number";
        return false;
      }
      values.push_back(v);
      lines.push_back(line_no);
    }
  }
  if (values.empty()) {
    error = "line " + std::to_string(line_no) + ": empty file, expected n";
    return false;
  }
  // size
  const double nd = values[0];
  if (nd < 0 || nd != std::floor(nd) || nd > 100000) {
    error = "line " + std::to_string(lines[0]) + ": n must be a non-negative integer";
    return false;
  }
  const Index n = static_cast<Index>(nd);
  const std::size_t need = 1 + static_cast<std::size_t>(n * n + n);
  if (values.size() < need) {
    error = "line " + std::to_string(lines.back()) + ": file ends after " +
            std::to_string(values.size() - 1) + " numbers, expected " + std::to_string(n * n) +
            " entries of M and " + std::to_string(n) + " of q";
    return false;
  }
  if (values.size() > need) {
    error = "line " + std::to_string(lines[need]) + ": unexpected extra number after q";
    return false;
  }
  // M row by row, then q
  problem.M.resize(n, n);
  problem.q.resize(n);
  std::size_t k = 1;
  for (Index i = 0; i < n; ++i)
    for (Index j = 0; j < n; ++j) problem.M(i, j) = values[k++];
  for (Index i = 0; i < n; ++i) problem.q[i] = values[k++];
  return true;
}

}  // namespace mannequin::lcp
