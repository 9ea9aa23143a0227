// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Minimal PNG files for the terrain's material-map tests, written byte by byte (independent of the reader under
// test): zlib "stored" deflate blocks (no compression), CRC-32 and Adler-32 by their definitions (PNG spec,
// RFC 1950/1951). Lets a test make any colour type and bit depth, and cut a file short.
#pragma once

#include <array>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace scree::test {

inline uint32_t pngCrc(const uint8_t* data, size_t n, uint32_t crc = 0xffffffffu) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  for (size_t i = 0; i < n; ++i) crc = table[(crc ^ data[i]) & 0xff] ^ (crc >> 8);
  return crc;
}

inline void putBE32(std::vector<uint8_t>& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(uint8_t(v >> s));
}

inline void pngChunk(std::vector<uint8_t>& out, const char* type, const std::vector<uint8_t>& data) {
  putBE32(out, uint32_t(data.size()));
  const size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  putBE32(out, pngCrc(out.data() + start, out.size() - start) ^ 0xffffffffu);
}

/// PNG bytes for `rows` (each row's raw sample bytes, without the filter byte). colorType: 0 grey, 2 RGB,
/// 3 palette (a grey palette of 256 entries is written), 6 RGBA.
inline std::vector<uint8_t> makePng(uint32_t width, uint32_t height, int bitDepth, int colorType,
                                    const std::vector<std::vector<uint8_t>>& rows) {
  std::vector<uint8_t> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<uint8_t> ihdr;
  putBE32(ihdr, width);
  putBE32(ihdr, height);
  ihdr.insert(ihdr.end(), {uint8_t(bitDepth), uint8_t(colorType), 0, 0, 0});
  pngChunk(out, "IHDR", ihdr);
  if (colorType == 3) {
    std::vector<uint8_t> plte;
    for (int i = 0; i < 256; ++i) plte.insert(plte.end(), {uint8_t(i), uint8_t(i), uint8_t(i)});
    pngChunk(out, "PLTE", plte);
  }
  // Filtered scanlines (filter type 0), then a zlib stream of stored blocks.
  std::vector<uint8_t> raw;
  for (const auto& r : rows) {
    raw.push_back(0);
    raw.insert(raw.end(), r.begin(), r.end());
  }
  std::vector<uint8_t> z = {0x78, 0x01};
  size_t pos = 0;
  do {
    const size_t n = std::min<size_t>(65535, raw.size() - pos);
    const bool last = pos + n == raw.size();
    z.push_back(last ? 1 : 0);
    z.insert(z.end(), {uint8_t(n), uint8_t(n >> 8), uint8_t(~n), uint8_t(~n >> 8)});
    z.insert(z.end(), raw.begin() + std::ptrdiff_t(pos), raw.begin() + std::ptrdiff_t(pos + n));
    pos += n;
  } while (pos < raw.size());
  uint32_t a = 1, b = 0;
  for (uint8_t c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  putBE32(z, (b << 16) | a);
  pngChunk(out, "IDAT", z);
  pngChunk(out, "IEND", {});
  return out;
}

/// An 8-bit grey PNG whose pixel (row, col) is index[row][col]; row 0 is the top row of the image.
inline std::vector<uint8_t> makeIndexPng(const std::vector<std::vector<uint8_t>>& index) {
  return makePng(uint32_t(index[0].size()), uint32_t(index.size()), 8, 0, index);
}

inline void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
}

}  // namespace scree::test
