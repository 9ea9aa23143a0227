// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The replay page written by `scree view FILE -o page.html`: one self-contained HTML file (three.js and the
// page's scripts inlined at build time, the recording embedded in base64) that replays a recording
// (docs/recording.md) offline in a browser with WebGL. The page reads the format itself (CRC-32 checks,
// DecompressionStream("deflate") for frames, the XOR deltas), so the C++ side only embeds the bytes: a file
// the page cannot read is reported in the page, with the chunk and byte offset, not here.
//
// Building: model/io/viewer/CMakeLists.txt fetches three.js from the npm registry once (a pinned version)
// and bundles the page when SCREE_BUILD_VIEWER is ON (the default when npm and node are found). Without it,
// scree_io still builds and writeViewerPage throws std::runtime_error.
#pragma once

#include <string>
#include <string_view>

namespace scree::io {

/// True when this build holds the page template (SCREE_BUILD_VIEWER was ON and npm could fetch three.js).
bool viewerPageAvailable();

/// The page template: the bundled HTML with two markers, each occurring once, that writeViewerPage replaces:
/// "@@SCREE_RECORDING_BASE64@@" (the recording's bytes, standard base64 with padding, no line breaks) and
/// "@@SCREE_TITLE@@" (the file name shown by the page, HTML-escaped). Empty when !viewerPageAvailable().
std::string_view viewerPageTemplate();

/// Writes the replay page of the recording at `recordingPath` to `htmlPath`: reads the recording's bytes
/// (checking only that they start with the "SCREEREC" magic), embeds them and writes the page to a temporary
/// file next to `htmlPath`, then renames it over `htmlPath`, so an interrupted write never leaves half a page.
/// Throws std::invalid_argument naming the path when the recording cannot be read or is not a recording, or
/// `htmlPath` cannot be written; std::runtime_error when built without the page.
void writeViewerPage(const std::string& recordingPath, const std::string& htmlPath);

}  // namespace scree::io
