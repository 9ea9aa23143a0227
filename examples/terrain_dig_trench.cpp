// terrain_dig_trench: a kinematic bucket digs a 0.6 m trench in a Terrain, lifts the soil, dumps it by turning
// its tip down, and the heap merges back into the height field. Prints per phase the particles created and
// merged, the live particles, and the soil-volume ledger (its total stays constant: digging moves soil
// heightField -> pending -> particles -> heightField, it never creates or loses any).
//
//   build/examples/terrain_dig_trench [DIR]   with DIR: after each phase writes DIR/<phase>_surface.dat (x, z of
//   the terrain surface along y = 0), DIR/<phase>_particles.dat (x, z of the particles with |y| < 0.15 m) and
//   DIR/<phase>_bucket.dat (the blade and back plate outlines in the x-z plane); docs/terrain/dig.gp plots them.
#include <cmath>
#include <cstdio>
#include <string>

#include <scree/scree.h>

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : "";
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
    if (!dir.empty()) {
      // Side view (x-z plane through y = 0) of this phase's end: surface, particles, bucket.
      const std::string base = dir + "/" + p.name;
      if (std::FILE* f = std::fopen((base + "_surface.dat").c_str(), "w")) {
        for (size_t i = 0; i < n; ++i) {
          const Vec3 v = terrain->getGeometry()->getTransform().apply(hf->getVertex(i, n / 2));
          std::fprintf(f, "%.4f %.4f\n", v.x(), v.z());
        }
        std::fclose(f);
      }
      if (std::FILE* f = std::fopen((base + "_particles.dat").c_str(), "w")) {
        sim.getGranularBodySystem().forEachParticle([&](size_t id) {
          const Vec3 x = sim.getGranularBodySystem().getPosition(id);
          if (std::abs(x.y()) < 0.15) std::fprintf(f, "%.4f %.4f\n", x.x(), x.z());
        });
        std::fclose(f);
      }
      if (std::FILE* f = std::fopen((base + "_bucket.dat").c_str(), "w")) {
        for (const GeometryRef& g : bucket->getGeometries()) {
          const Vec3 he = static_cast<const Box&>(*g->getShape()).getHalfExtents();
          for (int k = 0; k <= 4; ++k) {
            const Real sx = (k == 1 || k == 2) ? 1 : -1, sz = (k >= 2 && k <= 3) ? 1 : -1;
            const Vec3 c = g->getTransform().apply(Vec3(sx * he.x(), 0, sz * he.z()));
            std::fprintf(f, "%.4f %.4f\n", c.x(), c.z());
          }
          std::fprintf(f, "\n");
        }
        std::fclose(f);
      }
    }
  }
  return 0;
}
