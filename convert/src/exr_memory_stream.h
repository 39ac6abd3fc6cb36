// An Imf::OStream that collects an EXR file in memory, so that writers can hand the finished
// bytes to formats::write_file_atomic (no partial EXR is ever visible on disk).
#pragma once

#include <ImfIO.h>

#include <cstdint>
#include <cstring>
#include <string>

namespace spherekit::convert::detail {

class MemoryStream final : public Imf::OStream {
 public:
  MemoryStream() : Imf::OStream("<memory>") {}
  void write(const char c[], int n) override {
    const std::size_t end = pos_ + static_cast<std::size_t>(n);
    if (end > bytes_.size()) bytes_.resize(end);
    std::memcpy(bytes_.data() + pos_, c, static_cast<std::size_t>(n));
    pos_ = end;
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = static_cast<std::size_t>(pos); }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
  std::size_t pos_ = 0;
};

}  // namespace spherekit::convert::detail
