#pragma once
// What the firmware's node is built from besides its model and task (FirmwareNode,
// firmware_node.hpp): the controller's settings and the run's few extras. Its own header so that the
// settings blob (settings_blob.hpp) carries it without the node's bus and telemetry headers.
#include "control/controller_config.hpp"
#include "model/terrain.hpp"
#include "model/types.hpp"

namespace exc::app {

struct FirmwareNodeConfig {
  control::ControllerConfig controller;  // its law names the control law the node runs
  Terrain site_map;               // the scene's ground, for the soil-contact estimate (control/estimation/soil_contact.hpp)
  double track_delay = 0.05;      // s held at the first sensor reading before tracking starts
  // Hold until an operator's start (SUPERVISOR Command = start) before tracking; false: the task
  // starts by itself after track_delay (the default: runs without an operator station).
  bool wait_for_start = false;
  // Simulation only: the plant's true soil parameters, for telemetry and the Lyapunov value.
  bool theta_known = false;
  Vec6 theta_true = Vec6::Zero();
};
// The settings blob's field list (settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, FirmwareNodeConfig& c) {
  v("controller", c.controller);
  v("site_map", c.site_map);
  v("track_delay", c.track_delay);
  v("wait_for_start", c.wait_for_start);
  v("theta_known", c.theta_known);
  v("theta_true", c.theta_true);
}

}  // namespace exc::app
