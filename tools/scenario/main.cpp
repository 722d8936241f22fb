/// \file main.cpp
/// \brief mannequin-scenario: checks a scenario file (configs/scenarios/*.yaml) and draws its state machine.
///
///   mannequin-scenario --graph FILE.yaml --out F.svg   DOT → `dot -Tsvg` (Debian package graphviz)
///   mannequin-scenario --graph FILE.yaml --dot [--out F.dot]   the DOT text only (stdout without --out)
///   mannequin-scenario --check FILE.yaml               load, validate, print the warnings
///
/// Exit codes: 0 done, 1 bad scenario file / `dot` missing or failing / unwritable output, 2 bad command line.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <spdlog/spdlog.h>

#include "mannequin/core/main.hpp"
#include "mannequin/scenario/graph.hpp"
#include "mannequin/scenario/scenario.hpp"

extern char** environ;

namespace fs = std::filesystem;
using namespace mannequin;

namespace {

// `dot` on the PATH, or empty
std::string findDot() {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  std::string p = path;
  std::size_t start = 0;
  while (start <= p.size()) {
    const std::size_t end = p.find(':', start);
    const std::string dir = p.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (!dir.empty()) {
      const std::string cand = dir + "/dot";
      if (::access(cand.c_str(), X_OK) == 0) return cand;
    }
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return {};
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  out.close();
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
}

// dot -Tsvg -o OUT IN
void runDot(const std::string& dot, const std::string& in, const std::string& out) {
  std::vector<std::string> args = {dot, "-Tsvg", "-o", out, in};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = ::posix_spawn(&pid, dot.c_str(), nullptr, nullptr, argv.data(), environ);
  if (rc != 0) throw std::runtime_error("cannot run '" + dot + "': " + std::strerror(rc));
  int status = 0;
  if (::waitpid(pid, &status, 0) != pid) throw std::runtime_error("waiting for '" + dot + "' failed");
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("'" + dot + " -Tsvg' failed (status " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mannequin-scenario: check a scenario (configs/scenarios/*.yaml, docs/scenario.md) and draw its\n"
               "state machine with Graphviz, so a user can see a scenario before running it."};
  std::string graph, check, out;
  bool dot_only = false;
  auto* g = app.add_option("--graph", graph, "scenario file to draw")->check(CLI::ExistingFile);
  auto* c = app.add_option("--check", check, "scenario file to load and validate (warnings printed)")->check(CLI::ExistingFile);
  app.add_option("--out", out, "output file: SVG (or DOT text with --dot)");
  app.add_flag("--dot", dot_only, "write the DOT text instead of running `dot -Tsvg` (stdout without --out)");
  g->excludes(c);
  return core::runMain(app, argc, argv, [&]() -> int {
    if (graph.empty() && check.empty()) throw CLI::ValidationError("give --graph FILE.yaml or --check FILE.yaml");
    if (!check.empty()) {
      const scenario::Scenario s = scenario::loadScenario(check);
      for (const auto& w : s.warnings) std::cerr << w.where << ": warning: " << w.message << "\n";
      std::cout << "scenario " << s.name << ": " << s.states.size() << " states, " << s.frames.size()
                << " control frames, " << s.warnings.size() << " warnings\n";
      return core::kExitOk;
    }
    if (!dot_only && out.empty()) throw CLI::ValidationError("--graph needs --out F.svg (or --dot for the DOT text)");
    const scenario::Scenario s = scenario::loadScenario(graph);
    for (const auto& w : s.warnings) spdlog::warn("{}: {}", w.where, w.message);
    const std::string text = scenario::toDot(s);
    if (dot_only) {
      if (out.empty()) {
        std::cout << text;
      } else {
        writeFile(out, text);
      }
      return core::kExitOk;
    }
    const std::string dot = findDot();
    if (dot.empty())
      throw std::runtime_error("Graphviz 'dot' is not on the PATH (Debian: apt-get install graphviz, or tools/setup); "
                               "use --dot to write the DOT text only");
    const std::string tmp = out + ".dot.tmp";
    writeFile(tmp, text);
    try {
      runDot(dot, tmp, out);
    } catch (...) {
      fs::remove(tmp);
      throw;
    }
    fs::remove(tmp);
    spdlog::info("{} states → {}", s.states.size(), out);
    return core::kExitOk;
  });
}
