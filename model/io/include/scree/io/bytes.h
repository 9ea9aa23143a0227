// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Little-endian byte buffers for Scree's file writers and readers (recording, VTK). The reader checks every
// access against the end of its buffer and throws scree::io::FormatError naming what it was reading and the
// byte offset, so a truncated or corrupted file is a clear error and never a read past the end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace scree::io {

/// A file that is not what its format says (truncated, corrupted, wrong version).
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// CRC-32 (IEEE 802.3 polynomial, zlib's crc32) of `size` bytes.
uint32_t crc32(const void* data, size_t size);

/// Appends little-endian values to a byte vector.
class ByteWriter {
 public:
  std::vector<uint8_t>& bytes() { return bytes_; }
  const std::vector<uint8_t>& bytes() const { return bytes_; }
  size_t size() const { return bytes_.size(); }

  template <typename T>
  void put(T value) {
    static_assert(std::is_arithmetic_v<T>, "put() takes integers and floats");
    uint8_t raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));  // x86-64 and aarch64 are little-endian; static_assert below
    bytes_.insert(bytes_.end(), raw, raw + sizeof(T));
  }
  void putBytes(const void* data, size_t size) {
    const auto* p = static_cast<const uint8_t*>(data);
    bytes_.insert(bytes_.end(), p, p + size);
  }
  /// u32 byte length, then the bytes.
  void putString(std::string_view s) {
    put<uint32_t>(static_cast<uint32_t>(s.size()));
    putBytes(s.data(), s.size());
  }

 private:
  std::vector<uint8_t> bytes_;
};

/// Reads little-endian values from a byte range; every read is bounds-checked.
class ByteReader {
 public:
  /// `what` names the buffer in error messages (e.g. "frame 12"); `baseOffset` is the buffer's offset in its
  /// file, so errors give file offsets.
  ByteReader(const uint8_t* data, size_t size, std::string what, size_t baseOffset = 0)
      : data_(data), size_(size), what_(std::move(what)), base_(baseOffset) {}

  size_t offset() const { return pos_; }
  size_t remaining() const { return size_ - pos_; }
  bool atEnd() const { return pos_ == size_; }

  template <typename T>
  T get(const char* field) {
    static_assert(std::is_arithmetic_v<T>, "get() reads integers and floats");
    need(sizeof(T), field);
    T value;
    std::memcpy(&value, data_ + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  /// Pointer to `size` bytes, advancing past them.
  const uint8_t* getBytes(size_t size, const char* field) {
    need(size, field);
    const uint8_t* p = data_ + pos_;
    pos_ += size;
    return p;
  }
  std::string getString(const char* field) {
    const auto n = get<uint32_t>(field);
    const uint8_t* p = getBytes(n, field);
    return std::string(reinterpret_cast<const char*>(p), n);
  }
  /// Throws FormatError "<what>: <message> at byte <offset>".
  [[noreturn]] void fail(const std::string& message) const;

 private:
  void need(size_t n, const char* field) const {
    if (n > size_ - pos_) failShort(n, field);
  }
  [[noreturn]] void failShort(size_t n, const char* field) const;

  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
  std::string what_;
  size_t base_;
};

}  // namespace scree::io
