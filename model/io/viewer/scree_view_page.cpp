// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// scree_view_page RECORDING HTML: writes the replay page of a recording (scree::io::writeViewerPage). Used by
// test/test_viewer_page.py so the test exercises the C++ embedding; `scree view FILE -o page.html` is the
// user's command.
#include <exception>
#include <iostream>

#include "scree/io/viewer_page.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: scree_view_page RECORDING HTML\n";
    return 2;
  }
  try {
    scree::io::writeViewerPage(argv[1], argv[2]);
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
  return 0;
}
