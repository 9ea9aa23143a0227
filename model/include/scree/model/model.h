// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The model layer (after the AGX agxModel chapter): models built from the public pieces of the layers below
// (bodies, geometries, constraints, step and contact listeners) that join and leave a simulation as one unit.
//
// Every model is a scree::Model (scree/solver/model.h), the one way a model is added to a simulation:
//   sim.add(model)     Model::onAdd installs what the model needs with addOwned(...);
//   sim.remove(model)  removes everything it installed, leaving the simulation's lists as they were.
// A class that is also a Constraint or a StepEventListener is still added through the Model path: Simulation's
// add/remove templates pick it for any type derived from Model.
//
// The models (each header says what its hook installs):
//   TwoBodyTireModel           (two_body_tire_model.h)   its own constraint and a friction-direction listener
//   SuctionGripper             (suction_gripper.h)       itself as a step listener, a sensor listener, the holder
//                                                        and cup bodies it added, the cups' lock joints
//   GranularFieldStepListener  (granular_field_post_processor.h)  itself as a step listener
// A terrain will be the fourth user of the hook.
//
// Including this header includes the whole layer.
#pragma once

#include "scree/model/granular_field_post_processor.h"
#include "scree/model/suction_gripper.h"
#include "scree/model/two_body_tire_model.h"
#include "scree/solver/model.h"
