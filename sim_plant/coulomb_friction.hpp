#pragma once
// Dry (Coulomb and Stribeck) friction of the hydraulic functions as impulses after the integrator's
// step (docs/plant.md, "Friction and leakage"). A sign(v) force held over a step chatters about
// v = 0 and a stiff tanh is unstable at 1 ms for the light bucket; the impulse form sticks exactly.
// Over a substep of length h, with W = (M_a + J_t^T M_t J_t)^-1 the inverse effective mass the step
// used, u the velocities it reached without dry friction and b_i = h F_i the largest dry-friction
// impulse of function i (its Stribeck force at the substep's starting speed, the static friction at
// rest), the impulses lambda give v = u - W lambda with, for every i,
//   stuck:    |lambda_i| < b_i and v_i = 0 (what it takes to hold i is below its static friction), or
//   slipping: lambda_i = b_i sign(v_i) (friction opposes the motion it does not stop);
// the Coulomb law for coupled coordinates at fixed normal forces (a box-constrained LCP), solved by
// projected Gauss-Seidel: each sweep sets every lambda_i to the impulse that would stop i, clamped to
// +-b_i. W is symmetric positive definite, so the sweeps converge to the unique solution. Each
// impulse along W e_i takes kinetic energy only (the inelastic contact of the end stops, plant.cpp).
#include "model/types.hpp"

namespace exc::plant {

struct DryFrictionImpulses {
  Vec4 impulse = Vec4::Zero();   // N m s, N s: v = u - W impulse
  Vec4 velocity = Vec4::Zero();  // v after them; exactly 0 where stuck
  unsigned stuck = 0;            // bit i: function i held by its static friction
  int sweeps = 0;                // Gauss-Seidel sweeps used
};

// inverse_mass W (SPD), free_velocity u, bound b (>= 0; 0: no dry friction on that function); the
// sweeps start from `guess` clamped to the bounds (the last substep's impulses: a machine held or
// slipping as before needs one sweep).
DryFrictionImpulses dry_friction_impulses(const Mat4& inverse_mass, const Vec4& free_velocity, const Vec4& bound,
                                          const Vec4& guess = Vec4::Zero());
// The same with each impulse in [lower_i, upper_i] (lower <= 0 <= upper; both 0: no friction there).
// A function pressed on an end stop takes the stop's reaction in the same solve: one side unbounded
// (+inf on its upper stop, -inf on its lower), so the friction of the functions coupled to it acts on
// the motion the stop leaves them. Stuck where the impulse lies strictly inside its interval.
DryFrictionImpulses dry_friction_impulses(const Mat4& inverse_mass, const Vec4& free_velocity, const Vec4& lower,
                                          const Vec4& upper, const Vec4& guess);

}  // namespace exc::plant
