#pragma once
// Private to the studies: printf into a string, for the accuracy and stability reports' lines.
#include <cstdarg>
#include <cstdio>
#include <string>

namespace tubeplan::study {

// The attribute lets the compiler check every call's arguments against its format.
__attribute__((format(printf, 1, 2))) inline std::string Fmt(const char* format, ...) {
  char buf[200];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buf, sizeof buf, format, args);
  va_end(args);
  return buf;
}

}  // namespace tubeplan::study
