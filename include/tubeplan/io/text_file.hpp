#pragma once
// Whole-file text input and output for the loaders and writers.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace tubeplan::io {

/// The file's bytes, or nullopt when it cannot be read (missing, a directory, no permission).
std::optional<std::string> ReadTextFile(const std::filesystem::path& path);

/// Writes `text` to a temporary file next to `path` and renames it over `path`, so a reader never
/// sees a half-written file and a failed write leaves the old one in place. Returns an empty
/// string on success, else what went wrong (the temporary file is removed).
std::string WriteTextFileAtomically(const std::filesystem::path& path, std::string_view text);

}  // namespace tubeplan::io
