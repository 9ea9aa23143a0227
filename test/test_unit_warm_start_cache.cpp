// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The warm-start cache's lookups (solver/src/contact_rows.h WarmStartCache): the row build asks for each
// contact's entries with pairRangeAscending, a cursor that walks forward over the sorted entries. Whatever order
// the pairs are asked in -- ascending with gaps, long jumps past the cursor's linear stretch, repeats, backwards,
// pairs below the first or above the last entry, a cursor left past the end of a smaller cache -- it must give
// the binary search's range (pairRange).
#include <doctest/doctest.h>

#include <algorithm>
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

// The store in place (store_results.cpp with rows grouped by region): each contact's entries are written at the
// place the contacts before it leave free, by whichever thread stores the contact and in any order of contacts,
// each contact's run is ordered by feature (sortRun), then commitPlaced. It must give the cache that add() in
// contact order and commit() give -- entry for entry -- including over last step's larger storage, and when the
// contacts' pairs do not ascend (commitPlaced then sorts everything, as commit does).
TEST_CASE("warm-start cache: the store in place gives the entries of add and commit") {
  std::mt19937 rng(11);
  WarmStartCache placed, added;
  for (int round = 0; round < 4; ++round) {
    const bool ascending = round % 2 == 0;
    // Contacts in contact order: a pair each, 1..6 points with distinct features in narrowphase order (not sorted).
    const int numContacts = round == 0 ? 300 : 40 + int(rng() % 200);  // round 0 leaves the largest storage
    std::vector<uint64_t> pairs;
    for (uint64_t p = 5; int(pairs.size()) < numContacts; p += 1 + rng() % 9) pairs.push_back(p);
    if (!ascending) std::shuffle(pairs.begin(), pairs.end(), rng);
    std::vector<std::vector<WarmStartCache::Entry>> contacts;
    for (uint64_t p : pairs) {
      std::vector<uint32_t> features{0, 1, 2, 3, 4, 5};
      std::shuffle(features.begin(), features.end(), rng);
      features.resize(1 + rng() % 6);
      auto& c = contacts.emplace_back();
      for (uint32_t f : features)
        c.push_back({p, f, Real(rng() % 1000) / 7, Vec3(Real(f), 2, 3), Real(round), Vec3(Real(p), Real(f), 0)});
    }
    added.beginStore();
    for (const auto& c : contacts)
      for (const auto& e : c) added.add(e);
    added.commit();
    // In place: the places in contact order, the contacts written in a shuffled order (as two threads would).
    std::vector<size_t> first;
    size_t n = 0;
    for (const auto& c : contacts) {
      first.push_back(n);
      n += c.size();
    }
    placed.beginStorePlaced(n);
    std::vector<size_t> writeOrder(contacts.size());
    for (size_t k = 0; k < writeOrder.size(); ++k) writeOrder[k] = k;
    std::shuffle(writeOrder.begin(), writeOrder.end(), rng);
    for (size_t k : writeOrder) {
      for (size_t j = 0; j < contacts[k].size(); ++j) placed.set(first[k] + j, contacts[k][j]);
      placed.sortRun(first[k], first[k] + contacts[k].size());
    }
    placed.commitPlaced(ascending);
    int compared = 0;
    for (uint64_t p : pairs) {
      const auto want = added.pairRange(p), got = placed.pairRange(p);
      REQUIRE(got.second - got.first == want.second - want.first);
      for (auto a = want.first, b = got.first; a != want.second; ++a, ++b) {
        CHECK(b->feature == a->feature);
        CHECK(b->normal == a->normal);
        CHECK(b->point == a->point);
        CHECK(b->impactSpeed == a->impactSpeed);
        ++compared;
      }
    }
    CHECK(compared == int(n));
    // Sorted by pair, then feature: what the row build's ascending lookups need.
    for (uint64_t p : pairs) {
      const auto got = placed.pairRange(p);
      for (auto e = got.first; e + 1 < got.second; ++e) CHECK(e->feature < (e + 1)->feature);
    }
  }
}
