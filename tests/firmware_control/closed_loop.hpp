#pragma once
// A test plant built from the model itself (so the controller's model is exact): independent-
// coordinate forward dynamics with the paper's soil (eqs. 9-11: spring-damper-mass to an anchor that
// re-anchors at S_dist), integrated by semi-implicit Euler. Allocation-free after construction.
#include "control/laws/regressor.hpp"
#include "control/estimation/soil_contact.hpp"
#include "model/forward_dynamics.hpp"

namespace exc::control::sim {

struct SoilTruth {
  Vec6 theta = (Vec6() << 200, 5e3, 7e4, 200, 5e3, 7e4).finished();  // loam (machine.md)
  double terrain_height = 0;
  bool always_in_soil = false;  // contact everywhere (for the Lyapunov test)
  bool fixed_anchor = false;    // never re-anchor (for the Lyapunov test)
  Vec2 anchor = Vec2::Zero();
};

class ModelPlant {
 public:
  ModelPlant(const Model& model, const SoilTruth& soil) : model_(model), ws_(model), soil_(soil) {
    anchor_ = soil.anchor;
  }

  void reset(const Vec4& q, const Vec4& qd) {
    q_ = q;
    qd_ = qd;
    qdd_.setZero();
    in_soil_ = false;
    anchor_ = soil_.anchor;
  }

  // The soil load at the current state (updates contact and the anchor), as the model takes it.
  TipLoad soil_load() {
    update_closed_chain(model_, ws_, q_, qd_);
    const Vec2 rho = ws_.rho;
    const double depth = soil_.terrain_height - rho.y();
    const bool contact = soil_.always_in_soil || depth > 0;
    if (contact && !soil_.fixed_anchor) {
      if (!in_soil_ || (anchor_ - rho).norm() > shear_failure_distance(depth)) anchor_ = rho;
    }
    in_soil_ = contact;
    TipLoad load;
    if (contact) {
      const Vec6& th = soil_.theta;
      load.force = Vec2(th[1] * ws_.rhod.x() + th[2] * (rho.x() - anchor_.x()),
                        th[4] * ws_.rhod.y() + th[5] * (rho.y() - anchor_.y()));
      load.added_mass = Vec2(th[0], th[3]);
    }
    rho_ = rho;
    return load;
  }

  // Joint acceleration the plant would have under tau at the current state (no state change).
  Vec4 acceleration(const Vec4& tau, const TipLoad& load) {
    Vec4 qdd;
    forward_dynamics(model_, ws_, q_, qd_, tau, load, qdd);
    return qdd;
  }

  // One step: qdd from the current state, then semi-implicit Euler.
  bool step(const Vec4& tau, const TipLoad& load, double dt) {
    const ModelReport r = forward_dynamics(model_, ws_, q_, qd_, tau, load, qdd_);
    if (!r.ok()) return false;
    qd_ += qdd_ * dt;
    q_ += qd_ * dt;
    return true;
  }

  const Vec4& q() const { return q_; }
  const Vec4& qd() const { return qd_; }
  const Vec4& qdd() const { return qdd_; }
  bool in_soil() const { return in_soil_; }
  const Vec2& anchor() const { return anchor_; }
  const Vec2& rho() const { return rho_; }
  const SoilTruth& soil() const { return soil_; }

 private:
  const Model& model_;
  Workspace ws_;
  SoilTruth soil_;
  Vec4 q_ = Vec4::Zero(), qd_ = Vec4::Zero(), qdd_ = Vec4::Zero();
  bool in_soil_ = false;
  Vec2 anchor_ = Vec2::Zero(), rho_ = Vec2::Zero();
};

}  // namespace exc::control::sim
