#pragma once
/// \file io.hpp
/// \brief Plain-text LCP files for mannequin-lcp: blank lines and lines starting with '#'
/// are ignored; the first number is n, then the n×n entries of M row by row, then the n
/// entries of q (any whitespace layout).
#include <string>

#include "mannequin/lcp/lcp.hpp"

namespace mannequin::lcp {

/// Parses text into problem. Returns true on success; otherwise error names the line
/// ("line 4: ...") and problem is left empty.
bool parseLcpText(const std::string& text, LcpProblem& problem, std::string& error);

}  // namespace mannequin::lcp
