// Soil (paper eqs. 9-11): presets, terrain, entry anchor, the shear re-anchoring distance and the
// zig-zag force it makes, alone and in the plant.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "plant_scenes.hpp"

using namespace exc;
using namespace exc::plant;

TEST_CASE("plant/soil presets carry machine.md's numbers") {
  struct Row {
    SoilPreset p;
    double K, B, M;
  };
  const Row rows[] = {{SoilPreset::loose_sand, 2e4, 2.5e3, 200}, {SoilPreset::loam, 7e4, 5e3, 200},
                      {SoilPreset::stiff_clay, 2e5, 9e3, 200}, {SoilPreset::none, 0, 0, 0}};
  for (const Row& r : rows) {
    const SoilParameters s = soil_preset(r.p);
    for (int a = 0; a < 2; ++a) {
      CHECK(s.stiffness[a] == r.K);
      CHECK(s.damping[a] == r.B);
      CHECK(s.mass[a] == r.M);
    }
  }
}

TEST_CASE("plant/soil terrain profile interpolates and holds its ends") {
  Terrain t;
  t.num_points = 3;
  t.profile[0] = Vec2(0, 0);
  t.profile[1] = Vec2(4, 1);
  t.profile[2] = Vec2(6, 0.5);
  CHECK(t.height_at(-3) == doctest::Approx(0));
  CHECK(t.height_at(2) == doctest::Approx(0.5));
  CHECK(t.height_at(5) == doctest::Approx(0.75));
  CHECK(t.height_at(9) == doctest::Approx(0.5));
  Terrain flat;
  flat.height = -0.3;
  CHECK(flat.height_at(123) == -0.3);
}

TEST_CASE("plant/soil acts only below the surface and anchors at the entry point") {
  Terrain t;
  t.height = 0.0;
  SoilModel soil(t, soil_preset(SoilPreset::loam));
  // Above ground: nothing.
  TipLoad l = soil.load(Vec2(5, 0.1), Vec2(0, -1));
  CHECK(l.force.norm() == 0);
  CHECK(l.added_mass.norm() == 0);
  soil.commit(Vec2(5, 0.1));
  CHECK_FALSE(soil.in_soil());
  // Enters at (5.01, -0.01): anchored there; then the spring pulls back toward it.
  soil.commit(Vec2(5.01, -0.01));
  REQUIRE(soil.in_soil());
  CHECK(soil.anchor().isApprox(Vec2(5.01, -0.01)));
  l = soil.load(Vec2(5.02, -0.02), Vec2::Zero());
  CHECK(l.force.x() == doctest::Approx(7e4 * 0.01));
  CHECK(l.force.y() == doctest::Approx(7e4 * -0.01));
  CHECK(l.added_mass.x() == 200);
  // eq. 9 in full: F = M rhodd + B rhod + K (rho - rho_env).
  const Vec2 F = soil.total_force(Vec2(5.02, -0.02), Vec2(0.1, -0.2), Vec2(1.0, 2.0));
  CHECK(F.x() == doctest::Approx(200 * 1.0 + 5e3 * 0.1 + 7e4 * 0.01));
  CHECK(F.y() == doctest::Approx(200 * 2.0 + 5e3 * -0.2 + 7e4 * -0.01));
  // Leaving the soil releases the anchor.
  soil.commit(Vec2(5.02, 0.01));
  CHECK_FALSE(soil.in_soil());
}

TEST_CASE("plant/soil of preset none engages nothing: a tip below the terrain is not in soil and never shears") {
  Terrain t;
  t.height = 0.0;
  SoilModel none(t, soil_preset(SoilPreset::none));
  CHECK_FALSE(none.present());
  CHECK(SoilModel(t, soil_preset(SoilPreset::loose_sand)).present());
  // Buried 0.5 m and dragged 1 m up and back, as a scene that starts with its bucket below the
  // terrain's height: loam would shear many times over that path.
  SoilModel loam(t, soil_preset(SoilPreset::loam));
  for (int i = 0; i <= 1000; ++i) {
    const Vec2 rho(7.6 - 1e-3 * i, -0.5 + 5e-4 * i);
    CHECK(none.load(rho, Vec2(-1, 0.5)).force.norm() == 0);
    CHECK(none.load(rho, Vec2(-1, 0.5)).added_mass.norm() == 0);
    CHECK_FALSE(none.commit(rho));
    CHECK_FALSE(none.in_soil());
    loam.commit(rho);
  }
  CHECK(none.reanchor_count() == 0);
  CHECK(loam.reanchor_count() > 3);  // the control: the same path through soil shears
}

