#pragma once
// Built tools run as separate processes by the tests: a shell command line under coreutils timeout(1)
// with its stdout and stderr captured, a temporary directory removed with its contents at scope exit (and
// a fixture holding one per test), and python3 checks run the same way. Header-only, no state beyond the objects the caller holds.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>

namespace mannequin::testutil {

/// The directory the tools land in (build/bin): the parent of the test binary's (build/bin/tests).
inline std::filesystem::path binDir() {
  return std::filesystem::read_symlink("/proc/self/exe").parent_path().parent_path();
}

/// The bytes of the file at `path` ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh directory TMPDIR/<prefix>_XXXXXX (mkdtemp), removed with everything in it by the destructor.
/// On failure the test fails naming the directory and path() is empty.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix) {
    std::string templ = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
    if (::mkdtemp(templ.data()) == nullptr)
      ADD_FAILURE() << "mkdtemp " << templ << ": " << std::strerror(errno);
    else
      path_ = templ;
  }
  ~TempDir() {
    std::error_code ec;  // a destructor does not throw: what cannot be removed stays
    if (!path_.empty()) std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// path() / name (nothing is created).
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// A fixture whose tests keep their files in dir_, a fresh TMPDIR/<suite>_XXXXXX for each test, removed
/// after it. (The suite's name alone keeps the paths short enough for ipc:// sockets in them.)
class TempDirTest : public ::testing::Test {
 protected:
  /// dir_ / name (nothing is created).
  std::filesystem::path temp(const std::string& name) const { return dir_ / name; }

  const TempDir dir_{::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name()};
};

/// What a command left: its exit code (-1 when it did not exit normally, 124 when timeout(1) stopped it)
/// and the text it wrote to stdout and to stderr.
struct ToolResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

/// Runs `command_line` (sh syntax, arguments already quoted where needed) as
///   [cd cwd &&] timeout <timeout_s> <command_line> >OUT 2>ERR
/// and returns its exit code and both streams. Variables for the command go in its line through env(1)
/// ("env PATH=/x tool ..."); stdin is the test's unless the line redirects it. A run stopped at the
/// deadline (exit 124) also fails the test here, naming the command, so a hang is never mistaken for
/// a refusal the test expects.
inline ToolResult runTool(const std::string& command_line, int timeout_s, const std::string& cwd = "") {
  ToolResult r;
  const TempDir dir("tool_run");
  if (dir.path().empty()) return r;
  const std::filesystem::path out = dir / "stdout", err = dir / "stderr";
  const std::string cmd = (cwd.empty() ? "" : "cd '" + cwd + "' && ") + "timeout " + std::to_string(timeout_s) + " " +
                          command_line + " >" + out.string() + " 2>" + err.string();
  const int raw = std::system(cmd.c_str());
  r.exit_code = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  if (r.exit_code == 124)
    ADD_FAILURE() << "timed out after " << timeout_s << " s: " << command_line << "\nstderr:\n" << r.err;
  return r;
}

/// Runs python3 on `script` (written to dir/check.py) with `args` after it (sh syntax: "a.json", or
/// "<in.json" for stdin), under timeout(1) like runTool. exit_code is python's; out holds its stdout
/// followed by its stderr.
inline ToolResult runPython(const TempDir& dir, const std::string& script, const std::string& args,
                            int timeout_s = 60) {
  const std::filesystem::path py = dir / "check.py";
  std::ofstream(py) << script << "\n";
  ToolResult r = runTool("python3 " + py.string() + " " + args, timeout_s);
  r.out += r.err;
  return r;
}

}  // namespace mannequin::testutil
