#pragma once
/// \file text.hpp
/// \brief Small text helpers the command-line tools share: JSON strings and numbers, and integer lists
/// given on a command line ("0,250,-1").
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace mannequin::core {

/// A JSON string literal of s: quotes and backslashes escaped, control bytes as \u00XX; with
/// `ascii_only`, bytes ≥ 0x7f too (text from a binary file that need not be UTF-8).
inline std::string jsonString(const std::string& s, bool ascii_only = false) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20 || (ascii_only && c >= 0x7f)) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

/// A JSON number with `digits` significant digits, "null" when not finite, never "-0".
inline std::string jsonNumber(double v, int digits = 9) {
  if (!std::isfinite(v)) return "null";
  if (v == 0.0) v = 0.0;
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

/// "0,250,-1" → {0, 250, −1}. \throws std::invalid_argument "expected a comma-separated list of
/// integers, got 'ITEM'" on an empty item or one that is not a whole integer.
inline std::vector<long long> parseIntegerList(const std::string& list) {
  std::vector<long long> values;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    const std::string item = list.substr(start, comma - start);
    long long value = 0;
    std::size_t used = 0;
    try {
      value = std::stoll(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (item.empty() || used != item.size())
      throw std::invalid_argument("expected a comma-separated list of integers, got '" + item + "'");
    values.push_back(value);
    start = comma + 1;
  }
  return values;
}

}  // namespace mannequin::core
