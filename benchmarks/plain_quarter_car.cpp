#include "plain_quarter_car.h"

#include "vdyn/tire/tire_force.h"

namespace vdyn::bench {

using namespace SimTK;

namespace {
Body::Rigid body(const RigidBodyParams& b) {
  return Body::Rigid(MassProperties(b.mass_kg, Vec3(0), Inertia(b.inertia_kg_m2)));
}
Transform pin(const Vec3& p, const UnitVec3& axis) { return Transform(Rotation(axis, ZAxis), p); }

/// z''^2 of the chassis slider.
class AzSquared : public Measure_<Real>::Implementation {
 public:
  explicit AzSquared(const MobilizedBody& c) : Measure_<Real>::Implementation(0.0, 1), c_(c) {}
  Implementation* cloneVirtual() const override { return new AzSquared(*this); }
  int getNumTimeDerivativesVirtual() const override { return 0; }
  Stage getDependsOnStageVirtual(int) const override { return Stage::Acceleration; }
  void calcCachedValueVirtual(const State& s, int, Real& v) const override {
    const Real a = c_.getOneUDot(s, 0);
    v = a * a;
  }

 private:
  MobilizedBody c_;
};
class AzSquaredMeasure : public Measure_<Real> {
 public:
  AzSquaredMeasure(Subsystem& sub, const MobilizedBody& c)
      : Measure_<Real>(sub, new AzSquared(c), AbstractMeasure::SetHandle()) {}
};
}  // namespace

PlainQuarterCar::PlainQuarterCar(const QuarterCarParams& qp) : matter_(system_), forces_(system_) {
  Force::Gravity(forces_, matter_, -UnitVec3(ZAxis), qp.gravity_m_per_s2);
  const Rotation R(UnitVec3(ZAxis), XAxis);
  chassis_ = MobilizedBody::Slider(matter_.Ground(), Transform(R), Body::Rigid(MassProperties(qp.chassis_mass_kg, Vec3(0), Inertia(1, 1, 1))), Transform(R));
  DoubleWishboneParams p = qp.corner;
  p.upper_pivot.child_point_m[2] += qp.upper_pivot_offset_m;
  p.upper_pivot.child_axis_point_m[2] += qp.upper_pivot_offset_m;
  MobilizedBody::Pin lower(chassis_, pin(p.lower_pivot.parent_point_m, p.lower_pivot.axis()), body(p.lower_arm),
                           pin(p.lower_pivot.child_point_m, p.lower_pivot.axis()));
  MobilizedBody::Ball knuckle(lower, Transform(p.lower_ball.parent_point_m), body(p.knuckle),
                              Transform(p.lower_ball.child_point_m));
  MobilizedBody::Pin upper(chassis_, pin(p.upper_pivot.parent_point_m, p.upper_pivot.axis()), body(p.upper_arm),
                           pin(p.upper_pivot.child_point_m, p.upper_pivot.axis()));
  const UnitVec3 spin(p.wheel_spin_axis);
  MobilizedBody::Pin wheel(knuckle, pin(Vec3(0), spin), body(p.wheel), pin(Vec3(0), spin));
  Constraint::Ball(upper, p.upper_ball.parent_point_m, knuckle, p.upper_ball.child_point_m);
  if (qp.steer_lock) Constraint::ConstantAngle(chassis_, UnitVec3(XAxis), knuckle, spin);
  Force::TwoPointLinearSpring(forces_, chassis_, p.spring_chassis_point_m, lower, p.spring_arm_point_m,
                              p.spring_stiffness_N_per_m, p.spring_free_length_m);
  Force::TwoPointLinearDamper(forces_, chassis_, p.spring_chassis_point_m, lower, p.spring_arm_point_m,
                              p.damper_N_s_per_m);
  Force::Custom(forces_, new TireForceImpl(wheel, makeTireModel(qp.tire.plugin, ParamReader::fromJson(qp.tire.params, qp.tire.where)), makeRoad(qp.road), spin));
  psi_ = Measure::Integrate(forces_, AzSquaredMeasure(forces_, chassis_), Measure::Zero(forces_));
  system_.realizeTopology();
}

double PlainQuarterCar::run(const Vector& q0, double t_end, double report, const std::string& method,
                            double accuracy, std::vector<double>* az, int* steps) {
  State s = system_.getDefaultState();
  s.updQ() = q0;
  s.updU() = 0;
  if (method != "rk_merson") throw Error("plain quarter car: only rk_merson is written out");
  auto integ = std::make_unique<RungeKuttaMersonIntegrator>(system_);
  integ->setAccuracy(accuracy);
  integ->setConstraintTolerance(1e-10);
  integ->setFinalTime(t_end);
  integ->initialize(s);
  if (az) az->clear();
  State work = s;  // sampling workspace: only t, q, u, z are copied per sample
  for (int k = 0;; ++k) {
    const double t = std::min(t_end, k * report);
    if (k > 0) integ->stepTo(t);
    if (az) {
      const State& is = integ->getState();
      work.setTime(is.getTime());
      work.updQ() = is.getQ();
      work.updU() = is.getU();
      work.updZ() = is.getZ();
      system_.realize(work, Stage::Acceleration);
      az->push_back(chassis_.getOneUDot(work, 0));
    }
    if (t >= t_end - 1e-12) break;
  }
  if (steps) *steps = integ->getNumStepsTaken();
  return psi_.getValue(integ->getState());
}

}  // namespace vdyn::bench
