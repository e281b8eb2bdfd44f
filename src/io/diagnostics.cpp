#include <algorithm>
#include <tuple>
#include <utility>

#include <tubeplan/io/diagnostics.hpp>

namespace tubeplan::io {

std::string Format(const Diagnostic& diagnostic) {
  const char* severity = diagnostic.severity == Severity::kError ? "error" : "warning";
  std::string text = diagnostic.file;
  if (diagnostic.line > 0) {
    text += ':' + std::to_string(diagnostic.line) + ':' + std::to_string(diagnostic.column);
  }
  text += ": ";
  text += severity;
  text += ": ";
  text += diagnostic.message;
  return text;
}

void Diagnostics::Error(std::string file, int line, int column, std::string message) {
  all_.push_back({std::move(file), line, column, Severity::kError, std::move(message)});
}

void Diagnostics::Warning(std::string file, int line, int column, std::string message) {
  all_.push_back({std::move(file), line, column, Severity::kWarning, std::move(message)});
}

void Diagnostics::ErrorAfterAll(std::string file, std::string message) {
  all_.push_back({std::move(file), 0, 0, Severity::kError, std::move(message), true});
}

bool Diagnostics::HasErrors() const {
  return std::any_of(all_.begin(), all_.end(),
                     [](const Diagnostic& d) { return d.severity == Severity::kError; });
}

std::string Diagnostics::FormatAll() const {
  // Stable sort: problems found in one place keep the order the checker found them in.
  std::vector<const Diagnostic*> sorted;
  sorted.reserve(all_.size());
  for (const Diagnostic& d : all_) sorted.push_back(&d);
  std::stable_sort(sorted.begin(), sorted.end(), [](const Diagnostic* a, const Diagnostic* b) {
    return std::tie(a->file, a->after_all, a->line, a->column) <
           std::tie(b->file, b->after_all, b->line, b->column);
  });
  std::string text;
  for (const Diagnostic* d : sorted) {
    text += Format(*d);
    text += '\n';
  }
  return text;
}

void Diagnostics::Append(const Diagnostics& other) {
  all_.insert(all_.end(), other.all_.begin(), other.all_.end());
}

}  // namespace tubeplan::io
