// Stability limits, found and reported: each integrator x formulation is pushed through larger steps
// with a stiff soil until it fails; the failure must be detected (never silent garbage), the message
// must name the integrator and ask for a smaller step, and a smaller step must be stable.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "plant_scenes.hpp"

using namespace exc;
using namespace exc::plant;

namespace {

// The reference pose with its tip 0.1 m deep in a stiff soil (10x stiffer and 50x more damped than
// stiff clay: a full bucket pressed against rock), moving into it, efforts holding the weight.
Scene stiff_soil_scene(const std::string& method, const std::string& formulation, double h) {
  test::SceneText t = test::SceneText::stepped(method, formulation, h);
  t.terrain = "height: 1.93";
  t.soil = "stiffness: [2e6, 2e6], damping: [5e5, 5e5], mass: [200, 200]";
  t.checks = "energy_tolerance: 100";
  t.qd_a = "[0.05, -0.1, 0.05, -0.05]";  // moving into the ground at the start
  return t.scene();
}

struct Outcome {
  bool ok = true;
  PlantStatus status;
  bool finite = true;
};

Outcome run(const Scene& s, double seconds) {
  Plant p(s);
  ActuatorCommand c;
  c.value = p.hold_effort();
  Outcome o;
  const int n = static_cast<int>(std::lround(seconds / s.cycle));
  for (int k = 0; k < n; ++k) {
    const PlantStatus st = p.step(c);
    // Whatever happens, the state the plant shows is finite.
    o.finite = o.finite && p.state().q_a.allFinite() && p.state().qd_a.allFinite();
    if (!st.ok()) {
      o.ok = false;
      o.status = st;
      break;
    }
  }
  return o;
}

}  // namespace

TEST_CASE("plant/stability limit of every integrator with stiff soil is found, reported, and safe below") {
  const double steps[] = {1e-3, 2e-3, 4e-3, 8e-3, 16e-3, 32e-3, 64e-3, 128e-3, 256e-3, 512e-3};
  for (const std::string& m : test::methods()) {
    for (const char* f : test::kFormulations) {
      CAPTURE(std::string(m));
      CAPTURE(std::string(f));
      double largest_stable = 0, failed_at = 0;
      std::string message;
      for (double h : steps) {
        const Outcome o = run(stiff_soil_scene(m, f, h), 1.0);
        CHECK(o.finite);
        if (o.ok) {
          largest_stable = h;
          continue;
        }
        failed_at = h;
        message = o.status.text();
        break;
      }
      MESSAGE(std::string(m) << " / " << std::string(f) << ": stable up to " << largest_stable * 1e3 << " ms, fails at "
                             << failed_at * 1e3 << " ms: " << message);
      // Stable at the plant's own step ...
      CHECK(largest_stable >= 1e-3);
      // ... and a step large enough fails, detected and explained.
      REQUIRE(failed_at > 0);
      CHECK(message.find(m) != std::string::npos);
      CHECK(message.find(f) != std::string::npos);
      CHECK(message.find("smaller") != std::string::npos);
    }
  }
}

TEST_CASE("plant/a huge step in stiff clay is stopped with a message naming the integrator, and 1 ms is stable") {
  test::SceneText t;
  t.terrain = "height: 1.93";
  t.soil = "preset: stiff_clay";
  t.qd_a = "[0.05, -0.1, 0.05, -0.05]";
  t.step = 0.2;
  t.cycle = 0.2;
  Outcome o = run(t.scene(), 10.0);
  REQUIRE_FALSE(o.ok);
  const std::string msg = o.status.text();
  MESSAGE(msg);
  CHECK(msg.find("semi_implicit_euler") != std::string::npos);
  CHECK(msg.find("smaller integrator.step") != std::string::npos);
  CHECK(msg.find("t = ") != std::string::npos);
  t.step = 1e-3;
  t.cycle = 1e-3;
  o = run(t.scene(), 3.0);
  CHECK(o.ok);
}

TEST_CASE("plant/a machine thrown at high speed is caught before it produces garbage") {
  // 5x the relief forces on every cylinder with ideal actuators: the cylinders slam into their
  // stops within a fraction of a second; the plant must stop with a reason, never with NaN.
  test::SceneText t;
  t.method = "rk4";
  t.step = 8e-3;
  t.cycle = 8e-3;
  Plant p(t.scene());
  ActuatorCommand c;
  c.value = Vec4(3e5, 4e6, -1.2e6, 1.8e6);
  PlantStatus st;
  for (int k = 0; k < 500 && st.ok(); ++k) st = p.step(c);
  REQUIRE_FALSE(st.ok());
  MESSAGE(std::string(st.text()));
  CHECK(p.state().q_a.allFinite());
  CHECK((st.failure == PlantFailure::end_stop || st.failure == PlantFailure::model ||
         st.failure == PlantFailure::near_toggle || st.failure == PlantFailure::energy_growth));
}
