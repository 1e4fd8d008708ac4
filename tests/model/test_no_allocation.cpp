// The real-time path allocates nothing after loading: closed-chain update, inverse and forward
// dynamics (both forms), mass matrix and bias forces, over thousands of steps.
#include <doctest/doctest.h>

#include "app/allocation_counter.hpp"
#include "model_fixture.hpp"
#include "model/machine_reader.hpp"

using namespace exc;

TEST_CASE("model/zero heap allocations in id and fd after loading") {
  REQUIRE(exc::app::allocation_counting_works());
  const Model model = build_model(reference_machine());  // start-up: may allocate
  Workspace ws(model);
  test::RandomStates rs(31);
  std::vector<std::array<Vec4, 3>> states(256);
  for (auto& s : states) s = {rs.q_a(model), rs.qd_a(), rs.qdd_a()};
  TipLoad load;
  load.force = Vec2(1e4, -2e4);
  load.added_mass = Vec2(200, 200);

  double checksum = 0;
  std::size_t allocations = 0;
  {
    app::AllocationCounter counter;
    app::EigenNoMallocScope no_eigen_malloc;
    for (int k = 0; k < 5000; ++k) {
      const auto& s = states[k % states.size()];
      Vec4 tau_a, qdd_a, h_a;
      Mat4 M_a;
      if (!update_closed_chain(model, ws, s[0], s[1]).ok()) continue;
      inverse_dynamics(model, ws, s[2], Vec2(1e3, 2e3), tau_a);
      mass_matrix(model, ws, M_a);
      bias_forces(model, ws, h_a);
      forward_dynamics(model, ws, s[0], s[1], tau_a, load, qdd_a);
      checksum += tau_a.sum() + qdd_a.sum() + M_a.trace() + h_a.sum();
      if (k % 10 == 0) {
        Vec12 qdd;
        Vec8 lambda;
        forward_dynamics_augmented(model, ws, ws.q, ws.qd, tau_a, load, 1.0, 1.0, qdd, lambda);
        checksum += qdd.sum();
      }
    }
    allocations = counter.count();
  }
  CHECK(std::isfinite(checksum));
  CHECK(allocations == 0);
}
