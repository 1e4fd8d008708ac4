#pragma once
// Scene snippets shared by the tests: the firmware's own sections (task:, controller:) as YAML text.
#include <string>

namespace exc::control::sim {

// A dig pass on flat ground at z = 0 (approach, penetrate, drag, curl, lift), ~0.45 m deep,
// inside the reference machine's strokes and speeds.
inline const char* kDigTask = R"(
task:
  type: dig
  swing: 0.0
  path:
    - {t: 0.0,  x: 8.0, z: 0.6,   pitch_deg: 20}
    - {t: 2.0,  x: 7.8, z: 0.05,  pitch_deg: 15}
    - {t: 3.5,  x: 7.4, z: -0.4,  pitch_deg: 10}
    - {t: 6.5,  x: 6.3, z: -0.45, pitch_deg: 5}
    - {t: 8.0,  x: 6.0, z: -0.25, pitch_deg: 28}
    - {t: 10.0, x: 6.4, z: 0.8,   pitch_deg: 35}
)";

// Free motion of every joint (the paper's 5.1), inside the strokes, tip well above the ground,
// slow enough for the swing torque limit (the swing inertia is ~1.5e5 kg m^2).
inline const char* kFreeMotionTask = R"(
task:
  type: joint_waypoints
  waypoints:
    - {t: 0.0, q: [0.0, 2.45, 2.40, 2.10]}
    - {t: 2.0, q: [0.2, 2.60, 2.30, 1.95]}
    - {t: 4.0, q: [0.05, 2.50, 2.55, 2.20]}
    - {t: 6.0, q: [-0.15, 2.40, 2.45, 2.00]}
    - {t: 8.0, q: [0.0, 2.45, 2.40, 2.10]}
)";

// A saturating task: the swing turns 2 rad in 2.5 s, inside its speed limit but needing about 4.5x the
// swing motor's torque.
inline const char* kFastSwingTask = R"(
task:
  type: joint_waypoints
  waypoints:
    - {t: 0.0, q: [0.0, 2.45, 2.40, 2.10]}
    - {t: 2.5, q: [2.0, 2.45, 2.40, 2.10]}
)";

}  // namespace exc::control::sim
