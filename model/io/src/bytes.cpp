// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/io/bytes.h"

#include <bit>

#include <zlib.h>

namespace scree::io {

static_assert(std::endian::native == std::endian::little,
              "the Scree file formats are little-endian and the writers copy native bytes");

uint32_t crc32(const void* data, size_t size) {
  uLong crc = ::crc32(0L, Z_NULL, 0);
  const auto* p = static_cast<const Bytef*>(data);
  while (size > 0) {  // zlib's length is a uInt: feed it in pieces below 4 GiB
    const uInt n = size > (1u << 30) ? (1u << 30) : static_cast<uInt>(size);
    crc = ::crc32(crc, p, n);
    p += n;
    size -= n;
  }
  return static_cast<uint32_t>(crc);
}

void ByteReader::fail(const std::string& message) const {
  throw FormatError(what_ + ": " + message + " at byte " + std::to_string(base_ + pos_));
}

void ByteReader::failShort(size_t n, const char* field) const {
  throw FormatError(what_ + ": truncated reading " + field + " (needs " + std::to_string(n) + " bytes, " +
                    std::to_string(size_ - pos_) + " left) at byte " + std::to_string(base_ + pos_));
}

}  // namespace scree::io
