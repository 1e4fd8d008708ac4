#include <doctest/doctest.h>

#include <cstring>

#include "control/actuation/command_blender.hpp"
#include "safety/state_machine.hpp"

using namespace exc;
using namespace exc::safety;
using exc::control::CommandBlender;

TEST_CASE("firmware/state machine: init, wait for sensors, hold, track, finish") {
  ControlStateMachine sm(0.02);
  StateMachineInputs in;
  CHECK(sm.mode() == Mode::init);
  Transition tr = sm.step(in);
  CHECK(tr.changed);
  CHECK(sm.mode() == Mode::wait_sensors);
  in.t = 0.1;
  CHECK(!sm.step(in).changed);  // no frame yet: keep waiting
  in.track_requested = true;
  CHECK(!sm.step(in).changed);  // cannot track before sensors
  in.have_valid_frame = true;
  in.last_valid_frame_time = 0.1;
  tr = sm.step(in);
  CHECK(tr.to == Mode::hold);
  CHECK(std::strcmp(tr.reason, "first valid sensor frame") == 0);
  tr = sm.step(in);
  CHECK(tr.to == Mode::track);
  in.t = 0.2;
  in.last_valid_frame_time = 0.2;
  in.trajectory_finished = true;
  tr = sm.step(in);
  CHECK(tr.from == Mode::track);
  CHECK(tr.to == Mode::hold);
  CHECK(std::strcmp(sm.last_reason(), "trajectory finished") == 0);
}

TEST_CASE("firmware/state machine watchdog: lost frames stop safely, the stop latches until acknowledged, then hold") {
  ControlStateMachine sm(0.02);
  StateMachineInputs in;
  in.have_valid_frame = true;
  in.track_requested = true;
  for (int k = 0; k <= 100; ++k) {  // 100 ms of good frames
    in.t = k * 1e-3;
    in.last_valid_frame_time = in.t;
    sm.step(in);
  }
  CHECK(sm.mode() == Mode::track);
  // Frames stop at t = 0.1: still tracking within the timeout, safe stop just after it.
  in.t = 0.119;
  CHECK(!sm.step(in).changed);
  in.t = 0.1201;
  const Transition tr = sm.step(in);
  CHECK(tr.to == Mode::safe_stop);
  CHECK(std::strcmp(tr.reason, "watchdog: sensor frames timed out") == 0);
  in.t = 0.5;
  CHECK(!sm.step(in).changed);  // stays stopped without frames
  in.last_valid_frame_time = 0.5;
  for (int k = 0; k < 1000; ++k) {  // frames back, no fault: still stopped, nobody acknowledged
    in.t = 0.5 + k * 1e-3;
    in.last_valid_frame_time = in.t;
    REQUIRE(!sm.step(in).changed);
  }
  in.acknowledged = true;
  in.fault = true;
  CHECK(!sm.step(in).changed);  // an acknowledge while a fault stands does not leave the stop
  in.fault = false;
  in.last_valid_frame_time = in.t - 0.5;
  CHECK(!sm.step(in).changed);  // nor while the frames are stale
  in.last_valid_frame_time = in.t;
  const Transition back = sm.step(in);
  CHECK(back.to == Mode::hold);  // acknowledged, fresh, no fault: hold, not straight back to track
  CHECK(std::strcmp(back.reason, "acknowledged, sensor frames fresh, no fault") == 0);
  in.acknowledged = false;
  CHECK(sm.step(in).to == Mode::track);
  in.fault = true;
  CHECK(sm.step(in).to == Mode::safe_stop);
  CHECK(!sm.step(in).changed);  // a standing fault keeps it stopped
  in.fault = false;
  CHECK(!sm.step(in).changed);  // and a fault that went away too, without an acknowledge
}

TEST_CASE("firmware/bumpless switch: the command is continuous at the switch and converges to the new law") {
  CommandBlender blend(0.2);
  const double dt = 1e-3;
  // Old law: a constant 10 kN; new law: a ramp starting at 40 kN.
  auto old_law = [](double) { return Vec4::Constant(10000); };
  auto new_law = [](double t) { return Vec4::Constant(40000 + 1000 * t); };
  Vec4 last = old_law(0);
  double worst_step = 0;
  for (int k = 1; k < 1000; ++k) {
    const double t = k * dt;
    Vec4 cmd;
    if (t < 0.3) {
      cmd = old_law(t);
    } else {
      if (!blend.active() && std::abs(t - 0.3) < dt / 2) blend.on_switch(t, last, new_law(t));
      cmd = blend.apply(t, new_law(t));
    }
    worst_step = std::max(worst_step, (cmd - last).cwiseAbs().maxCoeff());
    last = cmd;
  }
  // The unblended jump would be 30 kN; blended over 200 steps it is ~150 N per step.
  CHECK(worst_step < 200);
  CHECK((last - new_law(0.999)).norm() == 0);
}
