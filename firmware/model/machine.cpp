// What the cycle asks of a machine: its limits in q_a order. Nothing here reads a file (the reader is
// machine_reader.cpp).
#include "model/machine.hpp"

#include <limits>

namespace exc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

}  // namespace

Vec4 Machine::q_min() const { return Vec4(-kInf, boom.min_length, arm.min_length, bucket.min_length); }
Vec4 Machine::q_max() const { return Vec4(kInf, boom.max_length, arm.max_length, bucket.max_length); }
Vec4 Machine::effort_min() const {
  return Vec4(swing.min_torque, boom.min_force, arm.min_force, bucket.min_force);
}
Vec4 Machine::effort_max() const {
  return Vec4(swing.max_torque, boom.max_force, arm.max_force, bucket.max_force);
}
Vec4 Machine::speed_max() const {
  return Vec4(swing.max_speed, boom.max_speed, arm.max_speed, bucket.max_speed);
}

HydraulicParameters without_dry_friction_and_leakage(HydraulicParameters p) {
  p.seal_preload.setZero();
  p.seal_pressure_friction.setZero();
  p.swing_breakaway_pressure = 0;
  p.piston_leakage.setZero();
  p.spool_leakage.setZero();
  p.swing_drain_leakage = 0;
  return p;
}

}  // namespace exc
