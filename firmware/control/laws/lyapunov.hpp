#pragma once
// The continuous Lyapunov equation A^T P + P A + Q = 0 (paper eqs. 24-25) for the error dynamics
// x = [e; ed], xd = A x, A = [0 I; -K_p -K_v], and for the same with integral action,
// z = [int e; e; ed], A = [0 I 0; 0 0 I; -K_i -K_p -K_v]. Solved once at start-up through the
// Kronecker form (I (x) A^T + A^T (x) I) vec(P) = -vec(Q) with an n^2 x n^2 LU (may allocate).
#include "model/types.hpp"

namespace exc::control {

// A of the error dynamics for diagonal gains (model.md s.6: K_p on e, K_v on ed).
Mat8 error_dynamics_matrix(const Vec4& kp, const Vec4& kv);
// The same with the integral of e as a state (K_i on int e).
Mat12 integral_error_dynamics_matrix(const Vec4& kp, const Vec4& kv, const Vec4& ki);

// P for a Hurwitz A and symmetric Q; symmetrised. Returns false if A is not Hurwitz (no SPD P).
bool solve_lyapunov(const Mat8& A, const Mat8& Q, Mat8& P);
bool solve_lyapunov(const Mat12& A, const Mat12& Q, Mat12& P);

}  // namespace exc::control
