// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// PNG material maps: an image whose pixel values are material indices (the AGX manual's
// `TerrainDataInterface::setMaterialMapping(filePath)`). Internal to scree_model; the terrain maps image pixels
// to height-field vertices, this file only decodes and encodes the index grid.
//
// Decoding goes through libpng (a kept, ubiquitous decoder; private dependency of scree_model). Only formats in
// which a pixel unambiguously names one index 0..255 are accepted:
//   - 8-bit grayscale: the gray value is the index;
//   - palette images of 1, 2, 4 or 8 bits: the palette index is the index (the palette colours and any tRNS
//     transparency are ignored; a painting program's "indexed colour" mode writes these, and PNG optimisers
//     shrink a few-colour palette to 1, 2 or 4 bits without changing the indices);
//   - 8-bit gray stored as gray+alpha, RGB or RGBA: every colour channel must be equal (the index) and alpha,
//     if present, 255 (opaque), else the read fails naming the first offending pixel (row-major scan).
// Refused with a message saying what is supported: 16-bit samples (any colour type) and 1, 2 or 4-bit
// grayscale (their values are fractions of white, 1-bit "1" means 255, so the index would be a guess).
// Interlaced (Adam7) files are read like non-interlaced ones (libpng assembles the passes). The stored sample
// values are the indices: gamma, colour-profile, significant-bits and tRNS (transparent colour) chunks are
// ignored in every format.
//
// Errors: every failure throws std::invalid_argument whose message starts with the function name and
// `path = "<path>"` and then says what is wrong: the file does not exist / is a directory / cannot be opened;
// it is not a PNG (no PNG signature); it is truncated (ends inside the PNG data); it is corrupt (CRC or zlib
// error, libpng's own text quoted); its colour type or bit depth is unsupported; it is too large.
// libpng reports errors with longjmp, so the decoder runs in small C-style stages that hold no C++ objects
// across setjmp (see png_index_map.cpp); no exception ever crosses libpng's C frames.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace scree::detail {

/// A decoded material map. `index[row * width + col]`, row-major as stored in the file: row 0 is the top row
/// of the image as a viewer shows it, col 0 its left column. index.size() == width * height.
struct PngIndexMap {
  size_t width = 0, height = 0;
  std::vector<uint8_t> index;
};

/// Largest image readPngIndexMap accepts, in pixels (2^28: a 16384 x 16384 map). The decoder holds up to four
/// bytes per pixel while it checks RGBA files; the limit turns an absurd header into an error message instead of
/// a failed allocation.
inline constexpr size_t kMaxPngIndexMapPixels = size_t(1) << 28;

/// Reads the PNG at `path` (formats above). Throws std::invalid_argument naming `path` on every failure.
PngIndexMap readPngIndexMap(const std::string& path);

/// Writes `index` (width * height values, row-major, row 0 = top row) to `path` as an 8-bit grayscale PNG,
/// replacing the file if it exists. Used by tests and examples to make material maps.
/// Throws std::invalid_argument if width or height is 0 or above 1,000,000 (libpng's default limit, which the
/// reader applies too), if index.size() != width * height, or if the file cannot be written (naming `path`;
/// a partly written file is removed).
void writePngIndexMap(const std::string& path, size_t width, size_t height, const std::vector<uint8_t>& index);

}  // namespace scree::detail
