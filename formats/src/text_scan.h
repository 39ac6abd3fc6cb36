// Allocation-free scanning for the text formats (OBJ, OFF, ascii PLY and STL, feature files):
// lines, whitespace-separated tokens and whole-token numbers via std::from_chars, which is
// locale-independent and several times faster than iostream extraction.
#pragma once

#include <charconv>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>

namespace spherekit::formats::detail {

/// Horizontal whitespace. '\n' is not included: line structure matters in most formats.
inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// Iterates over the lines of a buffer (split at '\n', a trailing '\r' removed).
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  /// The next line, or false at the end of the buffer. number() is then its 1-based number.
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    line = text_.substr(pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end + 1;
    ++number_;
    return true;
  }
  std::uint64_t number() const { return number_; }
  std::size_t remaining_bytes() const { return pos_ >= text_.size() ? 0 : text_.size() - pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::uint64_t number_ = 0;
};

/// Pops the next whitespace-separated token off the front of `rest`; false if none is left.
inline bool next_token(std::string_view& rest, std::string_view& token) {
  std::size_t i = 0;
  while (i < rest.size() && (is_blank(rest[i]) || rest[i] == '\n')) ++i;
  if (i == rest.size()) {
    rest = {};
    return false;
  }
  std::size_t j = i;
  while (j < rest.size() && !is_blank(rest[j]) && rest[j] != '\n') ++j;
  token = rest.substr(i, j - i);
  rest.remove_prefix(j);
  return true;
}

/// The line without a '#' comment and without surrounding whitespace.
inline std::string_view strip_comment(std::string_view line) {
  std::size_t hash = line.find('#');
  if (hash != std::string_view::npos) line = line.substr(0, hash);
  while (!line.empty() && is_blank(line.front())) line.remove_prefix(1);
  while (!line.empty() && is_blank(line.back())) line.remove_suffix(1);
  return line;
}

/// Case-insensitive ASCII comparison (STL keywords are written in either case in the wild).
inline bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    char x = a[i], y = b[i];
    if (x >= 'A' && x <= 'Z') x = static_cast<char>(x - 'A' + 'a');
    if (y >= 'A' && y <= 'Z') y = static_cast<char>(y - 'A' + 'a');
    if (x != y) return false;
  }
  return true;
}

/// from_chars reports out_of_range without a value. Decide from the decimal magnitude whether
/// the literal overflowed (-> +-inf, later rejected as non-finite) or underflowed (-> +-0,
/// a legitimate tiny coordinate). Only called for syntactically valid literals.
inline double out_of_range_value(std::string_view t) {
  bool negative = !t.empty() && t.front() == '-';
  if (!t.empty() && (t.front() == '-' || t.front() == '+')) t.remove_prefix(1);
  // magnitude ~ 10^(position of the first non-zero digit relative to the point + exponent)
  std::int64_t magnitude = 0;
  bool seen_point = false, seen_digit = false;
  std::size_t i = 0;
  for (; i < t.size() && t[i] != 'e' && t[i] != 'E'; ++i) {
    if (t[i] == '.') {
      seen_point = true;
    } else if (!seen_digit && t[i] == '0') {
      if (seen_point) --magnitude;
    } else {
      seen_digit = true;
      if (!seen_point) ++magnitude;
    }
  }
  std::int64_t exponent = 0;
  if (i < t.size()) {
    std::string_view e = t.substr(i + 1);
    bool eneg = !e.empty() && e.front() == '-';
    if (!e.empty() && (e.front() == '-' || e.front() == '+')) e.remove_prefix(1);
    for (char c : e) {
      exponent = exponent * 10 + (c - '0');
      if (exponent > 100000) break;  // far beyond any double's range; avoid overflow
    }
    if (eneg) exponent = -exponent;
  }
  double mag = (magnitude + exponent > 0) ? std::numeric_limits<double>::infinity() : 0.0;
  return negative ? -mag : mag;
}

/// Parses a whole token as a double (decimal, "nan", "inf"; a leading '+' is allowed).
/// Overflow gives +-inf, underflow +-0. False if the token is not exactly one number.
inline bool parse_double(std::string_view token, double& out) {
  std::string_view t = token;
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  if (t.empty()) return false;  // from_chars itself rejects "++1", "-+1", hex and spaces
  const char* end = t.data() + t.size();
  auto [ptr, ec] = std::from_chars(t.data(), end, out);
  if (ptr != end) return false;
  if (ec == std::errc::result_out_of_range) {
    out = out_of_range_value(token);
    return true;
  }
  return ec == std::errc();
}

/// Parses a whole token as a decimal integer (leading '+' allowed). Values beyond 64 bits are
/// clamped, so range checks downstream report them. False if the token is not an integer.
inline bool parse_int(std::string_view token, std::int64_t& out) {
  std::string_view t = token;
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  if (t.empty()) return false;
  const char* end = t.data() + t.size();
  auto [ptr, ec] = std::from_chars(t.data(), end, out);
  if (ptr != end) return false;
  if (ec == std::errc::result_out_of_range) {
    out = t.front() == '-' ? std::numeric_limits<std::int64_t>::min() : std::numeric_limits<std::int64_t>::max();
    return true;
  }
  return ec == std::errc();
}

/// A token from a file made safe for a one-line message: quoted, at most 40 characters,
/// control and non-ASCII bytes shown as '?' (garbage input must not break the message).
inline std::string quote_token(std::string_view token) {
  constexpr std::size_t kMax = 40;
  std::string s = "'";
  for (std::size_t i = 0; i < token.size() && i < kMax; ++i) {
    unsigned char c = static_cast<unsigned char>(token[i]);
    s += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  if (token.size() > kMax) s += "...";
  s += "'";
  return s;
}

/// A whitespace-separated token stream over a whole buffer that counts lines for messages
/// (ascii PLY bodies and ascii STL, where line breaks carry no meaning).
class TokenReader {
 public:
  explicit TokenReader(std::string_view text) : text_(text) {}

  bool next(std::string_view& token) {
    while (pos_ < text_.size() && (is_blank(text_[pos_]) || text_[pos_] == '\n')) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= text_.size()) return false;
    std::size_t start = pos_;
    while (pos_ < text_.size() && !is_blank(text_[pos_]) && text_[pos_] != '\n') ++pos_;
    token = text_.substr(start, pos_ - start);
    return true;
  }
  /// Skips to the start of the next line (for STL names, which may contain spaces).
  void skip_line() {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  }
  /// True if only blanks are left before the next line break (or the end of the text): the
  /// last token returned ended its line.
  bool rest_of_line_blank() const {
    for (std::size_t i = pos_; i < text_.size() && text_[i] != '\n'; ++i) {
      if (!is_blank(text_[i])) return false;
    }
    return true;
  }
  /// 1-based line of the last token returned.
  std::uint64_t line() const { return line_; }
  std::size_t remaining_bytes() const { return pos_ >= text_.size() ? 0 : text_.size() - pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::uint64_t line_ = 1;
};

}  // namespace spherekit::formats::detail
