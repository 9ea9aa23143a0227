// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Coulomb friction against closed forms, on the reference scenes (bench/scenes: slide, incline_mu05/06).
//
// Discrete floor: with semi-implicit Euler at h = 1/60 the exact discrete solutions differ from the continuous
// ones by O(h):
//   slide (a = mu g = 2.943 m/s^2, v0 = 5): v_n = v0 - n h a reaches 0 after 102 steps and
//     x = h sum_{k=1..101} (v0 - k h a) = 4.2056 m, i.e. -0.98 % of v0^2/(2 mu g) = 4.2474 m;
//   incline mu 0.5 (a = g (sin30 - 0.5 cos30) = 0.6571 m/s^2): x_120 = h^2 a 120*121/2 = 1.3252 m, +0.83 %
//     of 0.5 a t^2 = 1.3143 m.
// A correct friction solver lands on those values; 2 % allows the discretisation floor (~1 %) plus about one
// step of stop-time quantisation, and nothing more. Other engines measure -0.98 % and +0.83 % (docs/scenes.md).
#include <doctest/doctest.h>

#include <cmath>

#include "test_world.h"

using namespace scree;
using namespace scree::scenes;

TEST_SUITE("solver") {

TEST_CASE("a box sliding at 5 m/s with mu 0.3 stops at v^2/(2 mu g) within 2 %") {
  SlideScene s = buildSlide(0.3, 5.0);
  const SlideMetrics m = runSlide(s);
  MESSAGE("slide: distance " << m.distance << " m (analytic " << s.analyticDistance() << ", error "
                             << m.distanceErr * 100 << " %), stop time " << m.stopTime << " s (analytic "
                             << s.analyticTime() << ", error " << m.timeErr * 100 << " %)");
  CHECK(m.finite);
  CHECK(std::abs(m.distanceErr) < 0.02);
  // Stop time: the discrete stop is at step 102 = 1.700 s (+0.06 %); 2 % is one step (0.98 %) plus the floor.
  CHECK(m.stopTime > 0);
  CHECK(std::abs(m.timeErr) < 0.02);
  // It must not drift sideways or lift off.
  CHECK(std::abs(s.box->getPosition().y()) < 1e-3);
  CHECK(std::abs(s.box->getPosition().z() - 0.5) < 1e-3);
}

TEST_CASE("a cube on a 30 degree incline with mu 0.6 sticks (moves < 1 mm in 2 s)") {
  // tan 30 = 0.577 < 0.6: static friction holds. 1 mm bounds the creep a regularised (compliant) friction row
  // may show; Jolt and ODE's direct solver creep 0.05 mm, ODE QuickStep 5.7 mm (docs/scenes.md).
  InclineScene s = buildIncline(0.6);
  const InclineMetrics m = runIncline(s);
  MESSAGE("incline mu 0.6: displacement along the slope " << m.displacement * 1e3 << " mm");
  CHECK(m.finite);
  CHECK(std::abs(m.displacement) < 1e-3);
}

TEST_CASE("a cube on a 30 degree incline with mu 0.5 slides 0.5 g (sin30 - 0.5 cos30) t^2 within 2 %") {
  InclineScene s = buildIncline(0.5);
  const InclineMetrics m = runIncline(s);
  MESSAGE("incline mu 0.5: displacement " << m.displacement << " m (analytic " << m.analytic << ", error "
                                          << m.error * 100 << " %)");
  CHECK(m.finite);
  CHECK(m.analytic == doctest::Approx(1.3143).epsilon(1e-4));
  CHECK(std::abs(m.error) < 0.02);
  // It slides along the slope, staying on the surface: no motion along the normal or sideways beyond 1 mm.
  const Vec3 d = s.cube->getPosition() - s.cubeInitial;
  CHECK(std::abs(d.dot(s.slopeNormal)) < 1e-3);
  CHECK(std::abs(d.y()) < 1e-3);
}

}  // TEST_SUITE
