#pragma once
/// \file paths.hpp
/// \brief Finding the project's shipped files (configs/, data/) from any working directory.
#include <string>
#include <vector>

namespace mannequin::core {

/// The directories a relative data path is tried against, in order: the working directory, the
/// MANNEQUIN_SOURCE_DIR environment variable when set, the source tree this binary was built from, and
/// the executable's directory and its two parents (build/bin → the checkout).
std::vector<std::string> dataSearchDirs();

/// Resolves `path`: an absolute path, or a relative one found under one of dataSearchDirs(), is returned
/// as an existing path. \throws ConfigError "PATH: not found (looked in: ...)" when none exists.
std::string findData(const std::string& path);

}  // namespace mannequin::core
