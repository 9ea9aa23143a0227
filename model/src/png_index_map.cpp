// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// PNG material maps through libpng (see png_index_map.h for the formats and the error contract).
//
// Error handling. libpng reports a fatal error by calling the error callback and then longjmp-ing to the
// jmp_buf of png_jmpbuf(png); the callback must not return and must not throw (an exception unwinding through
// libpng's C frames is undefined behaviour and leaves libpng's state half-updated). longjmp in C++ is only
// defined when the frames it leaves would run no non-trivial destructors. So:
//   - each libpng call sequence runs in a small "stage" function (readHeaderStage, ...) that calls setjmp and
//     holds only pointers and integers; on longjmp it returns false;
//   - the callbacks (C language linkage) write into PngIo, a trivially destructible struct, then longjmp;
//   - everything with a destructor (the FILE guard, the libpng structs' guard, the pixel buffer and the row
//     pointers, strings) lives in the calling C++ function, which never calls setjmp itself, and is allocated
//     before the stage that fills it. After a stage fails, the C++ caller builds the message and throws; the
//     guards then destroy the libpng structs and close the file.
// Nothing a stage writes is read after a longjmp except through pointers to memory outside the stage frame,
// so no local needs `volatile`.
#include "png_index_map.h"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

#include "scree/core/logger.h"

namespace scree::detail {
namespace {

// State the libpng callbacks share with the C++ caller. Plain data only: a longjmp may leave any frame that
// refers to it.
struct PngIo {
  std::FILE* file = nullptr;
  size_t bytesRead = 0;     // reading: bytes consumed so far, the 8 signature bytes included
  bool endOfFile = false;   // reading: libpng asked for bytes past the end of the file
  bool readError = false;   // reading: fread failed with an I/O error
  char error[256] = {};     // the text of libpng's fatal error
  char warning[256] = {};   // the text of libpng's first warning
  int numWarnings = 0;
};
static_assert(std::is_trivially_destructible_v<PngIo>);

struct Header {
  png_uint_32 width = 0, height = 0;
  int bitDepth = 0, colorType = 0, interlace = 0;
};

}  // namespace
}  // namespace scree::detail

// libpng calls these through C function pointers, so they get C language linkage (internal: `static`).
extern "C" {

static void screePngError(png_structp png, png_const_charp message) {
  auto* io = static_cast<scree::detail::PngIo*>(png_get_error_ptr(png));
  std::snprintf(io->error, sizeof io->error, "%s", message ? message : "unknown error");
  png_longjmp(png, 1);  // never returns: back to the setjmp of the running stage
}

static void screePngWarning(png_structp png, png_const_charp message) {
  auto* io = static_cast<scree::detail::PngIo*>(png_get_error_ptr(png));
  if (io->numWarnings++ == 0) std::snprintf(io->warning, sizeof io->warning, "%s", message ? message : "");
}

// Our own read function instead of png_init_io's: libpng's says only "Read Error" at the end of the file; this
// one records that the file ended, so the caller can say "truncated" and where.
static void screePngRead(png_structp png, png_bytep data, size_t length) {
  auto* io = static_cast<scree::detail::PngIo*>(png_get_io_ptr(png));
  const size_t got = std::fread(data, 1, length, io->file);
  io->bytesRead += got;
  if (got == length) return;
  if (std::ferror(io->file)) {
    io->readError = true;
    png_error(png, "I/O error while reading");
  }
  io->endOfFile = true;
  png_error(png, "unexpected end of file");
}

}  // extern "C"