TEST_CASE("plant/soil re-anchors at S_dist = 0.365 h + 0.00754 and the force zig-zags") {
  for (double h : {0.1, 0.3, 0.5}) {
    CAPTURE(h);
    const double s_dist = 0.365 * h + 0.00754;  // paper eq. 11, written out independently
    Terrain t;
    SoilModel soil(t, soil_preset(SoilPreset::stiff_clay));
    const double K = 2e5, dx = 1e-5;
    soil.commit(Vec2(5.0, -h));
    std::vector<double> break_points, peaks;
    double last_force = 0;
    for (int i = 1; i <= 100000; ++i) {  // drag 1 m at constant depth
      const Vec2 rho(5.0 - i * dx, -h);
      const double f = soil.load(rho, Vec2::Zero()).force.x();
      if (soil.commit(rho)) {
        break_points.push_back(rho.x());
        peaks.push_back(f);
        // The force drops at the re-anchoring: the spring is relaxed right after.
        CHECK(std::abs(soil.load(rho, Vec2::Zero()).force.x()) < 1e-9);
      }
      last_force = f;
    }
    (void)last_force;
    REQUIRE(break_points.size() >= 2);
    // Spacing of the re-anchorings = S_dist (to the drag increment), every peak = K S_dist.
    for (std::size_t k = 1; k < break_points.size(); ++k)
      CHECK(std::abs((break_points[k - 1] - break_points[k]) - s_dist) < 2 * dx);
    for (double p : peaks) CHECK(std::abs(std::abs(p) - K * s_dist) < 2 * K * dx);
    CHECK(static_cast<int>(break_points.size()) == static_cast<int>(std::floor(1.0 / (s_dist + dx))));
  }
}

TEST_CASE("plant/soil zig-zag force comes out of a plant dragging the bucket through clay") {
  test::SceneText t;
  t.terrain = "height: 1.93";  // the tip of the reference pose (z ~ 1.83) is 0.1 m deep
  t.soil = "preset: stiff_clay";
  t.actuators = "fidelity: limited, lag: 0";
  Plant p(t.scene());
  REQUIRE(p.state().in_soil);
  const double K = p.scene().soil.stiffness.x();
  ActuatorCommand cmd;
  cmd.value = p.hold_effort();
  cmd.value[2] += 60e3;  // crowd the arm: the tip drags toward the machine
  Vec2 anchor_before = p.state().soil_anchor;
  double stretch_at_failure = 0, s_dist = 0;
  int previous_count = 0, drops = 0;
  bool pending = false;
  for (int i = 0; i < 1500; ++i) {
    REQUIRE(p.step(cmd).ok());
    const PlantState& s = p.state();
    // The spring's force K |rho - rho_env| (the total also carries the damping and mass terms, which
    // follow the tip's speed). The cycle that re-anchors stretched it from the old anchor by at least
    // S_dist(h); the next cycle pulls from the new anchor: the zig-zag's drop, >= K S_dist.
    const double spring = K * (s.rho - s.soil_anchor).norm();
    if (pending && s.in_soil) {
      CHECK(K * stretch_at_failure - spring > 0.8 * K * s_dist);
      ++drops;
    }
    pending = s.reanchor_count > previous_count;
    if (pending) {
      stretch_at_failure = (s.rho - anchor_before).norm();
      s_dist = 0.365 * s.depth + 0.00754;
      CHECK(stretch_at_failure >= s_dist);
    }
    previous_count = s.reanchor_count;
    anchor_before = s.soil_anchor;
  }
  MESSAGE("re-anchorings in 1.5 s of drag: " << p.state().reanchor_count);
  CHECK(drops >= 3);
}
