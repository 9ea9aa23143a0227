// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// scree::io::writeViewerPage (scree/io/viewer_page.h): the C++ half of the replay page. The page itself is
// tested in headless Chromium by test/test_viewer_page.py (label viewer); here: the embedding is exact (the
// base64 text between the markers decodes to the recording's bytes, the title is the HTML-escaped file name),
// the write is atomic (no temporary left behind), bad paths throw std::invalid_argument naming the path, and a
// build without the page throws std::runtime_error.
#include <doctest/doctest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <scree/io/viewer_page.h>

namespace fs = std::filesystem;

namespace {

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeAll(const fs::path& p, const std::string& s) {
  std::ofstream out(p, std::ios::binary);
  out << s;
}

// Standard base64 (RFC 4648, with padding), decoded independently of the writer's encoder.
std::vector<uint8_t> unbase64(const std::string& s) {
  auto val = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  };
  REQUIRE(s.size() % 4 == 0);
  std::vector<uint8_t> out;
  for (size_t i = 0; i < s.size(); i += 4) {
    const int a = val(s[i]), b = val(s[i + 1]);
    REQUIRE(a >= 0);
    REQUIRE(b >= 0);
    out.push_back(uint8_t(a << 2 | b >> 4));
    if (s[i + 2] != '=') {
      const int c = val(s[i + 2]);
      REQUIRE(c >= 0);
      out.push_back(uint8_t((b & 15) << 4 | c >> 2));
      if (s[i + 3] != '=') {
        const int d = val(s[i + 3]);
        REQUIRE(d >= 0);
        out.push_back(uint8_t((c & 3) << 6 | d));
      }
    }
  }
  return out;
}

struct TempDir {
  fs::path dir;
  TempDir() {
    dir = fs::temp_directory_path() / ("scree_viewer_page_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir);
  }
  ~TempDir() { fs::remove_all(dir); }
};

}  // namespace

TEST_SUITE("viewer page") {
  TEST_CASE("writeViewerPage embeds the recording's bytes exactly and names the page after the file") {
    TempDir t;
    if (!scree::io::viewerPageAvailable()) {
      writeAll(t.dir / "a.screerec", "SCREEREC");
      CHECK_THROWS_AS(scree::io::writeViewerPage((t.dir / "a.screerec").string(), (t.dir / "a.html").string()),
                      std::runtime_error);
      CHECK_FALSE(fs::exists(t.dir / "a.html"));
      return;
    }
    const std::string_view tpl = scree::io::viewerPageTemplate();
    // Each marker exactly once in the template (the writer replaces the first; a second would stay behind).
    for (std::string_view m : {"@@SCREE_RECORDING_BASE64@@", "@@SCREE_TITLE@@"}) {
      const size_t at = tpl.find(m);
      REQUIRE(at != std::string_view::npos);
      CHECK(tpl.find(m, at + 1) == std::string_view::npos);
    }
    // Lengths 0, 1 and 2 mod 3 past the magic exercise every base64 padding case; all byte values occur.
    for (size_t extra : {0u, 1u, 2u, 300u, 301u}) {
      std::string bytes = "SCREEREC";
      for (size_t i = 0; i < extra; ++i) bytes += char(uint8_t(i * 37 + 11));
      const fs::path rec = t.dir / "run<1>&.screerec", html = t.dir / "page.html";
      writeAll(rec, bytes);
      scree::io::writeViewerPage(rec.string(), html.string());
      const std::string page = readAll(html);
      CHECK_FALSE(fs::exists(html.string() + ".tmp"));
      const std::string open = "<script id=\"scree-recording\" type=\"application/octet-stream\">";
      const size_t a = page.find(open);
      REQUIRE(a != std::string::npos);
      const size_t b = page.find("</script>", a);
      REQUIRE(b != std::string::npos);
      const std::vector<uint8_t> got = unbase64(page.substr(a + open.size(), b - a - open.size()));
      CHECK(got == std::vector<uint8_t>(bytes.begin(), bytes.end()));
      CHECK(page.find("<title>Scree replay: run&lt;1&gt;&amp;.screerec</title>") != std::string::npos);
      CHECK(page.size() == tpl.size() - 26 - 15 + (bytes.size() + 2) / 3 * 4 +
                               std::string("run&lt;1&gt;&amp;.screerec").size());
    }
  }

  TEST_CASE("writeViewerPage: an unreadable or foreign input and an unwritable output name the path") {
    if (!scree::io::viewerPageAvailable()) return;  // covered by the runtime_error case above
    TempDir t;
    const fs::path rec = t.dir / "ok.screerec", notRec = t.dir / "notes.txt";
    writeAll(rec, "SCREEREC\x01\x00\x00\x00");
    writeAll(notRec, "hello, not a recording");
    auto throwsNaming = [](const std::string& in, const std::string& out, const std::string& name) {
      try {
        scree::io::writeViewerPage(in, out);
        FAIL("no exception for " << in << " -> " << out);
      } catch (const std::invalid_argument& e) {
        const std::string msg = e.what();
        CHECK_MESSAGE(msg.find(name) != std::string::npos, msg);
      }
    };
    throwsNaming((t.dir / "missing.screerec").string(), (t.dir / "a.html").string(), "missing.screerec");
    throwsNaming(notRec.string(), (t.dir / "b.html").string(), "notes.txt");
    throwsNaming(rec.string(), (t.dir / "no_such_dir" / "c.html").string(), "no_such_dir");
    for (const char* f : {"a.html", "b.html"}) CHECK_FALSE(fs::exists(t.dir / f));
    // An existing page is replaced whole.
    writeAll(t.dir / "d.html", std::string(1 << 20, 'x'));
    scree::io::writeViewerPage(rec.string(), (t.dir / "d.html").string());
    CHECK(readAll(t.dir / "d.html").find("xxxx") == std::string::npos);
  }
}
