// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// PNG material maps (model/src/png_index_map.h): exact round trips in every supported format, row 0 = the top
// row of the image, and a clear std::invalid_argument naming `path` and the problem for every bad file --
// including every truncation and every flipped byte of the image data, which must throw, never crash (run under
// AddressSanitizer/UBSan in CI). Odd formats are written with libpng directly (writeRawPng), and the orientation
// is checked against libpng's own simplified reader, independent of the code under test.
#include <doctest/doctest.h>

#include <png.h>
#include <zlib.h>

#include <csetjmp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "png_index_map.h"
#include "test_badinput.h"

namespace fs = std::filesystem;
using scree::detail::PngIndexMap;
using scree::detail::readPngIndexMap;
using scree::detail::writePngIndexMap;
using scree::test::expectInvalid;

namespace {

// A fresh directory under the system temp directory, removed with everything in it at scope exit.
struct TempDir {
  fs::path dir;
  TempDir() {
    std::random_device rd;
    for (int attempt = 0; attempt < 100 && dir.empty(); ++attempt) {
      const fs::path p = fs::temp_directory_path() /
                         ("scree_png_test_" + std::to_string(rd()) + "_" + std::to_string(rd()));
      if (fs::create_directory(p)) dir = p;
    }
    REQUIRE(!dir.empty());
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
  std::string file(const std::string& name) const { return (dir / name).string(); }
};

std::vector<uint8_t> readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes, size_t count) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(count));
  REQUIRE(out.good());
}

// The prefix every reader message starts with: the function, the parameter and its value.
std::string named(const std::string& path) { return "path = \"" + path + "\""; }

// ---- PNG files written with libpng directly ------------------------------------------------------------------

// An image as PNG stores it: rows top first, each `rowBytes` long, samples packed MSB first (bit depths < 8)
// or big-endian (16).
struct RawPng {
  size_t width = 0, height = 0;
  int colorType = PNG_COLOR_TYPE_GRAY, bitDepth = 8;
  bool interlaced = false;
  std::vector<uint8_t> data;
  std::vector<png_color> palette;
};

// setjmp stage: pointers only (libpng's error handler longjmps here; nothing with a destructor lives in this
// frame).
bool writeRawStage(png_structp png, png_infop info, const RawPng* img, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_IHDR(png, info, png_uint_32(img->width), png_uint_32(img->height), img->bitDepth, img->colorType,
               img->interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (!img->palette.empty()) png_set_PLTE(png, info, img->palette.data(), int(img->palette.size()));
  png_write_info(png, info);
  png_write_image(png, rows);  // all Adam7 passes if interlaced
  png_write_end(png, nullptr);
  return true;
}

void writeRawPng(const std::string& path, const RawPng& img) {
  const size_t rowBytes = img.data.size() / img.height;
  REQUIRE(rowBytes * img.height == img.data.size());
  std::vector<png_bytep> rows(img.height);
  std::vector<uint8_t> data = img.data;
  for (size_t r = 0; r < img.height; ++r) rows[r] = data.data() + r * rowBytes;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  REQUIRE(f != nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  bool ok = png && info;
  if (ok) {
    png_init_io(png, f);
    ok = writeRawStage(png, info, &img, rows.data());
  }
  if (png) png_destroy_write_struct(&png, info ? &info : nullptr);
  ok = std::fclose(f) == 0 && ok;
  REQUIRE(ok);
}

// Samples of `bits` bits packed MSB first, one row.
std::vector<uint8_t> packRow(const std::vector<uint8_t>& values, int bits) {
  std::vector<uint8_t> out((values.size() * size_t(bits) + 7) / 8, 0);
  for (size_t i = 0; i < values.size(); ++i) {
    const size_t bit = i * size_t(bits);
    out[bit / 8] |= uint8_t(values[i] << (8 - bits - int(bit % 8)));
  }
  return out;
}

// A gray 8-bit file read with libpng's simplified API (not the code under test): rows top first.
std::vector<uint8_t> readWithSimplifiedApi(const std::string& path, size_t* outWidth, size_t* outHeight) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  REQUIRE(png_image_begin_read_from_file(&image, path.c_str()) != 0);
  image.format = PNG_FORMAT_GRAY;
  std::vector<uint8_t> pixels(PNG_IMAGE_SIZE(image));
  REQUIRE(png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr) != 0);
  *outWidth = image.width;
  *outHeight = image.height;
  return pixels;
}

