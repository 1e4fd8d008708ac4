#pragma once
// The soil parameters' physical bounds and initial estimate, which both adaptive laws (the adaptive
// computed torque and Slotine-Li) project their estimates onto. ControllerConfig holds them once, as
// its `soil_parameters` member; each adaptive law takes them beside its own settings.
#include "model/types.hpp"

namespace exc::control {

// Theta = [M_x B_x K_x M_z B_z K_z]. Physical bounds (machine.md): M 50..500 kg,
// B 1e3..3e4 N s/m, K 1e4..1e6 N/m.
struct SoilParameterBounds {
  Vec6 theta_min = (Vec6() << 50, 1e3, 1e4, 50, 1e3, 1e4).finished();
  Vec6 theta_max = (Vec6() << 500, 3e4, 1e6, 500, 3e4, 1e6).finished();
  Vec6 theta_initial = (Vec6() << 100, 2e3, 3e4, 100, 2e3, 3e4).finished();
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, SoilParameterBounds& b) {
  v("theta_min", b.theta_min);
  v("theta_max", b.theta_max);
  v("theta_initial", b.theta_initial);
}

}  // namespace exc::control
