/// \file main.cpp
/// \brief mannequin-keys: ZeroMQ CURVE key pairs for the cluster (docs/cluster.md, Security).
///
///   mannequin-keys generate NAME [--dir DIR]   writes DIR/NAME.key (public, 0644) and DIR/NAME.key_secret
///                                              (secret, 0600); refuses to overwrite either
///   mannequin-keys public FILE.key_secret      prints the public key of a secret key file
///
/// Exit codes: 0 success, 2 bad command line or bad input (existing file, bad name, missing or bad
/// key file), each with one line on stderr.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

#include "mannequin/transport/security.hpp"

namespace fs = std::filesystem;
namespace tr = mannequin::transport;

namespace {

constexpr int kExitOk = 0;
constexpr int kExitBad = 2;

int fail(const std::string& message) {
  std::cerr << "mannequin-keys: " << message << "\n";
  return kExitBad;
}

bool validName(const std::string& name) {
  if (name.empty() || name == "." || name == "..") return false;
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) return false;
  return true;
}

int generate(const std::string& name, const std::string& dir) {
  if (!validName(name)) return fail("name '" + name + "': use letters, digits, '-', '_' and '.' only");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return fail("--dir '" + dir + "': not a directory");
  const std::string pub = (fs::path(dir) / (name + ".key")).string();
  const std::string sec = (fs::path(dir) / (name + ".key_secret")).string();
  for (const std::string& f : {pub, sec})
    if (fs::exists(fs::symlink_status(f, ec))) return fail(f + ": already exists (refusing to overwrite)");
  if (!tr::hasCurve()) return fail("this libzmq has no CURVE support");
  const tr::CurveKeyPair keys = tr::generateCurveKeyPair();
  try {
    tr::writeKeyFile(sec, keys.secret_key, "mannequin CURVE secret key of '" + name + "' (keep private)", 0600);
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  try {
    tr::writeKeyFile(pub, keys.public_key, "mannequin CURVE public key of '" + name + "'", 0644);
  } catch (const std::exception& e) {
    fs::remove(sec, ec);  // no half pair left behind
    return fail(e.what());
  }
  std::cout << "wrote " << pub << " (public " << keys.public_key << ") and " << sec << " (secret, mode 0600)\n";
  return kExitOk;
}

int printPublic(const std::string& file) {
  if (file.size() > 4 && file.compare(file.size() - 4, 4, ".key") == 0)
    return fail(file + ": a public key file; give the .key_secret file");
  try {
    std::cout << tr::curvePublicKey(tr::readKeyFile(file, true)) << "\n";
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("mannequin-keys: ZeroMQ CURVE key pairs for the cluster's publishers and subscribers");
  app.require_subcommand(1);
  std::string name, dir = ".", file;
  CLI::App* gen = app.add_subcommand("generate", "write DIR/NAME.key (public) and DIR/NAME.key_secret (secret, mode 0600)");
  gen->add_option("NAME", name, "key pair name (letters, digits, '-', '_', '.')")->required();
  gen->add_option("--dir", dir, "directory to write into")->capture_default_str();
  CLI::App* pub = app.add_subcommand("public", "print the public key (Z85) of a secret key file");
  pub->add_option("FILE", file, "a .key_secret file")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return fail(e.what() + std::string(" (see --help)"));
  }
  if (gen->parsed()) return generate(name, dir);
  return printPublic(file);
}