namespace scree::detail {
namespace {

constexpr size_t kMaxDimension = 1000000;  // libpng's default user limit (PNG_USER_WIDTH_MAX / HEIGHT_MAX)

const char* const kSupported =
    "supported: 8-bit grayscale, palette (1, 2, 4 or 8 bits), and 8-bit gray stored as gray+alpha, RGB or RGBA "
    "(equal colour channels, opaque)";

// ---- setjmp stages: pointers and integers only, no objects with destructors -------------------------------

// The chunks before the image data, and the header fields.
bool readHeaderStage(png_structp png, png_infop info, Header* out) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  png_get_IHDR(png, info, &out->width, &out->height, &out->bitDepth, &out->colorType, &out->interlace, nullptr,
               nullptr);
  return true;
}

// Transformations: 1/2/4-bit palette indices unpacked to one byte each (values unchanged); interlaced passes
// assembled by libpng. Reports the row size libpng will deliver.
bool setTransformsStage(png_structp png, png_infop info, bool unpack, size_t* outRowBytes) {
  if (setjmp(png_jmpbuf(png))) return false;
  if (unpack) png_set_packing(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  *outRowBytes = png_get_rowbytes(png, info);
  return true;
}

// The image into rows[0 .. height) (allocated by the caller), then the chunks after it.
bool readImageStage(png_structp png, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  // On read, libpng 1.6 downgrades "benign" errors to warnings by default; among them are a zlib error found
  // while checking the end of the image data (a wrong Adler-32, i.e. altered pixels) and surplus image data.
  // For a material map these are errors. Ancillary chunks before the image (e.g. a colour profile libpng
  // disapproves of) were read leniently above, and those after it are read leniently again below.
  png_set_benign_errors(png, 0);
  png_read_image(png, rows);
  png_set_benign_errors(png, 1);
  png_read_end(png, nullptr);
  return true;
}

bool writeStage(png_structp png, png_infop info, png_uint_32 width, png_uint_32 height, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_GRAY, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  return true;
}

// ---- RAII owners (live only in frames that never call setjmp) ---------------------------------------------

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

struct ReadStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ReadStructs() = default;
  ReadStructs(const ReadStructs&) = delete;
  ReadStructs& operator=(const ReadStructs&) = delete;
  ~ReadStructs() {
    if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
  }
};

struct WriteStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  WriteStructs() = default;
  WriteStructs(const WriteStructs&) = delete;
  WriteStructs& operator=(const WriteStructs&) = delete;
  ~WriteStructs() {
    if (png) png_destroy_write_struct(&png, info ? &info : nullptr);
  }
};

std::string errnoText(int e) { return std::error_code(e, std::generic_category()).message(); }

const char* colorTypeName(int colorType) {
  switch (colorType) {
    case PNG_COLOR_TYPE_GRAY: return "grayscale";
    case PNG_COLOR_TYPE_PALETTE: return "palette";
    case PNG_COLOR_TYPE_RGB: return "RGB";
    case PNG_COLOR_TYPE_RGB_ALPHA: return "RGBA";
    case PNG_COLOR_TYPE_GRAY_ALPHA: return "gray+alpha";
    default: return "unknown colour type";
  }
}

}  // namespace

