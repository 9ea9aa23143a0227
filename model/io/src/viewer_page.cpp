// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// scree::io::writeViewerPage (scree/io/viewer_page.h). The template itself is generated at build time by
// model/io/viewer/bundle.js into the build tree and linked into scree_io when the viewer is built
// (SCREE_HAVE_VIEWER_PAGE).
#include "scree/io/viewer_page.h"

#include "markup.h"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

#include "scree/core/errors.h"

namespace scree::io {

#ifdef SCREE_HAVE_VIEWER_PAGE
bool viewerPageAvailable() { return true; }
#else
bool viewerPageAvailable() { return false; }
std::string_view viewerPageTemplate() { return {}; }
#endif

namespace {

constexpr std::string_view kRecordingMarker = "@@SCREE_RECORDING_BASE64@@";
constexpr std::string_view kTitleMarker = "@@SCREE_TITLE@@";

std::string base64(const std::vector<uint8_t>& in) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 3 <= in.size(); i += 3) {
    const uint32_t v = uint32_t(in[i]) << 16 | uint32_t(in[i + 1]) << 8 | in[i + 2];
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i + 1 == in.size()) {
    const uint32_t v = uint32_t(in[i]) << 16;
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    const uint32_t v = uint32_t(in[i]) << 16 | uint32_t(in[i + 1]) << 8;
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}


}  // namespace

void writeViewerPage(const std::string& recordingPath, const std::string& htmlPath) {
  constexpr std::string_view where = "writeViewerPage";
  if (!viewerPageAvailable())
    throw std::runtime_error(
        "writeViewerPage: built without the replay page (npm was not available at build time)");
  std::ifstream in(recordingPath, std::ios::binary);
  if (!in) detail::throwInvalid(where, "recordingPath", recordingPath, "cannot be opened for reading");
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) detail::throwInvalid(where, "recordingPath", recordingPath, "could not be read");
  if (bytes.size() < 8 || std::string_view(reinterpret_cast<const char*>(bytes.data()), 8) != "SCREEREC")
    detail::throwInvalid(where, "recordingPath", recordingPath,
                         "is not a Scree recording: it does not start with \"SCREEREC\"");

  const std::string_view page = viewerPageTemplate();
  const size_t rec = page.find(kRecordingMarker), title = page.find(kTitleMarker);
  if (rec == std::string_view::npos || title == std::string_view::npos || title > rec)
    throw std::logic_error("writeViewerPage: the page template lacks its markers (a build defect)");
  const std::string name = std::filesystem::path(recordingPath).filename().string();

  const std::string tmp = htmlPath + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) detail::throwInvalid(where, "htmlPath", htmlPath, "cannot be opened for writing");
    out << page.substr(0, title) << markupEscape(name)
        << page.substr(title + kTitleMarker.size(), rec - title - kTitleMarker.size()) << base64(bytes)
        << page.substr(rec + kRecordingMarker.size());
    out.flush();
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      detail::throwInvalid(where, "htmlPath", htmlPath, "could not be written");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, htmlPath, ec);
  if (ec) {
    std::remove(tmp.c_str());
    detail::throwInvalid(where, "htmlPath", htmlPath, "could not be written (" + ec.message() + ")");
  }
}

}  // namespace scree::io
