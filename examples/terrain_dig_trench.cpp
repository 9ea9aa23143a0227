// terrain_dig_trench: a kinematic bucket digs a 0.6 m trench in a Terrain, lifts the soil, dumps it by turning
// its tip down, and the heap merges back into the height field. Prints per phase the particles created and
// merged, the live particles, and the soil-volume ledger (its total stays constant: digging moves soil
// heightField -> pending -> particles -> heightField, it never creates or loses any).
#include <cmath>
#include <cstdio>

#include <scree/scree.h>

int main() {
  using namespace scree;
  Simulation sim;
  sim.setTimeStep(1.0 / 60);
  sim.setUniformGravity(Vec3(0, 0, -9.81));
  auto soil = std::make_shared<Material>("soil");
  soil->setDensity(1600);  // the bulk density: a particle's mass is 1600 kg/m^3 x the soil volume it carries
  soil->setRollingResistanceCoefficient(0.3);  // grains do not roll on forever (particles copy soil's parameters)

  // 2 x 2 m of soil 0.5 m thick, 0.05 m cells, its surface at z = 0.
  const size_t n = 41;
  auto hf = std::make_shared<HeightField>(n, n, 2.0, 2.0);
  hf->setHeights(std::vector<Real>(n * n, 0.5));
  auto terrain = std::make_shared<Terrain>(hf);
  terrain->getGeometry()->setMaterial(soil);
  terrain->getGeometry()->setPosition(Vec3(0, 0, -0.5));
  sim.add(terrain);
  terrain->getDataInterface().add(soil, 0, /*particleAdhesion*/ 0, /*deformability*/ 0);
  terrain->getParticleAttributes().setParticleRadius(0.02);  // <= getMaximumParticleRadius() = 0.05
  terrain->setMergeVelocity(0.1);

  // The bucket: a bottom plate tagged as the shovel (forward +x to its front edge, up +z = its thickness) and a
  // back plate, on a kinematic body driven by velocities.
  auto bucket = std::make_shared<RigidBody>("bucket");
  auto blade = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.2, 0.15, 0.01)), "blade");
  blade->setMaterial(soil);
  blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelUpProperty, Vec3(0, 0, 0.02));
  blade->getPropertyContainer().addPropertyVec3(Terrain::ShovelForwardProperty, Vec3(0.2, 0, 0));
  bucket->add(blade);
  auto back = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(0.01, 0.15, 0.1)), "back");
  back->setMaterial(soil);
  back->setLocalPosition(Vec3(-0.21, 0, 0.09));
  bucket->add(back);
  bucket->setMotionControl(RigidBody::KINEMATICS);
  bucket->setPosition(Vec3(-0.6, 0, 0.03));
  sim.add(bucket);
  std::printf("blade is a shovel: %s; particle volume %.3g m^3\n", terrain->isGeometryShovel(blade) ? "yes" : "no",
              terrain->getParticleVolume());

  struct Phase {
    const char* name;
    Real seconds;
    Vec3 v, w;
  };
  const Phase phases[] = {{"lower", 0.5, Vec3(0, 0, -0.16), Vec3::Zero()},
                          {"dig", 1.5, Vec3(0.4, 0, 0), Vec3::Zero()},
                          {"lift", 1.0, Vec3(0, 0, 0.4), Vec3::Zero()},
                          {"dump", 1.0, Vec3::Zero(), Vec3(0, 2.0, 0)},
                          {"settle", 6.0, Vec3::Zero(), Vec3::Zero()}};
  const Real total0 = terrain->getVolumeLedger().total();
  std::printf("%-7s %8s %8s %6s %12s %12s %12s %12s %10s\n", "phase", "created", "merged", "live", "heightField",
              "pending", "particles", "total", "drift");
  for (const Phase& p : phases) {
    bucket->setVelocity(p.v);
    bucket->setAngularVelocity(p.w);
    size_t created = 0, merged = 0;
    for (int i = 0; i < int(std::lround(p.seconds / sim.getTimeStep())); ++i) {
      sim.stepForward();
      created += terrain->getLastStepDigStats().particlesCreated;
      merged += terrain->getLastStepDigStats().particlesMerged;
    }
    const TerrainVolumeLedger& l = terrain->getVolumeLedger();
    std::printf("%-7s %8zu %8zu %6zu %12.6f %12.6f %12.6f %12.6f %10.1e\n", p.name, created, merged,
                sim.getGranularBodySystem().numParticles(), l.heightField, l.pending, l.particles, l.total(),
                (l.total() - total0) / total0);
  }
  return 0;
}
