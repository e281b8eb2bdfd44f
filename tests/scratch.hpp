#pragma once
// Scratch files for tests that read files through the command line's loaders: a directory of its
// own for each test process (ctest runs test cases in parallel processes).
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace tubeplan::testing {

inline std::filesystem::path ScratchDir(const std::string& tag) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("tubeplan-" + tag + "-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

/// Writes `bytes` to `name` in the scratch directory `tag` and returns its path.
inline std::string WriteScratch(const std::string& tag, const std::string& name,
                                const std::string& bytes) {
  const std::filesystem::path path = ScratchDir(tag) / name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path.string();
}

}  // namespace tubeplan::testing
