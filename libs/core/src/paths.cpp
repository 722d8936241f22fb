#include "mannequin/core/paths.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "mannequin/core/config.hpp"

namespace mannequin::core {
namespace fs = std::filesystem;

std::vector<std::string> dataSearchDirs() {
  std::vector<std::string> dirs;
  auto add = [&dirs](const fs::path& d) {  // each directory once, in order
    const std::string s = d.lexically_normal().string();
    if (std::find(dirs.begin(), dirs.end(), s) == dirs.end()) dirs.push_back(s);
  };
  std::error_code ec;
  const fs::path cwd = fs::current_path(ec);
  if (!ec) add(cwd);
  if (const char* env = std::getenv("MANNEQUIN_SOURCE_DIR"); env != nullptr && *env != '\0') add(env);
#ifdef MANNEQUIN_SOURCE_TREE
  add(MANNEQUIN_SOURCE_TREE);
#endif
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    fs::path d = exe.parent_path();
    for (int up = 0; up < 3 && !d.empty(); ++up, d = d.parent_path()) add(d);
  }
  return dirs;
}

std::string findData(const std::string& path) {
  std::error_code ec;
  const fs::path p(path);
  if (p.is_absolute()) {
    if (fs::exists(p, ec)) return path;
    throw ConfigError(path + ": not found");
  }
  std::string tried;
  for (const std::string& dir : dataSearchDirs()) {
    const fs::path candidate = fs::path(dir) / p;
    if (fs::exists(candidate, ec)) return candidate.lexically_normal().string();
    tried += (tried.empty() ? "" : ", ") + dir;
  }
  throw ConfigError(path + ": not found (looked in: " + tried + ")");
}

}  // namespace mannequin::core