// Two materials, asymmetric under every flip and transpose: 1 on the top row and the right column.
std::vector<uint8_t> twoMaterialMap(size_t width, size_t height) {
  std::vector<uint8_t> index(width * height, 0);
  for (size_t r = 0; r < height; ++r)
    for (size_t c = 0; c < width; ++c) index[r * width + c] = (r == 0 || c == width - 1) ? 1 : 0;
  return index;
}

// Byte offsets of the chunks of a PNG: {offset of the length field, data length, type}.
struct Chunk {
  size_t offset, length;
  std::string type;
};
std::vector<Chunk> chunks(const std::vector<uint8_t>& png) {
  std::vector<Chunk> out;
  for (size_t at = 8; at + 12 <= png.size();) {
    const size_t len = size_t(png[at]) << 24 | size_t(png[at + 1]) << 16 | size_t(png[at + 2]) << 8 | png[at + 3];
    out.push_back({at, len, std::string(png.begin() + long(at) + 4, png.begin() + long(at) + 8)});
    at += 12 + len;
  }
  return out;
}

// Recomputes a chunk's CRC (over type and data) so that only zlib can notice a change in the data.
void fixCrc(std::vector<uint8_t>& png, const Chunk& c) {
  const uLong crc = crc32(crc32(0, nullptr, 0), png.data() + c.offset + 4, uInt(c.length + 4));
  const size_t at = c.offset + 8 + c.length;
  for (int k = 0; k < 4; ++k) png[at + size_t(k)] = uint8_t(crc >> (24 - 8 * k));
}

}  // namespace

