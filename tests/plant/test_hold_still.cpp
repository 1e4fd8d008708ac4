// Holding still (docs/control.md, "Holding still"): after the dig's path ends at 10.05 s the machine
// holds its last pose on the hydraulic plant with its seals' dry friction and its internal leakage.
// The leakage creeps every loaded function towards the ground and the firmware must correct it now
// and then; no correction may overshoot past the holding tolerance (a stick-slip hunt: the PID's
// integral wound up against the closed valve and the friction and threw the boom 23 mm past its
// pose every few minutes). Counted here from the plant's truth each cycle, apart from the run's own
// figures, which must agree with it.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>

#include "app/firmware_node.hpp"
#include "harness/lockstep_run.hpp"
#include "sim_plant/plant.hpp"

using namespace exc;

namespace {

// One function's hold, counted: corrections (a valve that opened while the machine held) and
// excursions (the error rising past the holding tolerance), and the worst error after each.
struct FunctionHold {
  int corrections = 0;
  int excursions = 0;
  double worst = 0;              // m, from the first settled cycle of the hold on
  double worst_after_correction = 0;  // m, the largest error from a correction's start to the next
  bool open = false, over = false;
};

struct HoldCount {
  sim::RunRecord run;
  std::array<FunctionHold, 4> f{};
  double hold_seconds = 0;
};

HoldCount count_hold(const std::string& law, double duration) {
  const sim::SceneBundle b = sim::load_scene_bundle(std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml");
  HoldCount h;
  sim::LockstepOptions o;
  o.controller = law;
  o.duration = duration;
  double hold_start = -1;
  bool settled = false;
  double inside_since = -1;
  o.observer = [&](std::int64_t, const plant::Plant& plant, const app::FirmwareNode& node) {
    if (node.mode() != safety::Mode::hold || !node.trajectory_finished()) return;
    const double t = plant.state().time;
    if (hold_start < 0) hold_start = t;
    // The path's last error dying out: the hold is judged once every function stayed inside half the
    // tolerance for the dwell (the run's rule, harness/lockstep_run.hpp).
    if (!settled) {
      bool inside = true;
      for (int j = 0; j < 4; ++j)
        inside = inside && std::abs(plant.state().q_a[j] - node.q_desired()[j]) <= 0.5 * sim::kHoldingTolerance[j];
      if (!inside) inside_since = -1;
      else if (inside_since < 0) inside_since = t;
      settled = (inside && t - inside_since >= sim::kHoldSettleDwell) || t - hold_start >= sim::kHoldSettleLimit;
      if (!settled) return;
    }
    h.hold_seconds += b.scene.cycle;
    for (int j = 1; j < 4; ++j) {
      FunctionHold& f = h.f[j];
      const double e = std::abs(plant.state().q_a[j] - node.q_desired()[j]);
      const bool open = node.last_valve_command().spool[j] != 0.0;
      if (open && !f.open) {
        ++f.corrections;
        f.worst_after_correction = std::max(f.worst_after_correction, e);
      }
      if (f.corrections > 0) f.worst_after_correction = std::max(f.worst_after_correction, e);
      f.open = open;
      const bool over = e > sim::kHoldingTolerance[j];
      if (over && !f.over) ++f.excursions;
      f.over = over;
      f.worst = std::max(f.worst, e);
    }
  };
  h.run = sim::run_lockstep(b.scene, b.firmware, o);
  return h;
}

}  // namespace

TEST_CASE("firmware/holding still: 400 s of the dig's hold under every law on defaults, with friction and leakage: "
          "the leakage calls for corrections, none overshoots past the 2.5 mm holding tolerance, and the run's hold "
          "figures and verdict say the same") {
  for (const std::string law : {"pid", "adaptive", "flow"}) {
    const HoldCount h = count_hold(law, 400);
    INFO(law << ": " << h.run.failure);
    REQUIRE(h.run.task_finished);
    // Settled within the limit, and judged from then to the end (the run's clock agrees).
    CHECK(h.hold_seconds > 400 - 10.05 - sim::kHoldSettleLimit);
    CHECK(h.run.hold.seconds == doctest::Approx(h.hold_seconds).epsilon(1e-3));  // and the start-up's 50 ms
    int corrections = 0;
    for (int j = 1; j < 4; ++j) {
      const FunctionHold& f = h.f[j];
      MESSAGE(law << " " << std::string(kActiveNames[j]) << ": " << f.corrections << " corrections, worst " << f.worst * 1e3
                  << " mm (after a correction " << f.worst_after_correction * 1e3 << " mm), " << f.excursions
                  << " excursions; run's hold max " << h.run.hold.max_error[j] * 1e3 << " mm");
      corrections += f.corrections;
      CHECK(f.excursions == 0);
      CHECK(f.worst < sim::kHoldingTolerance[j]);
      CHECK(f.worst_after_correction < sim::kHoldingTolerance[j]);
      // Leakage is slow (about 2 mm/min on a new boom, safety.md): a few corrections, not a hunt.
      CHECK(f.corrections <= 20);
      // The run's figures: the same hold, from the same truth.
      CHECK(h.run.hold.max_error[j] == doctest::Approx(f.worst).epsilon(1e-9));
      CHECK(h.run.hold.excursions[j] == static_cast<std::uint64_t>(f.excursions));
    }
    // The hold is exercised: the leakage carried some function out of its window and it was corrected.
    CHECK(corrections >= 1);
    CHECK(h.run.ok);
  }
}
