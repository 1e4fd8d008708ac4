#include "model/plant_scene_keys.hpp"

#include "model/scene_common.hpp"
#include "settings/section_reader.hpp"

namespace exc {

const std::vector<SceneSectionKeys>& plant_scene_keys() {
  static const std::vector<SceneSectionKeys> keys = {
      {"soil", {"preset", "stiffness", "damping", "mass"}},
      {"initial_state", {"q_a", "qd_a"}},
      {"actuators", {"fidelity", "lag"}},
      {"integrator",
       {"method", "formulation", "cycle", "step", "baumgarte_alpha", "baumgarte_beta", "implicit_max_iterations",
        "implicit_tolerance", "pressure_method"}},
      {"sensors",
       {"position_quantum", "position_noise", "velocity_noise", "pressure_quantum", "pressure_noise", "spool_noise",
        "seed", "latency_cycles"}},
      {"checks",
       {"constraint_tolerance", "energy_tolerance", "energy_relative_tolerance", "end_stop_margin",
        "pressure_check_margin"}},
  };
  return keys;
}

void check_plant_scene_keys(const settings::Document& scene) {
  for (const SceneSectionKeys& s : plant_scene_keys()) {
    // The section as a reader of its own sees it: not a mapping refused, its keys against the list.
    settings::SectionReader section(scene.file(), s.section, scene.root()[s.section]);
    section.others(s.keys);
    section.finish();
  }
}

}  // namespace exc
