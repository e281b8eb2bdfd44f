// Whole-file reading and atomic writing.
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include <catch2/catch.hpp>

#include <tubeplan/io/text_file.hpp>

namespace {
std::filesystem::path ScratchDir() {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("tubeplan-text-file-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}
}  // namespace

TEST_CASE("Atomic writes replace the file whole and leave no temporary behind", "[files]") {
  const auto dir = ScratchDir();
  const auto path = dir / "out.txt";
  REQUIRE(tubeplan::io::WriteTextFileAtomically(path, "first\n").empty());
  REQUIRE(tubeplan::io::WriteTextFileAtomically(path, "second, longer\n").empty());
  CHECK(tubeplan::io::ReadTextFile(path) == std::optional<std::string>("second, longer\n"));
  // Only the target exists: the temporary was renamed, not copied.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++files;
  CHECK(files == 1);
  // A write into a directory that does not exist fails with a message and changes nothing.
  const std::string error = tubeplan::io::WriteTextFileAtomically(dir / "no" / "x.txt", "z");
  CHECK_THAT(error, Catch::StartsWith("cannot create"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("Reading: empty files are empty text, directories and missing files are nothing",
          "[files]") {
  const auto dir = ScratchDir();
  std::ofstream(dir / "empty.txt").close();
  CHECK(tubeplan::io::ReadTextFile(dir / "empty.txt") == std::optional<std::string>(""));
  CHECK_FALSE(tubeplan::io::ReadTextFile(dir).has_value());
  CHECK_FALSE(tubeplan::io::ReadTextFile(dir / "missing.txt").has_value());
  std::filesystem::remove_all(dir);
}
