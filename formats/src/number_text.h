// Number formatting for the text writers. std::to_chars without a precision gives the
// shortest decimal string that parses back to the same double, i.e. an exact round trip
// with fewer characters than a fixed "%.17g".
#pragma once

#include <charconv>
#include <cstdint>
#include <string>

namespace spherekit::formats::detail {

/// Appends `v`; `precision` >= 17 means "exact" (shortest round-trip form).
inline void append_double(std::string& out, double v, int precision = 17) {
  char buf[64];
  std::to_chars_result r = precision >= 17 ? std::to_chars(buf, buf + sizeof buf, v)
                                           : std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general,
                                                           precision < 1 ? 1 : precision);
  out.append(buf, r.ptr);
}

inline void append_int(std::string& out, std::int64_t v) {
  char buf[24];
  std::to_chars_result r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

}  // namespace spherekit::formats::detail