TEST_SUITE("model png index map") {
  TEST_CASE("a written two-material map reads back exactly, row 0 the top row of the image") {
    TempDir tmp;
    const size_t w = 7, h = 5;
    const std::vector<uint8_t> index = twoMaterialMap(w, h);
    const std::string path = tmp.file("two.png");
    writePngIndexMap(path, w, h, index);

    const PngIndexMap map = readPngIndexMap(path);
    CHECK(map.width == w);
    CHECK(map.height == h);
    CHECK(map.index == index);

    // The file itself, decoded by libpng's simplified API: the row PNG stores first (the top row a viewer
    // shows) is index row 0, and the width is the number of columns.
    size_t fw = 0, fh = 0;
    const std::vector<uint8_t> pixels = readWithSimplifiedApi(path, &fw, &fh);
    CHECK(fw == w);
    CHECK(fh == h);
    CHECK(pixels == index);
    for (size_t c = 0; c < w; ++c) CHECK(int(pixels[c]) == 1);  // top row
    CHECK(int(pixels[(h - 1) * w]) == 0);                      // bottom-left
    CHECK(int(pixels[(h - 1) * w + w - 1]) == 1);              // bottom-right
  }

  TEST_CASE("all 256 index values and a large random map read back exactly") {
    TempDir tmp;
    std::vector<uint8_t> all(256);
    for (size_t i = 0; i < 256; ++i) all[i] = uint8_t(i);
    writePngIndexMap(tmp.file("all.png"), 32, 8, all);
    const PngIndexMap a = readPngIndexMap(tmp.file("all.png"));
    CHECK(a.width == 32);
    CHECK(a.height == 8);
    CHECK(a.index == all);

    std::mt19937 rng(15);
    std::vector<uint8_t> big(257 * 129);
    for (auto& v : big) v = uint8_t(rng() % 2);
    writePngIndexMap(tmp.file("big.png"), 257, 129, big);
    const PngIndexMap b = readPngIndexMap(tmp.file("big.png"));
    CHECK(b.width == 257);
    CHECK(b.height == 129);
    CHECK(b.index == big);
  }

  TEST_CASE("palette PNGs: the palette index is the material index (8, 4 and 1 bits)") {
    TempDir tmp;
    const size_t w = 9, h = 4;
    for (int bits : {8, 4, 1}) {
      CAPTURE(bits);
      const int numColours = bits == 1 ? 2 : 5;
      RawPng img;
      img.width = w;
      img.height = h;
      img.colorType = PNG_COLOR_TYPE_PALETTE;
      img.bitDepth = bits;
      for (int k = 0; k < numColours; ++k)  // colours unrelated to the indices
        img.palette.push_back(png_color{png_byte(200 - 40 * k), png_byte(17 * k), png_byte(90)});
      std::vector<uint8_t> expected(w * h);
      for (size_t r = 0; r < h; ++r) {
        std::vector<uint8_t> row(w);
        for (size_t c = 0; c < w; ++c) row[c] = uint8_t((r == 0 ? c + 1 : r * c) % size_t(numColours));
        std::copy(row.begin(), row.end(), expected.begin() + long(r * w));
        const std::vector<uint8_t> packed = packRow(row, bits);
        img.data.insert(img.data.end(), packed.begin(), packed.end());
      }
      const std::string path = tmp.file("palette" + std::to_string(bits) + ".png");
      writeRawPng(path, img);
      const PngIndexMap map = readPngIndexMap(path);
      CHECK(map.width == w);
      CHECK(map.height == h);
      CHECK(map.index == expected);
    }
  }

  TEST_CASE("gray stored as RGB, RGBA or gray+alpha (opaque) reads as the gray value") {
    TempDir tmp;
    const size_t w = 6, h = 3;
    const std::vector<uint8_t> index = {0, 1, 2, 3, 4, 5, 10, 11, 12, 13, 14, 15, 255, 254, 0, 7, 7, 1};
    struct Case {
      int colorType, channels;
      const char* name;
    };
    for (const Case& k : {Case{PNG_COLOR_TYPE_RGB, 3, "rgb"}, Case{PNG_COLOR_TYPE_RGB_ALPHA, 4, "rgba"},
                          Case{PNG_COLOR_TYPE_GRAY_ALPHA, 2, "ga"}}) {
      CAPTURE(k.name);
      RawPng img;
      img.width = w;
      img.height = h;
      img.colorType = k.colorType;
      for (uint8_t v : index)
        for (int c = 0; c < k.channels; ++c) {
          const bool alpha = (k.channels == 2 || k.channels == 4) && c == k.channels - 1;
          img.data.push_back(alpha ? 255 : v);
        }
      const std::string path = tmp.file(std::string(k.name) + ".png");
      writeRawPng(path, img);
      const PngIndexMap map = readPngIndexMap(path);
      CHECK(map.width == w);
      CHECK(map.height == h);
      CHECK(map.index == index);
    }
  }

  TEST_CASE("an interlaced (Adam7) grayscale PNG reads like a non-interlaced one") {
    TempDir tmp;
    const size_t w = 13, h = 11;
    RawPng img;
    img.width = w;
    img.height = h;
    img.interlaced = true;
    for (size_t i = 0; i < w * h; ++i) img.data.push_back(uint8_t((i * 7) % 3));
    const std::string path = tmp.file("adam7.png");
    writeRawPng(path, img);
    const PngIndexMap map = readPngIndexMap(path);
    CHECK(map.width == w);
    CHECK(map.height == h);
    CHECK(map.index == img.data);
  }

  TEST_CASE("a missing file, a directory, an empty file and a text file are refused by name") {
    TempDir tmp;
    const std::string missing = tmp.file("no-such-map.png");
    expectInvalid([&] { readPngIndexMap(missing); }, {named(missing), "no such file"});
    expectInvalid([&] { readPngIndexMap(tmp.dir.string()); }, {named(tmp.dir.string()), "is a directory"});

    const std::string empty = tmp.file("empty.png");
    writeBytes(empty, {}, 0);
    expectInvalid([&] { readPngIndexMap(empty); }, {named(empty), "not a PNG", "empty"});

    const std::string text = tmp.file("material-map.png");
    const std::string words = "index,material\n0,sand\n1,gravel\n";
    writeBytes(text, std::vector<uint8_t>(words.begin(), words.end()), words.size());
    expectInvalid([&] { readPngIndexMap(text); }, {named(text), "not a PNG", "signature"});
  }

  TEST_CASE("a PNG cut at any length is refused as not a PNG or truncated, never read") {
    TempDir tmp;
    const std::string whole = tmp.file("whole.png");
    writePngIndexMap(whole, 23, 17, twoMaterialMap(23, 17));
    const std::vector<uint8_t> bytes = readBytes(whole);
    REQUIRE(bytes.size() > 60);
    const std::string cut = tmp.file("cut.png");
    for (size_t n = 0; n < bytes.size(); ++n) {
      CAPTURE(n);
      writeBytes(cut, bytes, n);
      if (n < 8)
        expectInvalid([&] { readPngIndexMap(cut); }, {named(cut), "not a PNG"});
      else
        expectInvalid([&] { readPngIndexMap(cut); },
                      {named(cut), "truncated", "ends after " + std::to_string(n) + " bytes", "libpng: "});
    }
  }

  TEST_CASE("a flipped byte anywhere in the image data is refused (CRC, and zlib when the CRC is forged)") {
    TempDir tmp;
    const size_t w = 31, h = 19;
    std::vector<uint8_t> index(w * h);
    std::mt19937 rng(7);
    for (auto& v : index) v = uint8_t(rng() % 3);
    const std::string good = tmp.file("good.png");
    writePngIndexMap(good, w, h, index);
    const std::vector<uint8_t> bytes = readBytes(good);
    const std::vector<Chunk> cs = chunks(bytes);
    const Chunk* idat = nullptr;
    for (const Chunk& c : cs)
      if (c.type == "IDAT") idat = &c;
    REQUIRE(idat != nullptr);
    REQUIRE(idat->length > 20);

    const std::string bad = tmp.file("bad.png");
    size_t numCrc = 0, numThrownForged = 0, numSameForged = 0;
    for (size_t k = 0; k < idat->length; ++k) {
      CAPTURE(k);
      std::vector<uint8_t> flipped = bytes;
      flipped[idat->offset + 8 + k] ^= 0xFF;

      // CRC left as it was: every position is caught.
      writeBytes(bad, flipped, flipped.size());
      bool thrown = false;
      try {
        readPngIndexMap(bad);
      } catch (const std::invalid_argument& e) {
        thrown = true;
        const std::string what = e.what();
        INFO("message: " << what);
        CHECK(what.find(named(bad)) != std::string::npos);
        CHECK(what.find("corrupt PNG data (libpng: ") != std::string::npos);
        if (what.find("CRC") != std::string::npos) ++numCrc;
      }
      CHECK(thrown);

      // CRC recomputed: zlib (the deflate codes, the stream's Adler-32) has to notice. A flip that only touches
      // bits inflate ignores may read, but then it must read the original map.
      fixCrc(flipped, *idat);
      writeBytes(bad, flipped, flipped.size());
      try {
        const PngIndexMap map = readPngIndexMap(bad);
        CHECK(map.index == index);
        ++numSameForged;
      } catch (const std::invalid_argument& e) {
        ++numThrownForged;
        const std::string what = e.what();
        INFO("message: " << what);
        CHECK(what.find(named(bad)) != std::string::npos);
        CHECK(what.find("corrupt PNG data (libpng: ") != std::string::npos);
      }
    }
    MESSAGE("IDAT of " << idat->length << " bytes: " << numCrc << " flips reported as CRC errors; with forged CRC "
                       << numThrownForged << " refused by zlib, " << numSameForged << " harmless");
    CHECK(numCrc > 0);
    CHECK(numThrownForged + numSameForged == idat->length);
    CHECK(numThrownForged > idat->length / 2);

    // The zlib header (first two bytes) and the Adler-32 (last four) are always checked.
    for (size_t k : {size_t(0), size_t(1), idat->length - 4, idat->length - 1}) {
      CAPTURE(k);
      std::vector<uint8_t> flipped = bytes;
      flipped[idat->offset + 8 + k] ^= 0xFF;
      fixCrc(flipped, *idat);
      writeBytes(bad, flipped, flipped.size());
      expectInvalid([&] { readPngIndexMap(bad); }, {named(bad), "corrupt PNG data (libpng: "});
    }
  }

  TEST_CASE("16-bit and 1/2/4-bit grayscale PNGs are refused, naming the format and what is supported") {
    TempDir tmp;
    const size_t w = 4, h = 2;
    {
      RawPng img;
      img.width = w;
      img.height = h;
      img.bitDepth = 16;
      img.data.assign(w * h * 2, 0);
      img.data[1] = 1;
      const std::string path = tmp.file("gray16.png");
      writeRawPng(path, img);
      expectInvalid([&] { readPngIndexMap(path); },
                    {named(path), "unsupported PNG format 16-bit grayscale", "supported: 8-bit grayscale"});
    }
    {
      RawPng img;
      img.width = w;
      img.height = h;
      img.colorType = PNG_COLOR_TYPE_RGB;
      img.bitDepth = 16;
      img.data.assign(w * h * 6, 0);
      const std::string path = tmp.file("rgb16.png");
      writeRawPng(path, img);
      expectInvalid([&] { readPngIndexMap(path); }, {named(path), "unsupported PNG format 16-bit RGB", "supported:"});
    }
    for (int bits : {1, 2, 4}) {
      CAPTURE(bits);
      RawPng img;
      img.width = w;
      img.height = h;
      img.bitDepth = bits;
      for (size_t r = 0; r < h; ++r) {
        const std::vector<uint8_t> packed = packRow({0, 1, 1, 0}, bits);
        img.data.insert(img.data.end(), packed.begin(), packed.end());
      }
      const std::string path = tmp.file("gray" + std::to_string(bits) + ".png");
      writeRawPng(path, img);
      expectInvalid([&] { readPngIndexMap(path); },
                    {named(path), "unsupported PNG format " + std::to_string(bits) + "-bit grayscale",
                     "supported: 8-bit grayscale"});
    }
  }

  TEST_CASE("an RGB PNG with colour names the first coloured pixel; transparency is refused") {
    TempDir tmp;
    const size_t w = 5, h = 4;
    RawPng img;
    img.width = w;
    img.height = h;
    img.colorType = PNG_COLOR_TYPE_RGB;
    img.data.assign(w * h * 3, 3);
    const auto set = [&](size_t r, size_t c, uint8_t red, uint8_t green, uint8_t blue) {
      uint8_t* p = img.data.data() + (r * w + c) * 3;
      p[0] = red, p[1] = green, p[2] = blue;
    };
    set(2, 3, 200, 30, 3);  // first in row-major order
    set(3, 0, 1, 2, 3);
    const std::string path = tmp.file("colour.png");
    writeRawPng(path, img);
    expectInvalid([&] { readPngIndexMap(path); },
                  {named(path), "8-bit RGB", "pixel (row 2, column 3)", "(R, G, B) = (200, 30, 3)", "gray"});

    RawPng rgba;
    rgba.width = w;
    rgba.height = h;
    rgba.colorType = PNG_COLOR_TYPE_RGB_ALPHA;
    rgba.data.assign(w * h * 4, 255);
    rgba.data[(1 * w + 4) * 4 + 3] = 128;
    const std::string pathA = tmp.file("transparent.png");
    writeRawPng(pathA, rgba);
    expectInvalid([&] { readPngIndexMap(pathA); },
                  {named(pathA), "8-bit RGBA", "pixel (row 1, column 4)", "alpha = 128", "opaque"});
  }

  TEST_CASE("writePngIndexMap refuses bad sizes and unwritable paths") {
    TempDir tmp;
    const std::string path = tmp.file("w.png");
    expectInvalid([&] { writePngIndexMap(path, 0, 3, {}); }, {"width = 0"});
    expectInvalid([&] { writePngIndexMap(path, 3, 0, {}); }, {"height = 0"});
    expectInvalid([&] { writePngIndexMap(path, 3, 2, std::vector<uint8_t>(5)); }, {"index has 5 values", "= 6"});
    CHECK(!fs::exists(path));
    const std::string nowhere = tmp.file("missing-dir/w.png");
    expectInvalid([&] { writePngIndexMap(nowhere, 1, 1, {0}); }, {named(nowhere), "cannot be opened for writing"});
  }
}
