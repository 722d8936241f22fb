// Shipped files are found from any working directory (a benchmark started in build/bin), and a file that
// is nowhere gets an error naming it and where it was looked for.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>

#include "mannequin/core/config.hpp"
#include "mannequin/core/paths.hpp"

namespace {
namespace fs = std::filesystem;
using mannequin::core::ConfigError;
using mannequin::core::findData;

struct Cwd {
  explicit Cwd(const fs::path& p) : old(fs::current_path()) { fs::current_path(p); }
  ~Cwd() { fs::current_path(old); }
  fs::path old;
};

TEST(FindData, FindsShippedConfigFromAnotherDirectory) {
  Cwd in(fs::temp_directory_path());
  const std::string found = findData("configs/mannequins/male_50th.yaml");
  EXPECT_TRUE(fs::exists(found)) << found;
  EXPECT_TRUE(fs::path(found).is_absolute()) << found;
}

TEST(FindData, PrefersTheWorkingDirectory) {
  const fs::path dir = fs::temp_directory_path() / ("mannequin_paths_" + std::to_string(getpid()));
  fs::create_directories(dir / "configs/mannequins");
  { std::FILE* f = std::fopen((dir / "configs/mannequins/male_50th.yaml").c_str(), "w"); ASSERT_NE(f, nullptr); std::fclose(f); }
  {
    Cwd in(dir);
    EXPECT_EQ(fs::path(findData("configs/mannequins/male_50th.yaml")), dir / "configs/mannequins/male_50th.yaml");
  }
  fs::remove_all(dir);
}

TEST(FindData, MissingFileNamesItAndTheDirectoriesTried) {
  try {
    findData("configs/no_such_file.yaml");
    FAIL() << "no error for a missing file";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("configs/no_such_file.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find("looked in"), std::string::npos) << what;
  }
  EXPECT_THROW(findData("/no/such/absolute/path.yaml"), ConfigError);
}

}  // namespace