PngIndexMap readPngIndexMap(const std::string& path) {
  const std::string where = "readPngIndexMap: path = \"" + path + "\": ";
  const auto fail = [&](const std::string& problem) { return std::invalid_argument(where + problem); };

  // ---- the file ----
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (!std::filesystem::exists(status)) throw fail("no such file");
  if (std::filesystem::is_directory(status)) throw fail("is a directory, not a PNG file");
  FilePtr file(std::fopen(path.c_str(), "rb"));
  if (!file) {
    const int e = errno;
    throw fail("cannot be opened for reading (" + errnoText(e) + ")");
  }

  // ---- the signature: checked here so a wrong file type gets its own message ----
  png_byte signature[8] = {};
  const size_t numSignature = std::fread(signature, 1, sizeof signature, file.get());
  if (numSignature < sizeof signature) {
    if (std::ferror(file.get())) throw fail("I/O error while reading the PNG signature");
    if (numSignature == 0) throw fail("not a PNG file (the file is empty)");
    throw fail("not a PNG file (only " + std::to_string(numSignature) +
               " bytes long, shorter than the 8-byte PNG signature)");
  }
  if (png_sig_cmp(signature, 0, sizeof signature) != 0)
    throw fail("not a PNG file (its first 8 bytes are not the PNG signature)");

  // ---- libpng ----
  PngIo io;
  io.file = file.get();
  io.bytesRead = sizeof signature;
  ReadStructs rs;
  rs.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &io, screePngError, screePngWarning);
  if (!rs.png) throw fail("libpng could not create its reader (out of memory, or png.h and libpng differ)");
  rs.info = png_create_info_struct(rs.png);
  if (!rs.info) throw fail("libpng could not create its reader (out of memory)");
  png_set_read_fn(rs.png, &io, screePngRead);
  png_set_sig_bytes(rs.png, sizeof signature);

  // The message for a failed stage, from what the callbacks recorded.
  const auto libpngFailure = [&]() {
    std::string problem;
    if (io.endOfFile)
      problem = "truncated PNG: the file ends after " + std::to_string(io.bytesRead) +
                " bytes, inside the PNG data";
    else if (io.readError)
      problem = "I/O error after " + std::to_string(io.bytesRead) + " bytes";
    else
      problem = "corrupt PNG data";
    problem += std::string(" (libpng: ") + io.error + ")";
    if (io.numWarnings > 0) problem += std::string("; libpng warned before: ") + io.warning;
    return fail(problem);
  };

  Header h;
  if (!readHeaderStage(rs.png, rs.info, &h)) throw libpngFailure();

  // ---- what this reader accepts (libpng has already rejected invalid colour type / depth pairs) ----
  const std::string format = std::to_string(h.bitDepth) + "-bit " + colorTypeName(h.colorType);
  if (h.bitDepth == 16)
    throw fail("unsupported PNG format " + format + " (16-bit samples are not material indices 0..255); " +
               kSupported);
  if (h.colorType == PNG_COLOR_TYPE_GRAY && h.bitDepth < 8)
    throw fail("unsupported PNG format " + format +
               " (a 1, 2 or 4-bit gray value is a fraction of white, not an index; save the map as 8-bit "
               "grayscale or with a palette); " + kSupported);
  size_t channels = 0;
  switch (h.colorType) {
    case PNG_COLOR_TYPE_GRAY:
    case PNG_COLOR_TYPE_PALETTE: channels = 1; break;
    case PNG_COLOR_TYPE_GRAY_ALPHA: channels = 2; break;
    case PNG_COLOR_TYPE_RGB: channels = 3; break;
    case PNG_COLOR_TYPE_RGB_ALPHA: channels = 4; break;
    default: throw fail("unsupported PNG format " + format + "; " + kSupported);
  }
  if (h.colorType != PNG_COLOR_TYPE_PALETTE && h.bitDepth != 8)
    throw fail("unsupported PNG format " + format + "; " + kSupported);
  const size_t width = h.width, height = h.height;  // each <= 1,000,000 (libpng's limit, checked in IHDR)
  if (width * height > kMaxPngIndexMapPixels)
    throw fail("the image is " + std::to_string(width) + " x " + std::to_string(height) +
               " pixels, more than the " + std::to_string(kMaxPngIndexMapPixels) + " this reader accepts");

  size_t rowBytes = 0;
  if (!setTransformsStage(rs.png, rs.info, h.colorType == PNG_COLOR_TYPE_PALETTE && h.bitDepth < 8, &rowBytes))
    throw libpngFailure();
  if (rowBytes != width * channels)  // cannot happen with the transformations above; never write past a row
    throw fail("libpng delivers rows of " + std::to_string(rowBytes) + " bytes, expected " +
               std::to_string(width * channels) + " (" + format + ")");

  // ---- the pixels: buffer and row pointers allocated here, outside the setjmp stage ----
  std::vector<uint8_t> pixels(width * height * channels);
  std::vector<png_bytep> rows(height);
  for (size_t r = 0; r < height; ++r) rows[r] = pixels.data() + r * rowBytes;
  if (!readImageStage(rs.png, rows.data())) throw libpngFailure();
  if (io.numWarnings > 0)
    Logger::warning(where + "read with " + std::to_string(io.numWarnings) + " libpng warning(s), the first: " +
                    io.warning);

  PngIndexMap map;
  map.width = width;
  map.height = height;
  if (channels == 1) {
    map.index = std::move(pixels);
    return map;
  }

  // Gray stored with alpha or as RGB(A): colour channels equal, alpha (the last channel if present) opaque.
  const bool hasAlpha = channels == 2 || channels == 4;
  const size_t numColour = hasAlpha ? channels - 1 : channels;
  map.index.resize(width * height);
  for (size_t p = 0; p < width * height; ++p) {
    const uint8_t* px = pixels.data() + p * channels;
    bool gray = true;
    for (size_t c = 1; c < numColour; ++c) gray = gray && px[c] == px[0];
    const std::string at = "pixel (row " + std::to_string(p / width) + ", column " + std::to_string(p % width) + ")";
    if (!gray) {
      std::string rgb = std::to_string(px[0]);
      for (size_t c = 1; c < numColour; ++c) rgb += ", " + std::to_string(px[c]);
      throw fail(format + " material map with a coloured " + at + ": (R, G, B) = (" + rgb +
                 "), the first pixel in row-major order whose colour channels differ; an RGB map must be gray "
                 "(R = G = B = the index)");
    }
    if (hasAlpha && px[channels - 1] != 255)
      throw fail(format + " material map with a transparent " + at + ": alpha = " +
                 std::to_string(px[channels - 1]) + "; a map with alpha must be opaque (alpha = 255)");
    map.index[p] = px[0];
  }
  return map;
}

