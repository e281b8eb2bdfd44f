// The tubeplan command: everything is in the cli library so tests can drive it with strings.
#include <iostream>
#include <string>
#include <vector>

#include <tubeplan/io/interrupt.hpp>

#include "app.hpp"

int main(int argc, char** argv) {
  // SIGINT and SIGTERM remove the temporaries of unfinished outputs and exit 130.
  tubeplan::io::HandleInterrupts();
  std::vector<std::string> args(argv + 1, argv + argc);
  return tubeplan::cli::Run(args, std::cout, std::cerr);
}
