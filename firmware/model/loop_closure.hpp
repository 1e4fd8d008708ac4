#pragma once
// Loop closure (paper Table 2, model.md s.4): passive joints from active ones, in closed form
// (two triangles and the bucket four-bar) and by Newton iteration (the general path).
#include "workspace.hpp"

namespace exc {

// h(q): the 8 cut-pin residuals (x and z in the swing plane of point_p - point_s per loop).
void loop_residual(const Model& model, const Vec12& q, Vec8& h);

// Closed form: fills ws.q from q_a (the passive angles unless skipped) and each pin's cos, sin.
// Reports no_assembly (with the loop) when a triangle cannot close, near_toggle when the four-bar's
// transmission is below tolerance.
ModelReport solve_loop_closure(const Model& model, Workspace& ws, const Vec4& q_a,
                               PassiveAngles angles = PassiveAngles::computed);

// Newton iteration on h(q_a, q_p) = 0 from ws.q as the initial guess; same reports.
ModelReport solve_loop_closure_newton(const Model& model, Workspace& ws, const Vec4& q_a,
                                      int max_iterations = 30, double tolerance = 1e-12);

}  // namespace exc
