// Decoding fuzz bytes into numbers: a small stand-in for libFuzzer's FuzzedDataProvider that also
// builds with GCC (the regression replay test uses the normal compiler).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace rbx::fuzz {

/// Reads the input front to back; past the end every read gives 0, so any input decodes.
class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  /// The next byte, 0..255.
  int u8() { return pos_ < size_ ? data_[pos_++] : 0; }
  /// The next byte as a signed value, -128..127.
  int i8() { return static_cast<int8_t>(static_cast<uint8_t>(u8())); }
  /// The next 8 bytes as a raw double (any bit pattern: NaN, infinities, denormals).
  double raw_double() {
    uint8_t bytes[8] = {};
    for (uint8_t& b : bytes) b = static_cast<uint8_t>(u8());
    double v;
    std::memcpy(&v, bytes, sizeof v);
    return v;
  }
  /// A coordinate (m): one signed byte on a 1/8 m grid, so coplanar and coincident points are
  /// common; the escape byte -128 is followed by a raw double instead.
  double coordinate() {
    const int b = i8();
    return b == -128 ? raw_double() : b / 8.0;
  }
  /// Bytes not read yet.
  size_t remaining() const { return size_ - pos_; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

}  // namespace rbx::fuzz
