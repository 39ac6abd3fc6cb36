// Bounds-checked reads from a byte buffer with explicit endianness (binary PLY, STL, GLB).
// Every read checks the remaining size first, so truncated or hostile files fail cleanly
// instead of reading past the buffer; memcpy keeps unaligned reads defined.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace spherekit::formats::detail {

/// Decodes one little- or big-endian value of type T from `p` (at least sizeof(T) bytes).
template <class T>
T load_scalar(const char* p, bool big_endian) {
  static_assert(std::is_arithmetic_v<T>);
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, p, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) {
      unsigned char t = bytes[i];
      bytes[i] = bytes[sizeof(T) - 1 - i];
      bytes[sizeof(T) - 1 - i] = t;
    }
  }
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

/// Encodes `value` little-endian at the end of `out` (the byte order of our binary writers).
template <class T, class String>
void append_le(String& out, T value) {
  static_assert(std::is_arithmetic_v<T>);
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) {
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) {
      unsigned char t = bytes[i];
      bytes[i] = bytes[sizeof(T) - 1 - i];
      bytes[sizeof(T) - 1 - i] = t;
    }
  }
  out.append(reinterpret_cast<const char*>(bytes), sizeof(T));
}

/// A cursor over a byte range; reads fail (return false) instead of running off the end.
class ByteReader {
 public:
  ByteReader(const char* data, std::size_t size) : data_(data), size_(size) {}

  std::size_t remaining() const { return size_ - pos_; }
  std::size_t position() const { return pos_; }

  template <class T>
  bool read(T& out, bool big_endian) {
    if (remaining() < sizeof(T)) return false;
    out = load_scalar<T>(data_ + pos_, big_endian);
    pos_ += sizeof(T);
    return true;
  }
  bool skip(std::size_t n) {
    if (remaining() < n) return false;
    pos_ += n;
    return true;
  }

 private:
  const char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace spherekit::formats::detail
