// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Model add/remove hook (see scree/solver/model.h) and Simulation's model membership.
#include "scree/solver/model.h"

#include <algorithm>

#include "scree/core/errors.h"
#include "scree/solver/simulation.h"
#include "simulation_state.h"

namespace scree {

template <class Ref>
void Model::addItem(Ref ref, const char* param) {
  detail::requireNonNull("Model::addOwned", param, ref.get());
  if (!sim_) return;  // onAdd installs everything when the model is added
  for (const Item& it : owned_)
    if (const Ref* r = std::get_if<Ref>(&it); r && *r == ref) return;
  sim_->add(ref);
  owned_.emplace_back(std::move(ref));
}

template <class Ref>
bool Model::removeItem(const Ref& ref) {
  for (auto it = owned_.begin(); it != owned_.end(); ++it)
    if (const Ref* r = std::get_if<Ref>(&*it); r && *r == ref) {
      if (sim_) sim_->remove(ref);
      owned_.erase(it);
      return true;
    }
  return false;
}

void Model::addOwned(RigidBodyRef b) { addItem(std::move(b), "rigidBody"); }
void Model::addOwned(GeometryRef g) { addItem(std::move(g), "geometry"); }
void Model::addOwned(ConstraintRef c) { addItem(std::move(c), "constraint"); }
void Model::addOwned(StepEventListenerRef l) { addItem(std::move(l), "stepEventListener"); }
void Model::addOwned(ContactEventListenerRef l) { addItem(std::move(l), "contactEventListener"); }
bool Model::removeOwned(const RigidBodyRef& b) { return removeItem(b); }
bool Model::removeOwned(const GeometryRef& g) { return removeItem(g); }
bool Model::removeOwned(const ConstraintRef& c) { return removeItem(c); }
bool Model::removeOwned(const StepEventListenerRef& l) { return removeItem(l); }
bool Model::removeOwned(const ContactEventListenerRef& l) { return removeItem(l); }

void Model::attach(Simulation& sim) {
  sim_ = &sim;
  try {
    onAdd(sim);
  } catch (...) {
    detach(sim);  // leave the simulation as it was
    throw;
  }
}

void Model::detach(Simulation& sim) {
  onRemove(sim);
  for (auto it = owned_.rbegin(); it != owned_.rend(); ++it) std::visit([&](const auto& ref) { sim.remove(ref); }, *it);
  owned_.clear();
  sim_ = nullptr;
}

void Simulation::add(ModelRef model) {
  detail::requireNonNull("Simulation::add", "model", model.get());
  if (model->getSimulation() == this) return;
  if (model->getSimulation() != nullptr)
    throw std::invalid_argument("Simulation::add: model \"" + model->getModelName() +
                                "\" is invalid (already in another simulation)");
  s_->models.push_back(model);
  try {
    model->attach(*this);
  } catch (...) {
    s_->models.pop_back();
    throw;
  }
}

bool Simulation::remove(const ModelRef& model) {
  auto it = std::find(s_->models.begin(), s_->models.end(), model);
  if (it == s_->models.end()) return false;
  ModelRef keep = *it;  // the model may hold the last reference to itself through its items
  s_->models.erase(it);
  keep->detach(*this);
  return true;
}

}  // namespace scree
