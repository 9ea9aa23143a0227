// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The stages of Simulation::stepForward (solver-private), in step order. Each does what its name says and is
// timed on its own (StepStats); the file that defines it is named after it.
//
//   listeners (PRE_COLLIDE)   step_listeners.cpp
//   syncGeometries            collide_stage.cpp   geometries added to / removed from bodies reach the space
//   collideGeometries         collide_stage.cpp   Space: broadphase + narrowphase -> contacts
//   collideParticles          collide_stage.cpp   ParticleCollider -> particle contact lists (destroys deferred)
//   resolveContactMaterials   collide_stage.cpp   contact material and friction model per geometry contact
//   runContactEvents          contact_events.cpp  impact / contact / separation listeners
//   listeners (PRE_STEP)      step_listeners.cpp
//   applyForces               forces.cpp          free velocities v + h M^-1 f (bodies and particles)
//   buildContactRows          contact_rows.cpp    normal, friction and rolling rows with warm start
//   buildConstraintRows       constraint_rows.cpp joints and models, separation report
//   buildParticleRows         contact_rows.cpp         the particle stage's contact units (granular_stage.h)
//   solve                     solve_stage.cpp     PGS / hybrid direct-iterative / particle sweeps, shock pass
//   integrateMotion           integration.cpp     positions and rotations from the solved velocities
//   storeResults              store_results.cpp   contact forces, warm-start caches, constraint results
//   projectPositions          position_projection.cpp
//   checkFinite               finiteness.cpp      non-finite bodies restored and stopped
//   listeners (POST_STEP)     step_listeners.cpp
//   endParticleDeferral       step_listeners.cpp  particle destroys deferred since collision applied
#pragma once

#include "simulation_state.h"

namespace scree::detail {

void runStepListeners(SimulationState& s, int mask);
void syncGeometries(SimulationState& s);
void collideGeometries(SimulationState& s);
void collideParticles(SimulationState& s);
void resolveContactMaterials(SimulationState& s);
void runContactEvents(SimulationState& s);
/// The particle part of the contact events stage (ContactEventListener::particleContacts); run by
/// runContactEvents after the geometry events.
void runParticleContactEvents(SimulationState& s);
void applyForces(SimulationState& s);
void buildContactRows(SimulationState& s);
void buildConstraintRows(SimulationState& s);
void buildParticleRows(SimulationState& s);
void solve(SimulationState& s);
/// The partitioned work of a step (Solver::setUsePartitionedSweeps; sweep_threads.h) runs from the contact row
/// build to the store: beginPartitionedWork (called by buildContactRows) picks its thread count for the step and,
/// with the adaptive count, starts its clock; endPartitionedWork (after storeResults) hands the span's wall time to
/// the choice when the step's sweeps were partitioned. solve_stage.cpp.
void beginPartitionedWork(SimulationState& s);
void endPartitionedWork(SimulationState& s);
void integrateMotion(SimulationState& s);
void storeResults(SimulationState& s);
void projectPositions(SimulationState& s);
void checkFinite(SimulationState& s);
void endParticleDeferral(SimulationState& s);

// Helpers shared by stages.
/// s.particleGeometrySides from the particle-geometry contact list (collide_stage.cpp).
void describeParticleGeometrySides(SimulationState& s);
/// Support levels and the shock-propagation order of the rows (shock_order.cpp).
void buildShockOrder(SimulationState& s);
/// s.geomK[b] = sum over direct-set rows on body b of |lambda / h| |r|; false when all are zero
/// (geometric_stiffness.cpp).
bool computeGeometricStiffness(SimulationState& s);
/// Adds the geometric stiffness to the inertia the solve sees (Solver::setUseGeometricStiffness).
void addGeometricStiffness(SimulationState& s);

}  // namespace scree::detail
