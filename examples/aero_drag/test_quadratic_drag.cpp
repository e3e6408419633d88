// Unit test of the quadratic drag force (no scene file, no vehicle): a free body
// of mass m launched at v0 along x without gravity has m v' = -c v^2, so
// v(t) = v0 / (1 + c v0 t / m) (docs/equations.md, "Aerodynamic drag"), and the
// drag's work equals the change of kinetic energy. Prints both errors; exit 1
// when either exceeds its bound.
#include <cmath>
#include <cstdio>
#include <memory>

#include "quadratic_drag.h"
#include "vdyn/core/error.h"
#include "vdyn/core/scene.h"
#include "vdyn/core/simulation.h"

int main() {
  try {
    const double m = 1000.0, v0 = 30.0, t_end = 20.0;
    vdyn::Scene scene;
    SimTK::Body::Rigid body(SimTK::MassProperties(m, SimTK::Vec3(0), SimTK::UnitInertia(1, 1, 1)));
    SimTK::MobilizedBody::Free free(scene.updMatter().Ground(), body);
    scene.addBody("chassis", free);
    vdyn_example::QuadraticDragParams p;
    p.record_work = true;
    scene.addPlugin(std::make_unique<vdyn_example::QuadraticDragPlugin>("aero", p));
    SimTK::State s = scene.getDefaultState();
    free.setUToFitLinearVelocity(s, SimTK::Vec3(v0, 0, 0));
    const double E0 = scene.evalOutput("aero.mechanical_energy_J", s);

    vdyn::SimulationSettings sim;
    sim.t_end_s = t_end;
    sim.integrator.accuracy = 1e-8;
    vdyn::simulate(scene, s, sim);

    const double c = p.coefficient_kg_per_m();
    const double v = free.getBodyOriginVelocity(s)[0];
    const double closed = v0 / (1 + c * v0 * t_end / m);
    const double work = scene.evalOutput("aero.work_J", s);
    const double dE = scene.evalOutput("aero.mechanical_energy_J", s) - E0;
    const double speedError = std::abs(v - closed) / closed;
    const double energyError = std::abs(dE - work) / std::abs(work);
    std::printf("free body: v(%g s) = %.9f m/s, closed form %.9f m/s, relative error %.2e (bound 1e-6)\n", t_end, v,
                closed, speedError);
    std::printf("free body: drag work %.6f J, kinetic energy change %.6f J, relative error %.2e (bound 1e-6)\n", work,
                dE, energyError);
    return speedError < 1e-6 && energyError < 1e-6 ? 0 : 1;
  } catch (const vdyn::Error& e) {
    std::fprintf(stderr, "test_quadratic_drag: error: %s\n", e.what());
    return 1;
  }
}
