#include "mujoco_peer.hpp"

#include <mujoco/mujoco.h>

#include <Eigen/Geometry>
#include <cmath>

#include "mjcf_export.hpp"

namespace exc::bench {

std::string mujoco_version() {
  const int v = mj_version();  // e.g. 222
  return "MuJoCo " + std::to_string(v / 100) + "." + std::to_string(v / 10 % 10) + "." + std::to_string(v % 10);
}

std::unique_ptr<MujocoPeer> MujocoPeer::load(const Model& model, const std::string& xml_path, std::string& error) {
  char message[1000] = "";
  mjModel* m = mj_loadXML(xml_path.c_str(), nullptr, message, sizeof(message));
  if (!m) {
    error = std::string("MuJoCo could not load ") + xml_path + ": " + message;
    return nullptr;
  }
  std::unique_ptr<MujocoPeer> peer(new MujocoPeer());
  peer->model_ = &model;
  peer->m_ = m;
  peer->d_ = mj_makeData(m);
  for (int k = 0; k < kNumJoints; ++k) {
    const int j = mj_name2id(m, mjOBJ_JOINT, kMjcfBodyNames[k]);
    const int b = mj_name2id(m, mjOBJ_BODY, kMjcfBodyNames[k]);
    if (j < 0 || b < 0) {
      error = xml_path + ": no joint or body named '" + kMjcfBodyNames[k] + "' (not an excavator-bench export)";
      return nullptr;
    }
    peer->qpos_[k] = m->jnt_qposadr[j];
    peer->dof_[k] = m->jnt_dofadr[j];
    peer->body_[k] = b;
  }
  for (int a = 0; a < kNumActive; ++a) {
    peer->actuator_[a] = mj_name2id(m, mjOBJ_ACTUATOR, kActiveNames[a]);
    if (peer->actuator_[a] < 0) {
      error = xml_path + ": no actuator named '" + kActiveNames[a] + "'";
      return nullptr;
    }
  }
  peer->tip_site_ = mj_name2id(m, mjOBJ_SITE, "tip");
  if (peer->tip_site_ < 0) {
    error = xml_path + ": no site named 'tip'";
    return nullptr;
  }
  mj_forward(m, peer->d_);
  return peer;
}

MujocoPeer::~MujocoPeer() {
  if (d_) mj_deleteData(d_);
  if (m_) mj_deleteModel(m_);
}

void MujocoPeer::set_state(const Vec12& q, const Vec12& qd) {
  for (int k = 0; k < kNumJoints; ++k) {
    d_->qpos[qpos_[k]] = q[k];
    d_->qvel[dof_[k]] = qd[k];
  }
  mj_forward(m_, d_);
}

void MujocoPeer::set_effort(const Vec4& tau_a) {
  for (int a = 0; a < kNumActive; ++a) d_->ctrl[actuator_[a]] = tau_a[a];
}

void MujocoPeer::set_tip_force(const Vec3& f) {
  // xfrc_applied acts at the body's centre of mass: move the force from the tip there.
  const int b = body_[kBucket];
  const mjtNum* tip = d_->site_xpos + 3 * tip_site_;
  const mjtNum* com = d_->xipos + 3 * b;
  const Vec3 r(tip[0] - com[0], tip[1] - com[1], tip[2] - com[2]);
  const Vec3 torque = r.cross(f);
  for (int i = 0; i < 3; ++i) {
    d_->xfrc_applied[6 * b + i] = f[i];
    d_->xfrc_applied[6 * b + 3 + i] = torque[i];
  }
}

void MujocoPeer::step() { mj_step(m_, d_); }

void MujocoPeer::inverse(const Vec12& q, const Vec12& qd, const Vec12& qdd, Vec12& tau) {
  for (int k = 0; k < kNumJoints; ++k) {
    d_->qpos[qpos_[k]] = q[k];
    d_->qvel[dof_[k]] = qd[k];
    d_->qacc[dof_[k]] = qdd[k];
  }
  mj_inverse(m_, d_);
  for (int k = 0; k < kNumJoints; ++k) tau[k] = d_->qfrc_inverse[dof_[k]];
}

Vec12 MujocoPeer::acceleration() {
  mj_forward(m_, d_);
  Vec12 a;
  for (int k = 0; k < kNumJoints; ++k) a[k] = d_->qacc[dof_[k]];
  return a;
}

Vec12 MujocoPeer::q() const {
  Vec12 q;
  for (int k = 0; k < kNumJoints; ++k) q[k] = d_->qpos[qpos_[k]];
  return q;
}

Vec12 MujocoPeer::qd() const {
  Vec12 v;
  for (int k = 0; k < kNumJoints; ++k) v[k] = d_->qvel[dof_[k]];
  return v;
}

double MujocoPeer::time() const { return d_->time; }

Vec3 MujocoPeer::tip_world() const {
  const mjtNum* p = d_->site_xpos + 3 * tip_site_;
  return Vec3(p[0], p[1], p[2]);
}

namespace {
Vec3 world_point(const mjData* d, int body, const Vec3& local) {
  const mjtNum* x = d->xpos + 3 * body;
  const mjtNum* R = d->xmat + 9 * body;  // row-major
  Vec3 p;
  for (int i = 0; i < 3; ++i) p[i] = x[i] + R[3 * i] * local[0] + R[3 * i + 1] * local[1] + R[3 * i + 2] * local[2];
  return p;
}
}  // namespace

double MujocoPeer::constraint_error() const {
  double worst = 0;
  for (int l = 0; l < kNumLoops; ++l) {
    const LoopCut& cut = model_->loops[l];
    const Vec3 a = world_point(d_, body_[cut.link_p], cut.point_p);
    const Vec3 b = world_point(d_, body_[cut.link_s], cut.point_s);
    worst = std::max(worst, (a - b).norm());
  }
  return worst;
}

Vec3 MujocoPeer::compiled_anchor2(int loop) const {
  const mjtNum* e = m_->eq_data + mjNEQDATA * loop;
  return Vec3(e[3], e[4], e[5]);
}

bool MujocoPeer::finite() const {
  for (int i = 0; i < m_->nq; ++i)
    if (!std::isfinite(d_->qpos[i])) return false;
  for (int i = 0; i < m_->nv; ++i)
    if (!std::isfinite(d_->qvel[i])) return false;
  return true;
}

double MujocoPeer::total_mass() const { return mj_getTotalmass(m_); }

}  // namespace exc::bench
