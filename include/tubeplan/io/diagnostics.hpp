#pragma once
// Diagnostics for files: every problem found is collected, then all are reported at once as
// "file:line:col: error: what, and what was expected" (lines and columns start at 1).

#include <string>
#include <vector>

namespace tubeplan::io {

enum class Severity { kError, kWarning };

struct Diagnostic {
  std::string file;
  int line = 0;    ///< 1-based; 0 when the problem is the whole file (e.g. it cannot be read)
  int column = 0;  ///< 1-based; 0 with line 0
  Severity severity = Severity::kError;
  std::string message;
  bool after_all = false;  ///< shown after the file's other diagnostics ("... and 12 more errors")
};

/// "file:line:col: error: message" ("file: error: message" when line is 0).
std::string Format(const Diagnostic& diagnostic);

class Diagnostics {
 public:
  void Error(std::string file, int line, int column, std::string message);
  void Warning(std::string file, int line, int column, std::string message);
  /// An error about the file's other diagnostics, shown after them (a count of those left out).
  void ErrorAfterAll(std::string file, std::string message);
  bool HasErrors() const;
  const std::vector<Diagnostic>& all() const { return all_; }
  /// Every diagnostic, one per line, in file order then position order.
  std::string FormatAll() const;
  void Append(const Diagnostics& other);

 private:
  std::vector<Diagnostic> all_;
};

}  // namespace tubeplan::io
