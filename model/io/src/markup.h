// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Text escaping shared by the XML (VTK) and HTML (replay page) writers of Scree::io.
#pragma once

#include <string>
#include <string_view>

namespace scree::io {

/// `s` with & < > " ' replaced by entities. `&#39;` for the apostrophe is valid in both XML and HTML.
inline std::string markupEscape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace scree::io
