// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// HeightField rectangle edits: values land where the layout says, bounds and tile bounds always equal a full
// scan (exact: min/max of the same doubles), bad input changes nothing, batches defer the bounds.
#include <doctest/doctest.h>

#include <algorithm>
#include <random>

#include <scree/scree.h>

using namespace scree;

namespace {
// Full-scan bounds of the grid and of every tile, the reference the incremental bounds must equal.
void checkBounds(const HeightField& hf) {
  const auto& h = hf.getHeights();
  CHECK(hf.getMinHeight() == *std::min_element(h.begin(), h.end()));
  CHECK(hf.getMaxHeight() == *std::max_element(h.begin(), h.end()));
  const size_t T = HeightField::kTileSize, nx = hf.getResolutionX(), ny = hf.getResolutionY();
  for (size_t tj = 0; tj < hf.getNumTilesY(); ++tj)
    for (size_t ti = 0; ti < hf.getNumTilesX(); ++ti) {
      Real mn = 1e300, mx = -1e300;
      for (size_t j = tj * T; j <= std::min(tj * T + T, ny - 1); ++j)
        for (size_t i = ti * T; i <= std::min(ti * T + T, nx - 1); ++i) {
          mn = std::min(mn, hf.getHeight(i, j));
          mx = std::max(mx, hf.getHeight(i, j));
        }
      REQUIRE(hf.getTileMinHeight(ti, tj) == mn);
      REQUIRE(hf.getTileMaxHeight(ti, tj) == mx);
    }
}
}  // namespace

TEST_SUITE("heightfield edit") {
  TEST_CASE("tiles cover every cell once and the grid's last vertices") {
    HeightField a(2, 2, 1, 1), b(17, 17, 1, 1), c(18, 33, 1, 1), d(257, 257, 1, 1);
    CHECK(a.getNumTilesX() == 1);
    CHECK(b.getNumTilesX() == 1);  // 16 cells
    CHECK(c.getNumTilesX() == 2);  // 17 cells
    CHECK(c.getNumTilesY() == 2);  // 32 cells
    CHECK(d.getNumTilesX() == 16);
  }

  TEST_CASE("a rectangle edit writes row-major with i fastest and keeps the bounds exact") {
    HeightField hf(40, 35, 3.9, 3.4);
    hf.setHeights(3, 5, 6, 7, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12});
    CHECK(hf.getHeight(3, 5) == 1);
    CHECK(hf.getHeight(6, 5) == 4);
    CHECK(hf.getHeight(3, 6) == 5);
    CHECK(hf.getHeight(6, 7) == 12);
    CHECK(hf.getHeight(2, 5) == 0);
    CHECK(hf.getHeight(7, 7) == 0);
    CHECK(hf.getHeight(3, 8) == 0);
    CHECK(hf.getMaxHeight() == 12);
    const auto& r = hf.getDirtyRectangle();
    CHECK(r.i0 == 3);
    CHECK(r.j0 == 5);
    CHECK(r.i1 == 6);
    CHECK(r.j1 == 7);
    checkBounds(hf);
    // Lower the highest vertex: the maximum must come down to the next highest (the case a single running
    // max cannot handle without a rescan).
    hf.setHeights(6, 7, 6, 7, {-1});
    CHECK(hf.getMaxHeight() == 11);
    checkBounds(hf);
  }

  TEST_CASE("random rectangle edits, single edits and batches agree with a full scan") {
    std::mt19937 rng(7);
    HeightField hf(70, 53, 6.9, 5.2);
    std::uniform_real_distribution<Real> value(-2, 2);
    for (int k = 0; k < 300; ++k) {
      std::uniform_int_distribution<size_t> ix(0, 69), iy(0, 52);
      size_t i0 = ix(rng), i1 = ix(rng), j0 = iy(rng), j1 = iy(rng);
      if (i0 > i1) std::swap(i0, i1);
      if (j0 > j1) std::swap(j0, j1);
      std::vector<Real> v((i1 - i0 + 1) * (j1 - j0 + 1));
      for (Real& x : v) x = value(rng) * (k % 3 == 0 ? 0.1 : 1.0);  // some edits lower everything they touch
      if (k % 4 == 0) {
        hf.beginHeightEdit();
        for (size_t j = j0; j <= j1; ++j)
          for (size_t i = i0; i <= i1; ++i) hf.setHeight(i, j, v[(j - j0) * (i1 - i0 + 1) + (i - i0)]);
        hf.endHeightEdit();
      } else {
        hf.setHeights(i0, j0, i1, j1, v);
      }
      for (size_t j = j0; j <= j1; ++j)
        for (size_t i = i0; i <= i1; ++i) REQUIRE(hf.getHeight(i, j) == v[(j - j0) * (i1 - i0 + 1) + (i - i0)]);
      checkBounds(hf);
    }
  }

  TEST_CASE("bad rectangle edits throw naming the parameter and change nothing") {
    HeightField hf(10, 8, 0.9, 0.7);
    hf.setHeights(0, 0, 9, 7, std::vector<Real>(80, 0.5));
    hf.clearDirtyRectangle();
    const std::vector<Real> before = hf.getHeights();
    auto expect = [&](auto&& fn, const char* param) {
      try {
        fn();
        FAIL("no exception");
      } catch (const std::invalid_argument& e) {
        CHECK(std::string(e.what()).find(param) != std::string::npos);
      }
      CHECK(hf.getHeights() == before);
      CHECK(hf.getDirtyRectangle().empty());
      CHECK(hf.getMaxHeight() == 0.5);
    };
    expect([&] { hf.setHeights(0, 0, 10, 1, std::vector<Real>(22, 1.0)); }, "i1");
    expect([&] { hf.setHeights(0, 0, 1, 8, std::vector<Real>(18, 1.0)); }, "j1");
    expect([&] { hf.setHeights(3, 0, 2, 1, std::vector<Real>(4, 1.0)); }, "i0");
    expect([&] { hf.setHeights(0, 3, 1, 2, std::vector<Real>(4, 1.0)); }, "j0");
    expect([&] { hf.setHeights(0, 0, 1, 1, std::vector<Real>(3, 1.0)); }, "values.size()");
    expect([&] { hf.setHeights(0, 0, 1, 1, {1.0, 2.0, std::nan(""), 3.0}); }, "values[2]");
  }

  TEST_CASE("inside a batch the bounds wait for endHeightEdit") {
    HeightField hf(20, 20, 1.9, 1.9);
    hf.beginHeightEdit();
    hf.setHeight(4, 4, 3.0);
    hf.setHeights(10, 10, 11, 11, {1, 2, 3, 5});
    CHECK(hf.getMaxHeight() == 0);  // deferred
    hf.endHeightEdit();
    CHECK(hf.getMaxHeight() == 5);
    checkBounds(hf);
    CHECK(hf.getDirtyRectangle().i0 == 4);
    CHECK(hf.getDirtyRectangle().i1 == 11);
  }
}