void writePngIndexMap(const std::string& path, size_t width, size_t height, const std::vector<uint8_t>& index) {
  const std::string fn = "writePngIndexMap: ";
  if (width == 0 || width > kMaxDimension)
    throw std::invalid_argument(fn + "width = " + std::to_string(width) + " is not in 1.." +
                                std::to_string(kMaxDimension));
  if (height == 0 || height > kMaxDimension)
    throw std::invalid_argument(fn + "height = " + std::to_string(height) + " is not in 1.." +
                                std::to_string(kMaxDimension));
  if (index.size() != width * height)
    throw std::invalid_argument(fn + "index has " + std::to_string(index.size()) + " values, width * height = " +
                                std::to_string(width) + " * " + std::to_string(height) + " = " +
                                std::to_string(width * height));
  const std::string where = fn + "path = \"" + path + "\": ";

  FilePtr file(std::fopen(path.c_str(), "wb"));
  if (!file) {
    const int e = errno;
    throw std::invalid_argument(where + "cannot be opened for writing (" + errnoText(e) + ")");
  }
  // A failed write leaves no half-written map behind.
  const auto failAndRemove = [&](const std::string& problem) {
    file.reset();
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
    return std::invalid_argument(where + problem);
  };

  PngIo io;
  io.file = file.get();
  bool ok = false;
  {
    WriteStructs ws;
    ws.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &io, screePngError, screePngWarning);
    if (!ws.png) throw failAndRemove("libpng could not create its writer (out of memory, or png.h and libpng differ)");
    ws.info = png_create_info_struct(ws.png);
    if (!ws.info) throw failAndRemove("libpng could not create its writer (out of memory)");
    png_init_io(ws.png, file.get());  // fwrite; a short write is a libpng error ("Write Error")
    // png_write_image takes non-const rows but only reads them (each row is copied before filtering).
    std::vector<png_bytep> rows(height);
    for (size_t r = 0; r < height; ++r) rows[r] = const_cast<png_bytep>(index.data() + r * width);
    ok = writeStage(ws.png, ws.info, png_uint_32(width), png_uint_32(height), rows.data());
  }
  if (!ok) throw failAndRemove(std::string("writing failed (libpng: ") + io.error + ")");
  const int closed = std::fclose(file.release());  // buffered data is written here: check it
  if (closed != 0) {
    const int e = errno;
    throw failAndRemove("writing failed when closing the file (" + errnoText(e) + ")");
  }
}

}  // namespace scree::detail
