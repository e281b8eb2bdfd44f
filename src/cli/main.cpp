// The tubeplan command: everything is in the cli library so tests can drive it with strings.
#include <iostream>
#include <string>
#include <vector>

#include <tubeplan/cli/app.hpp>

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  return tubeplan::cli::Run(args, std::cout, std::cerr);
}
