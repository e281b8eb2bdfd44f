// Whole-file reading and atomic writing.
#include "io/text_file.hpp"

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include <catch2/catch.hpp>

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
  std::filesystem::remove_all(dir);
}

TEST_CASE("An output's missing directories are made; one that cannot be made is said", "[files]") {
  const auto dir = ScratchDir();
  // A fresh checkout has no build/: the directory and its parents are made as mkdir -p does.
  REQUIRE(tubeplan::io::WriteTextFileAtomically(dir / "no" / "deeper" / "x.txt", "z").empty());
  CHECK(tubeplan::io::ReadTextFile(dir / "no" / "deeper" / "x.txt") ==
        std::optional<std::string>("z"));
  // A parent that is a file: the message names the temporary it could not create and, since
  // nothing was asked to be written yet, speaks of no room ("room for 0 bytes").
  std::ofstream(dir / "plain") << "a file\n";
  const std::string error = tubeplan::io::WriteTextFileAtomically(dir / "plain" / "x.txt", "");
  CHECK_THAT(error,
             Catch::StartsWith("cannot create " + (dir / "plain" / "x.txt").string() + ".tmp."));
  CHECK_THAT(error, Catch::EndsWith(": Not a directory; nothing was written (" +
                                    (dir / "plain" / "x.txt").string() +
                                    " is as it was), expected a writable directory"));
  tubeplan::io::AtomicFile never(dir / "plain" / "y.txt");
  CHECK_THAT(never.Commit(), Catch::EndsWith("expected a writable directory"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("An output that is an input's file is refused, through links too", "[files]") {
  using tubeplan::io::CheckOutputsApart;
  namespace fs = std::filesystem;
  const auto dir = ScratchDir();
  const fs::path input = dir / "t.csv";
  std::ofstream(input) << "t,px,py,pz,qw,qx,qy,qz\n";
  const std::vector<tubeplan::io::RolePath> inputs = {{"the scene", dir / "s.yaml"},
                                                      {"the trajectory", input}};
  // The same spelling.
  CHECK(CheckOutputsApart({{"--out", input}}, inputs) ==
        "--out " + input.string() + " is the same file as the trajectory " + input.string() +
            ": writing it would replace the input, expected another file for the output");
  // A symbolic link, a hard link and another spelling of the path: the same file.
  fs::create_symlink(input, dir / "link.csv");
  fs::create_hard_link(input, dir / "hard.csv");
  for (const fs::path& other :
       {dir / "link.csv", dir / "hard.csv", dir / "sub" / ".." / "t.csv", dir / "." / "t.csv"}) {
    fs::create_directories(dir / "sub");
    CAPTURE(other.string());
    CHECK(CheckOutputsApart({{"--out", other}}, inputs) ==
          "--out " + other.string() + " is the same file as the trajectory " + input.string() +
              " (through a link or another spelling of its path): writing it would replace the "
              "input, expected another file for the output");
  }
  // An input that does not exist yet, named twice: the canonical paths decide.
  CHECK_THAT(CheckOutputsApart({{"--report", dir / "sub" / ".." / "s.yaml"}}, inputs),
             Catch::StartsWith("--report " + (dir / "sub" / ".." / "s.yaml").string() +
                               " is the same file as the scene "));
  // Two outputs to one file: one would replace the other.
  CHECK(CheckOutputsApart({{"--dot", dir / "g"}, {"--json", dir / "g"}}, inputs) ==
        "--json " + (dir / "g").string() + " is the same file as --dot " + (dir / "g").string() +
            ": one would replace the other, expected a file of its own for each output");
  // Files apart, and options not given (empty paths), pass.
  CHECK(CheckOutputsApart({{"--out", dir / "series.csv"}, {"--json", ""}}, inputs).empty());
  // A copy is another file, whatever it holds.
  fs::copy_file(input, dir / "copy.csv");
  CHECK(CheckOutputsApart({{"--out", dir / "copy.csv"}}, inputs).empty());
  fs::remove_all(dir);
}

TEST_CASE("A file whose lines end in a carriage return alone is one clear error", "[files]") {
  tubeplan::io::Diagnostics d;
  // Classic Mac OS line ends: the whole file would be one line (and a YAML comment).
  CHECK_FALSE(tubeplan::io::CheckInputText("# comment\rtubeplan: 1\rname: x\r", "s.yaml",
                                           "a YAML scene file", d));
  CHECK(d.FormatAll() ==
        "s.yaml:1:10: error: a carriage return (CR) with no line feed after it: the lines end in "
        "CR alone (as classic Mac OS saved text), expected LF or CRLF line endings in a YAML "
        "scene file\n");
  // CRLF, and a CR as the last byte, are fine; a CR cut from its LF by a chunk's end too.
  tubeplan::io::Diagnostics fine;
  CHECK(tubeplan::io::CheckInputText("a: 1\r\nb: 2\r\n", "s.yaml", "a YAML scene file", fine));
  CHECK(tubeplan::io::CheckInputText("a: 1\r\nb: 2\r", "s.yaml", "a YAML scene file", fine));
  tubeplan::io::InputTextCheck pieces;
  pieces.Feed("a: 1\r");
  pieces.Feed("\nb: 2\n");
  CHECK(pieces.Finish("s.yaml", "a YAML scene file", fine));
  CHECK(fine.FormatAll() == "");
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

TEST_CASE("An atomic file abandoned before its commit leaves nothing behind", "[files]") {
  const auto dir = ScratchDir();
  const auto path = dir / "series.csv";
  {
    tubeplan::io::AtomicFile file(path);
    REQUIRE(file.error().empty());
    CHECK(file.Write("a,b\n"));
    CHECK(file.Write("1,2\n"));
    // Destroyed without Commit: an error or an interruption in the middle of a series.
  }
  CHECK(std::filesystem::is_empty(dir));
  {
    tubeplan::io::AtomicFile file(path);
    CHECK(file.Write("a,b\n"));
    CHECK(file.Write("1,2\n"));
    CHECK(file.Commit().empty());
  }
  CHECK(tubeplan::io::ReadTextFile(path) == std::optional<std::string>("a,b\n1,2\n"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("Reading refuses devices and files over the limit without reading them", "[files]") {
  const auto dir = ScratchDir();
  // /dev/zero never ends: read, it would fill the memory.
  const tubeplan::io::ReadResult zero = tubeplan::io::ReadInputFile("/dev/zero");
  CHECK_FALSE(zero.text);
  CHECK(zero.error == "it is not a regular file (a device, FIFO or socket)");
  const auto big = dir / "big.txt";
  std::ofstream(big) << std::string(3u << 20, 'x');
  const tubeplan::io::ReadResult refused = tubeplan::io::ReadInputFile(big, 1u << 20);
  CHECK_FALSE(refused.text);
  CHECK(refused.error == "it is 3 MiB, more than the 1 MiB allowed");
  CHECK(tubeplan::io::ReadInputFile(big, 3u << 20).text->size() == 3u << 20);
  CHECK(tubeplan::io::ReadInputFile(dir).error == "it is a directory");
  std::filesystem::remove_all(dir);
}

TEST_CASE("Abbreviate cuts long words for messages, never inside a UTF-8 character", "[files]") {
  using tubeplan::io::Abbreviate;
  CHECK(Abbreviate("short") == "short");
  CHECK(Abbreviate(std::string(50, 'x')) == std::string(40, 'x') + "...");
  // 39 ASCII bytes then a two-byte micro sign: the cut at 40 would split it; it backs up to 39.
  CHECK(Abbreviate(std::string(39, 'x') + "\u00B5m and more") == std::string(39, 'x') + "...");
}
