#pragma once
// MuJoCo as a peer (compiled only when libmujoco-dev is found, EXC_HAVE_MUJOCO): the machine exported
// by mjcf_export.hpp, driven with the same efforts from the same states as the project's plant.
// Coordinates are the project's: q, qd in paper Table 1 order, tau_a in q_a order.
#include <memory>
#include <string>

#include "model/model.hpp"

struct mjModel_;
struct mjData_;

namespace exc::bench {

// "MuJoCo 2.2.2" (the library's own version).
std::string mujoco_version();

class MujocoPeer {
 public:
  // Compiles the MJCF file; nullptr and 'error' (MuJoCo's message) on failure.
  static std::unique_ptr<MujocoPeer> load(const Model& model, const std::string& xml_path, std::string& error);
  ~MujocoPeer();
  MujocoPeer(const MujocoPeer&) = delete;
  MujocoPeer& operator=(const MujocoPeer&) = delete;

  // State in our tree coordinates; runs mj_forward so that positions and the tip are current.
  void set_state(const Vec12& q, const Vec12& qd);
  void set_effort(const Vec4& tau_a);
  // A world force on the bucket at the tip (the soil's reaction), held until changed.
  void set_tip_force(const Vec3& force_world);
  void step();  // mj_step
  // mj_inverse at (q, qd, qdd): the generalised forces, in our order.
  void inverse(const Vec12& q, const Vec12& qd, const Vec12& qdd, Vec12& tau);
  // mj_forward at the current state: qacc in our order.
  Vec12 acceleration();

  Vec12 q() const;
  Vec12 qd() const;
  double time() const;
  Vec3 tip_world() const;
  // Largest distance (m) between the two points of a cut pin (Table 2), over the 4 loops, with the
  // pin points taken from our model (not from MuJoCo's compiled anchors).
  double constraint_error() const;
  // MuJoCo's compiled second anchor of loop l (body2 frame), to check the export.
  Vec3 compiled_anchor2(int loop) const;
  bool finite() const;
  double total_mass() const;

 private:
  MujocoPeer() = default;
  const Model* model_ = nullptr;
  mjModel_* m_ = nullptr;
  mjData_* d_ = nullptr;
  int qpos_[kNumJoints] = {}, dof_[kNumJoints] = {}, body_[kNumJoints] = {};
  int actuator_[kNumActive] = {};
  int tip_site_ = -1;
};

}  // namespace exc::bench
