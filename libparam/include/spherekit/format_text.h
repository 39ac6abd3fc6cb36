// printf-style formatting into a std::string (g++ 12 has no <format>), for messages and
// reports: the one helper the libraries and the command line share.
#pragma once

#include <cstdarg>
#include <cstdio>
#include <string>

namespace spherekit {

inline std::string format_text(const char* format, ...) __attribute__((format(printf, 1, 2)));
inline std::string format_text(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string out(n > 0 ? static_cast<size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, format, args);
  va_end(args);
  return out;
}

}  // namespace spherekit
