#pragma once
// The c3d.org sample01 capture shipped in data/c3d/ (PC, SGI and DEC formats of one walk), found from the
// source tree (MANNEQUIN_SOURCE_DIR, set by ctest; else the working directory); MANNEQUIN_C3D_DATA
// overrides the folder.
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "../common/source.hpp"

namespace c3dtest {

using mannequin::testing::sourceDir;

/// kind: "pr" (PC/Intel), "sr" (SGI/MIPS), "vr" (DEC/VAX).
inline std::string samplePath(const std::string& kind) {
  if (const char* dir = std::getenv("MANNEQUIN_C3D_DATA")) return std::string(dir) + "/sample01_Eb015" + kind + ".c3d";
  return sourceDir() + "/data/c3d/sample01_Eb015" + kind + ".c3d";
}

/// The bytes of the file at `path` ("" when it cannot be read).
inline std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace c3dtest
