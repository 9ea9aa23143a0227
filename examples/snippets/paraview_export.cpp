// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The C++ fragment of docs/paraview.md, between "// [doc]" and "// [/doc]": a small terrain, a few falling
// particles and their granular fields exported for ParaView into out/ (60 frames).
#include <cstdio>
#include <scree/io/vtk_export.h>
#include <scree/scree.h>
using namespace scree;

int main() {
  Simulation sim;
  auto hf = std::make_shared<HeightField>(33, 33, 3.2, 3.2);
  auto terrain = std::make_shared<Terrain>(hf);
  sim.add(terrain);
  for (int i = 0; i < 20; ++i) sim.getGranularBodySystem().createParticle(Vec3(0.05 * i - 0.5, 0, 0.5), 0.02);
  auto postProcessor = std::make_shared<GranularFieldPostProcessor>(
      sim.getGranularBodySystem(), GranularFieldPostProcessor::Shape{8, 8, 4}, Vec3(2, 2, 1));
  postProcessor->addField(GranularField::MASS);

  // [doc]
  scree::io::VtkExporter vtk("out", "scene");  // creates out/; std::invalid_argument if it cannot write there
  vtk.addTerrain(*terrain);                     // optional: the height field as a structured grid
  vtk.addGranularFields(*postProcessor);        // optional: the voxel fields as image data
  for (int i = 0; i < 600; ++i) {
    sim.stepForward();
    if (i % 10 == 0) { postProcessor->calculateFields(); vtk.writeFrame(sim, sim.getTimeStamp()); }
  }
  vtk.close();                                  // writes out/scene.pvd (the destructor does it too)
  // [/doc]
  std::printf("wrote out/scene.pvd\n");
}
