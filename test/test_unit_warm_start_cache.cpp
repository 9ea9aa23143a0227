// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The warm-start cache's lookups (solver/src/contact_rows.h WarmStartCache): the row build asks for each
// contact's entries with pairRangeAscending, a cursor that walks forward over the sorted entries. Whatever order
// the pairs are asked in -- ascending with gaps, long jumps past the cursor's linear stretch, repeats, backwards,
// pairs below the first or above the last entry, a cursor left past the end of a smaller cache -- it must give
// the binary search's range (pairRange).
#include <doctest/doctest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "contact_rows.h"

using namespace scree;
using namespace scree::detail;

namespace {

/// A cache whose entries are the given pairs (several features each), committed so that it is the one read.
WarmStartCache makeCache(const std::vector<uint64_t>& pairs, std::mt19937& rng) {
  WarmStartCache c;
  c.beginStore();
  for (uint64_t p : pairs) {
    const int features = 1 + int(rng() % 6);
    for (int f = 0; f < features; ++f)
      c.add({p, uint32_t(f), Real(f), Vec3(1, 2, 3), 0, Vec3(Real(p % 7), Real(f), 0)});
  }
  c.commit();
  return c;
}

void checkSame(WarmStartCache& c, uint64_t pair, int& checks) {
  const auto want = c.pairRange(pair);
  const auto got = c.pairRangeAscending(pair);
  CHECK(got.first == want.first);
  CHECK(got.second == want.second);
  ++checks;
}

}  // namespace

TEST_CASE("warm-start cache: the ascending cursor finds every pair's entries as the binary search does") {
  std::mt19937 rng(7);
  // Pairs 10, 20, ..., with holes, so that asked pairs fall on entries, between them and outside them.
  std::vector<uint64_t> pairs;
  for (uint64_t p = 10; p <= 4000; p += 10)
    if (rng() % 3 != 0) pairs.push_back(p);
  WarmStartCache c = makeCache(pairs, rng);
  int checks = 0;

  SUBCASE("ascending, every pair and every value between them") {
    c.resetCursor();
    for (uint64_t q = 0; q <= 4010; ++q) checkSame(c, q, checks);
  }
  SUBCASE("ascending with jumps longer than the cursor's linear stretch") {
    c.resetCursor();
    for (uint64_t q = 5; q <= 4010; q += 10 + 97 * (q % 3)) checkSame(c, q, checks);
  }
  SUBCASE("repeated, backwards and random order (the binary-search fallback)") {
    c.resetCursor();
    for (uint64_t q : {uint64_t(500), uint64_t(500), uint64_t(490), uint64_t(3990), uint64_t(10), uint64_t(0),
                       uint64_t(4000), uint64_t(4000), uint64_t(20)})
      checkSame(c, q, checks);
    for (int k = 0; k < 2000; ++k) checkSame(c, uint64_t(rng() % 4100), checks);
  }
  SUBCASE("a commit of fewer entries, with the cursor left past their end, and no reset") {
    c.resetCursor();
    checkSame(c, 3000, checks);  // the cursor is now far past the two entries committed next
    c.beginStore();
    c.add({20, 0, 1, Vec3::Zero(), 0, Vec3::Zero()});
    c.add({40, 0, 1, Vec3::Zero(), 0, Vec3::Zero()});
    c.commit();
    checkSame(c, 20, checks);
    checkSame(c, 40, checks);
    const auto none = c.pairRangeAscending(50);
    CHECK(none.first == none.second);
  }
  CHECK(checks > 0);
}

TEST_CASE("warm-start cache: an empty cache gives empty ranges") {
  WarmStartCache c;
  c.resetCursor();
  for (uint64_t q : {uint64_t(0), uint64_t(5), uint64_t(1) << 40}) {
    const auto r = c.pairRangeAscending(q);
    CHECK(r.first == r.second);
  }
}
