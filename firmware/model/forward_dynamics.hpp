#pragma once
// Forward dynamics in two formulations (model.md s.4).
#include "closed_chain.hpp"

namespace exc {

// Independent coordinates: (M_a + J_t^T M_t J_t) qdd_a = tau_a - h_a - J_t^T (f + M_t rhodd_bias).
// Runs update_closed_chain itself.
ModelReport forward_dynamics(const Model& model, Workspace& ws, const Vec4& q_a, const Vec4& qd_a,
                             const Vec4& tau_a, const TipLoad& load, Vec4& qdd_a);

// Augmented form (eq. 8) on all 12 tree coordinates, which need not satisfy h(q) = 0 exactly:
// [M_r H^T; H 0] [qdd; -lambda] = [tau - C qd - g - J^T f; -Hd qd - 2 alpha h_dot - beta^2 h]
// (Baumgarte with alpha, beta >= 0; zero gives eq. 8 as written). tau_a acts on the active joints.
ModelReport forward_dynamics_augmented(const Model& model, Workspace& ws, const Vec12& q,
                                       const Vec12& qd, const Vec4& tau_a, const TipLoad& load,
                                       double baumgarte_alpha, double baumgarte_beta, Vec12& qdd,
                                       Vec8& lambda);

}  // namespace exc
