#include <doctest/doctest.h>

#include <sstream>

#include "scenes.hpp"
#include "tracking_run.hpp"
#include "model/machine_reader.hpp"
#include "control/task/task_reader.hpp"

using namespace exc;
using namespace exc::control;

namespace {

std::string mm(const Vec4& v) {
  std::ostringstream s;
  s.precision(3);
  s << "swing " << v[0] * 1e3 << " mrad, boom " << v[1] * 1e3 << " mm, arm " << v[2] * 1e3 << " mm, bucket "
    << v[3] * 1e3 << " mm";
  return s.str();
}

}  // namespace

TEST_CASE("firmware/dig scene: adaptive RMS error of arm and bucket at least 5x smaller than PID") {
  const Model model = build_model(reference_machine());
  const Task task = read_task(settings::Document::parse(sim::kDigTask, "dig"), model.machine);
  const ControllerConfig cfg;
  const sim::SoilTruth loam;  // loam, re-anchoring at S_dist, terrain at z = 0
  const auto pid = sim::run_tracking(model, task, "pid", cfg, loam);
  const auto ada = sim::run_tracking(model, task, "adaptive", cfg, loam);
  const auto sl = sim::run_tracking(model, task, "slotine_li", cfg, loam);
  REQUIRE(pid.ok);
  REQUIRE(ada.ok);
  REQUIRE(sl.ok);
  MESSAGE("PID        RMS: " << mm(pid.rms) << " | max " << mm(pid.max_abs));
  MESSAGE("adaptive   RMS: " << mm(ada.rms) << " | max " << mm(ada.max_abs));
  MESSAGE("Slotine-Li RMS: " << mm(sl.rms) << " | max " << mm(sl.max_abs));
  MESSAGE("theta_hat adaptive: " << ada.theta_hat.transpose() << "  Slotine-Li: " << sl.theta_hat.transpose());
  MESSAGE("steps in soil: " << ada.soil_steps << ", saturated steps PID/adaptive/SL: " << pid.saturated_steps
                            << "/" << ada.saturated_steps << "/" << sl.saturated_steps);
  CHECK(ada.soil_steps > 3000);  // the pass really digs
  CHECK(ada.rms[2] * 5 <= pid.rms[2]);
  CHECK(ada.rms[3] * 5 <= pid.rms[3]);
  // Slotine-Li, without any acceleration measurement, meets the same target.
  CHECK(sl.rms[2] * 5 <= pid.rms[2]);
  CHECK(sl.rms[3] * 5 <= pid.rms[3]);
}

TEST_CASE("firmware/free motion: every cylinder tracks to under 1 mm under PID and adaptive (Slotine-Li 2.5 mm)") {
  const Model model = build_model(reference_machine());
  const Task task = read_task(settings::Document::parse(sim::kFreeMotionTask, "free"), model.machine);
  const ControllerConfig cfg;
  sim::SoilTruth no_soil;
  no_soil.terrain_height = -100;  // never touches
  for (const std::string kind : {"pid", "adaptive", "slotine_li"}) {
    const auto r = sim::run_tracking(model, task, kind, cfg, no_soil);
    REQUIRE(r.ok);
    MESSAGE(kind << " free motion max |e|: " << mm(r.max_abs));
    CHECK(r.soil_steps == 0);
    CHECK(r.saturated_steps == 0);
    // The paper's controllers: under 1 mm on every cylinder (and 1 mrad on the swing). Slotine-Li
    // feeds the lagging filtered velocity through qdd_r as well: 2.5 mm allowed (measured ~1.8).
    const double bound = kind == "slotine_li" ? 2.5e-3 : 1e-3;
    for (int j = 1; j < 4; ++j) CHECK(r.max_abs[j] < bound);
    CHECK(r.max_abs[0] < 1e-3);
  }
}
