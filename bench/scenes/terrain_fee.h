// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Digging-force scene against the fundamental earthmoving equation (FEE; docs/terrain.md, "Digging force against
// the fundamental earthmoving equation"): a flat blade of width w, rake alpha (from the horizontal), kinematic,
// its cutting edge held at depth d, pushed at constant speed along +x through cohesionless terrain that digs
// into particles. Used by examples/terrain_fee_study.cpp and test_model_terrain_fee.cpp.
//
// FEE (Reece 1964; McKyes 1985, ch. 4) for a cohesionless soil of unit weight gamma and friction angle phi,
// soil-blade friction angle delta and a surcharge q on the surface in front of the blade: the soil before the
// blade fails as a rigid wedge on a plane at beta from the horizontal, and the blade force, inclined delta from the
// blade normal, is
//     F = w (gamma d^2 N_gamma + q d N_q),   D = cos(alpha + delta) + sin(alpha + delta) cot(beta + phi),
//     N_gamma = (cot alpha + cot beta) / (2 D),   N_q = (cot alpha + cot beta) / D,
// with beta in (0, pi/2 - phi), D > 0, the one minimising F. The horizontal draft is H = F sin(alpha + delta).
#pragma once

#include <vector>

#include "scenes/scenes.h"

namespace scree::scenes {

/// The FEE factors at the failure angle that minimises F for the given surcharge ratio q / (gamma d).
struct FeeFactors {
  Real beta = 0, nGamma = 0, nQ = 0;
};
/// alpha, phi, delta in rad; surchargeRatio = q / (gamma d) >= 0 (0: no surcharge). Golden-section search of beta
/// to 1e-9 rad.
FeeFactors feeFactors(Real alpha, Real phi, Real delta, Real surchargeRatio = 0);
/// Horizontal draft H = w (gamma d^2 N_gamma + q d N_q) sin(alpha + delta), N.
Real feeHorizontalForce(Real alpha, Real phi, Real delta, Real gamma, Real d, Real w, Real q = 0);

struct TerrainFeeParams {
  Real depth = 0.05;          ///< d, m: the cutting edge below the original surface
  Real width = 0.3;           ///< w, m
  Real rake = 0.7853981633974483;  ///< alpha, rad from the horizontal
  Real bladeLength = 0.4;     ///< m, along the blade from the edge up
  Real bladeThickness = 0.002; ///< m (thin: a blunt edge presses particles smaller than it into the floor)
  Real speed = 0.2;           ///< m/s along +x
  Real travel = 0.3;          ///< m pushed
  Real start = -0.7;          ///< x of the cutting edge at t = 0, m (the field spans x in [-1, 1])
  Real cell = 0.02;           ///< height-field cell, m
  Real radius = 0.01;         ///< particle radius, m
  Real density = 1600;        ///< bulk density, kg/m^3
  Real soilFriction = 0.7;    ///< mu of soil (terrain and particles); phi = atan(mu)
  Real bladeFriction = 0.364; ///< mu of the blade-soil contacts; delta = atan(mu)
  Real rollingResistance = 0.3;
  Real youngsModulus = 1e7;   ///< N/m per contact point, soil and blade
  Real dt = 1.0 / 100;
  int iterations = 30;        ///< PGS iterations (rigid and particle sweeps)
  bool failureWedge = true;   ///< Terrain::setShovelFailureWedge: the cut takes the FEE failure wedge
};

struct TerrainFeeSample {
  Real travel = 0;      ///< m pushed so far
  Real force = 0;       ///< horizontal resistance on the blade, N (-x of the digging force)
  Real vertical = 0;    ///< z of the digging force, N
  Real heapHeight = 0;  ///< highest particle top in front of the blade above the original surface, m
  size_t particles = 0; ///< live terrain particles
  Real soilVolume = 0;  ///< soil carried by the terrain particles (the ledger's particle account), m^3
};

struct TerrainFeeResult {
  std::vector<TerrainFeeSample> samples;  ///< one per step
  Real meanForce = 0;       ///< mean horizontal force over the second half of the travel, N
  Real meanHeapHeight = 0;  ///< mean heap height over the same window, m
  Real meanSoilVolume = 0;  ///< mean soil volume in particles over the same window, m^3
  /// Least-squares line F(s) = force0 + pileSlope s through every step's horizontal force at travel s > 0.05 m:
  /// force0 is the force of a blade that has gathered no dug soil yet (the FEE's gamma d^2 w N_gamma term),
  /// pileSlope s the part that grows with the soil it pushes (the FEE's surcharge term), docs/terrain.md.
  Real force0 = 0;          ///< N
  Real pileSlope = 0;       ///< N/m
  Real ledgerDrift = 0;     ///< largest relative change of the volume ledger's total
};

TerrainFeeResult runTerrainFee(const TerrainFeeParams& p);

/// runTerrainFee at `phases` start positions p.start + k p.cell / phases (k = 0 .. phases - 1), spread over one
/// height-field cell, with every scalar and every step's sample averaged (ledgerDrift: the largest). Why: where
/// the edge starts relative to the grid and the particle lattice decides when each batch of particles is made,
/// and the force comes in pulses with it; one push's F0 (the line's intercept) moved by up to +-1.5 N (a factor
/// 2.7 at d = 3 cm) with a 5 mm shift of the start, enough to move one rake's fitted exponent of d by +-0.6
/// (docs/terrain.md, "The failure wedge"). The mean over the phases is the force of the cut, not of its lattice.
TerrainFeeResult runTerrainFeeAveraged(const TerrainFeeParams& p, int phases);

}  // namespace scree::scenes
