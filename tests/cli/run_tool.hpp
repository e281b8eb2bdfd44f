#pragma once
// The command line as the tests drive it: argument strings in, exit code and both streams out,
// through the same tubeplan::cli::Run the executable calls.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli/app.hpp"

namespace tubeplan::testing {

struct Outcome {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline Outcome RunTool(std::vector<std::string> args) {
  std::ostringstream out, err;
  const int code = tubeplan::cli::Run(args, out, err);
  return {code, out.str(), err.str()};
}

/// A file of the source tree (scenes, plans, test data) by its path from the top.
inline std::string SourcePath(const std::string& relative) {
  return std::string(TUBEPLAN_SOURCE_DIR) + "/" + relative;
}

/// A whole file as bytes.
inline std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace tubeplan::testing
