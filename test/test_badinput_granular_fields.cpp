// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Bad input at the GranularFieldPostProcessor API boundary: std::invalid_argument naming the parameter and the
// value, and the object unchanged.
#include <doctest/doctest.h>

#include <cmath>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "scree/core/granular_body_system.h"
#include "scree/model/granular_field_post_processor.h"

#include "test_badinput.h"

using namespace scree;
using namespace scree::test;

TEST_SUITE("badinput.granular_fields") {

TEST_CASE("constructor rejects zero voxel counts and non-positive or non-finite volumes") {
  GranularBodySystem gbs;
  expectInvalid([&] { GranularFieldPostProcessor(gbs, {0, 3, 3}, Vec3(1, 1, 1)); }, {"shape[0]", "0"});
  expectInvalid([&] { GranularFieldPostProcessor(gbs, {3, 3, 0}, Vec3(1, 1, 1)); }, {"shape[2]", "0"});
  expectInvalid([&] { GranularFieldPostProcessor(gbs, {4096, 4096, 4096}, Vec3(1, 1, 1)); }, {"shape", "4096"});
  for (Real bad : {kNaN, kInf, -1.0, 0.0}) {
    expectInvalid([&] { GranularFieldPostProcessor(gbs, {3, 3, 3}, Vec3(1, bad, 1)); }, {"volume.y"});
  }
}

TEST_CASE("placement setters reject non-finite values and keep the old placement") {
  GranularBodySystem gbs;
  GranularFieldPostProcessor gpp(gbs, {2, 2, 2}, Vec3(1, 1, 1));
  gpp.setPosition(Vec3(1, 2, 3));
  expectInvalid([&] { gpp.setPosition(Vec3(kNaN, 0, 0)); }, {"centre", "nan"});
  expectInvalid([&] { gpp.setRotation(Quat(0, 0, 0, 0)); }, {"rotation"});
  expectInvalid([&] { gpp.setTransform(Transform{Vec3(0, kInf, 0), Quat::Identity()}); }, {"transform.p", "inf"});
  CHECK(gpp.getTransform().p == Vec3(1, 2, 3));
  CHECK(gpp.getTransform().q.isApprox(Quat::Identity()));
}

TEST_CASE("fields: null, unknown custom buffer, CUSTOM by type, unknown names") {
  GranularBodySystem gbs;
  GranularFieldPostProcessor gpp(gbs, {2, 2, 2}, Vec3(1, 1, 1));
  expectInvalid([&] { gpp.addField(GranularFieldRef()); }, {"field", "null"});
  expectInvalid([&] { gpp.addField(std::make_shared<GranularCustomBufferField>("porosity")); }, {"\"porosity\""});
  expectInvalid([&] { gpp.addField(GranularField::CUSTOM); }, {"type"});
  expectInvalid([&] { GranularCustomBufferField(""); }, {"bufferName"});
  CHECK(gpp.getFields().empty());
  expectInvalid([&] { gpp.getField("mass"); }, {"\"mass\"", "none"});
  expectInvalid([&] { gpp.getField(GranularField::MASS); }, {"type"});
  // A field object belongs to one post-processor.
  auto mass = gpp.addField(GranularField::MASS);
  GranularFieldPostProcessor other(gbs, {3, 3, 3}, Vec3(1, 1, 1));
  expectInvalid([&] { other.addField(mass); }, {"\"mass\"", "another post-processor"});
  CHECK(other.getFields().empty());
  // Adding the same type again returns the existing field.
  CHECK(gpp.addField(std::make_shared<GranularMassField>()) == mass);
  CHECK(gpp.getFields().size() == 1);
  expectInvalid([&] { mass->getValue(2, 0, 0); }, {"i", "2"});
  expectInvalid([&] { mass->getValue(0, 0, 0, 1); }, {"c", "1"});
}

TEST_CASE("a custom buffer removed after addField is reported by calculateFields") {
  GranularBodySystem gbs;
  gbs.addCustomBufferReal("c");
  gbs.createParticle(Vec3::Zero(), 0.1);
  GranularFieldPostProcessor gpp(gbs, {2, 2, 2}, Vec3(1, 1, 1));
  gpp.addField(std::make_shared<GranularCustomBufferField>("c"));
  gpp.calculateFields();
  gbs.removeCustomBufferReal("c");
  expectInvalid([&] { gpp.calculateFields(); }, {"\"c\"", "removed"});
  CHECK(gpp.getNumCalculations() == 1);
}

TEST_CASE("a custom field may not take a built-in field's name") {
  GranularBodySystem gbs;
  gbs.addCustomBufferReal("velocity");
  GranularFieldPostProcessor gpp(gbs, {2, 2, 2}, Vec3(1, 1, 1));
  expectInvalid([&] { gpp.addField(std::make_shared<GranularCustomBufferField>("velocity")); }, {"\"velocity\"", "built-in"});
  CHECK(gpp.getFields().empty());
}

TEST_CASE("a particle with a non-finite state is named instead of spreading NaN") {
  GranularBodySystem gbs;
  GranularFieldPostProcessor gpp(gbs, {2, 2, 2}, Vec3(1, 1, 1));
  auto velocity = gpp.addField(GranularField::VELOCITY);
  gbs.createParticle(Vec3(0.1, 0.1, 0.1), 0.05, Vec3(1, 0, 0));
  const size_t bad = gbs.createParticle(Vec3(-0.2, 0.1, 0.1), 0.05);
  gpp.calculateFields();
  const std::vector<Real> before(velocity->getFieldData(), velocity->getFieldData() + velocity->getDataSize());
  // A blown-up solver writes the dense arrays directly (the setters would refuse NaN).
  gbs.velocities()[gbs.denseIndex(bad)] = Vec3(std::nan(""), 0, 0);
  bool thrown = false;
  try {
    gpp.calculateFields();
  } catch (const std::runtime_error& e) {
    thrown = true;
    const std::string what = e.what();
    CHECK(what.find("particle id " + std::to_string(bad)) != std::string::npos);
    CHECK(what.find("non-finite") != std::string::npos);
  }
  CHECK(thrown);
  CHECK(std::vector<Real>(velocity->getFieldData(), velocity->getFieldData() + velocity->getDataSize()) == before);
}

TEST_CASE("exports reject a bad axis or index") {
  GranularBodySystem gbs;
  GranularFieldPostProcessor gpp(gbs, {2, 3, 4}, Vec3(1, 1, 1));
  gpp.addField(GranularField::MASS);
  expectInvalid([&] { gpp.writeCsvSlice("unused.csv", 3, 0); }, {"axis", "3"});
  expectInvalid([&] { gpp.writeCsvSlice("unused.csv", 1, 3); }, {"index", "3"});
  CHECK_THROWS_AS(gpp.writeVti("/nonexistent-directory/x.vti"), std::runtime_error);
}

TEST_CASE("the step listener rejects a null post-processor and a zero interval") {
  GranularBodySystem gbs;
  auto gpp = std::make_shared<GranularFieldPostProcessor>(gbs, GranularFieldPostProcessor::Shape{2, 2, 2}, Vec3(1, 1, 1));
  expectInvalid([&] { GranularFieldStepListener(nullptr, 1); }, {"postProcessor"});
  expectInvalid([&] { GranularFieldStepListener(gpp, 0); }, {"everyNSteps", "0"});
}

}  // TEST_SUITE
