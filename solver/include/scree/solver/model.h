// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Model: the one way a model (terrain, tire, granular field post-processor, suction gripper, or a user's own)
// joins and leaves a Simulation.
//
//   sim.add(model)     records the model, then calls model->onAdd(sim); the model installs what it needs with
//                      addOwned(...) (bodies, static geometries, constraints, step and contact listeners).
//   sim.remove(model)  calls model->onRemove(sim), then removes everything addOwned installed, newest first,
//                      so the simulation is left as it was before the model was added.
//
// A model belongs to at most one simulation at a time (adding it to a second one throws). Items a model adds
// while it is installed (a gripper's new cup) go through addOwned too and are removed with it. Adding the same
// model twice is a no-op, as for bodies and constraints.
//
// A class that is both a Constraint and a Model (TwoBodyTireModel) is added through the Model path:
// Simulation::add(std::shared_ptr<T>) with T derived from Model picks add(ModelRef), and the model adds itself
// as a constraint with addOwned(selfAs<Constraint>()).
#pragma once

#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "scree/collide/geometry.h"
#include "scree/core/listeners.h"
#include "scree/core/rigid_body.h"
#include "scree/solver/constraint.h"

namespace scree {

class Simulation;

class Model : public std::enable_shared_from_this<Model> {
 public:
  explicit Model(std::string name = "") : modelName_(std::move(name)) {}
  virtual ~Model() = default;
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  const std::string& getModelName() const { return modelName_; }
  void setModelName(const std::string& name) { modelName_ = name; }
  /// The simulation the model is installed in, or nullptr.
  Simulation* getSimulation() const { return sim_; }
  /// Number of items (bodies, geometries, constraints, listeners) the model has installed.
  size_t getNumOwned() const { return owned_.size(); }

 protected:
  /// Called by Simulation::add after the model is recorded: install what the model needs with addOwned().
  virtual void onAdd(Simulation& sim) = 0;
  /// Called by Simulation::remove before the owned items are removed (newest first). Default: nothing.
  virtual void onRemove(Simulation& /*sim*/) {}

  /// Adds the item to the model's simulation and remembers it for removal. Outside a simulation: nothing
  /// (onAdd installs everything when the model is added). Null throws std::invalid_argument.
  void addOwned(RigidBodyRef body);
  void addOwned(GeometryRef staticGeometry);
  void addOwned(ConstraintRef constraint);
  void addOwned(StepEventListenerRef listener);
  void addOwned(ContactEventListenerRef listener);
  /// Removes one owned item from the simulation and forgets it. False when it is not owned.
  bool removeOwned(const RigidBodyRef& body);
  bool removeOwned(const GeometryRef& staticGeometry);
  bool removeOwned(const ConstraintRef& constraint);
  bool removeOwned(const StepEventListenerRef& listener);
  bool removeOwned(const ContactEventListenerRef& listener);

  /// This model as a shared_ptr of one of its other bases (a model that is itself a constraint or listener).
  template <class T>
  std::shared_ptr<T> selfAs() {
    return std::dynamic_pointer_cast<T>(shared_from_this());
  }

 private:
  friend class Simulation;
  using Item = std::variant<RigidBodyRef, GeometryRef, ConstraintRef, StepEventListenerRef, ContactEventListenerRef>;
  void attach(Simulation& sim);
  void detach(Simulation& sim);
  template <class Ref>
  void addItem(Ref ref, const char* param);
  template <class Ref>
  bool removeItem(const Ref& ref);

  std::string modelName_;
  Simulation* sim_ = nullptr;
  std::vector<Item> owned_;
};
using ModelRef = std::shared_ptr<Model>;

}  // namespace scree
