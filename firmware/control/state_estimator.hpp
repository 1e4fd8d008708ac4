#pragma once
// Velocity and acceleration of the active joints from the measured q_a and qd_a the plant sends.
// - Velocity: a 2nd-order Butterworth low-pass on the measured velocity (default cut-off 25 Hz at
//   1 kHz: removes sensor noise, ~9 ms group delay at low frequency, well above the ~0.5 Hz of the
//   digging motion).
// - Acceleration (needed only by the adaptive law's regressor, for the soil's M_t rhodd term):
//   a filtered derivative s / (tau s + 1) of the filtered velocity, tau = 1 / (2 pi f_a), default
//   f_a = 15 Hz. Both discretised by the bilinear (Tustin) transform, cut-off prewarped.
// The passive joints follow from q_a by the model's loop closure (update_closed_chain), not here.
// Fixed-size state, no allocation.
#include <cmath>

#include "model/types.hpp"

namespace exc::control {

struct EstimatorConfig {
  double period = 1e-3;                // s
  double velocity_cutoff_hz = 25;      // Butterworth low-pass on qd_a
  double acceleration_cutoff_hz = 15;  // filtered derivative of the filtered velocity
};

class StateEstimator {
 public:
  explicit StateEstimator(const EstimatorConfig& c = {}) { configure(c); }

  void configure(const EstimatorConfig& c) {
    config_ = c;
    const double pi = 3.14159265358979323846;
    // Butterworth biquad by the bilinear transform with prewarping (standard coefficients).
    const double k = std::tan(pi * c.velocity_cutoff_hz * c.period);
    const double norm = 1 / (1 + std::sqrt(2.0) * k + k * k);
    b0_ = k * k * norm;
    b1_ = 2 * b0_;
    b2_ = b0_;
    a1_ = 2 * (k * k - 1) * norm;
    a2_ = (1 - std::sqrt(2.0) * k + k * k) * norm;
    // Filtered derivative a = s/(tau s + 1) v, Tustin: a_k = g (v_k - v_{k-1}) - r a_{k-1}.
    const double tau = 1 / (2 * pi * c.acceleration_cutoff_hz);
    g_ = 2 / (2 * tau + c.period);
    r_ = (c.period - 2 * tau) / (2 * tau + c.period);
    primed_ = false;
  }

  // Starts the filters at rest at this measurement (no start-up transient).
  void reset(const Vec4& q, const Vec4& qd) {
    q_ = q;
    x1_ = x2_ = qd;
    y1_ = y2_ = qd;
    v_ = qd;
    a_.setZero();
    primed_ = true;
  }

  void update(const Vec4& q_measured, const Vec4& qd_measured) {
    if (!primed_) reset(q_measured, qd_measured);
    q_ = q_measured;
    const Vec4 y = b0_ * qd_measured + b1_ * x1_ + b2_ * x2_ - a1_ * y1_ - a2_ * y2_;
    x2_ = x1_;
    x1_ = qd_measured;
    y2_ = y1_;
    y1_ = y;
    a_ = g_ * (y - v_) - r_ * a_;
    v_ = y;
  }

  bool primed() const { return primed_; }
  const Vec4& position() const { return q_; }
  const Vec4& velocity() const { return v_; }
  const Vec4& acceleration() const { return a_; }
  const EstimatorConfig& config() const { return config_; }

 private:
  EstimatorConfig config_;
  double b0_ = 0, b1_ = 0, b2_ = 0, a1_ = 0, a2_ = 0, g_ = 0, r_ = 0;
  bool primed_ = false;
  Vec4 q_ = Vec4::Zero(), v_ = Vec4::Zero(), a_ = Vec4::Zero();
  Vec4 x1_ = Vec4::Zero(), x2_ = Vec4::Zero(), y1_ = Vec4::Zero(), y2_ = Vec4::Zero();
};

}  // namespace exc::control
