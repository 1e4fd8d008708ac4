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

#include "control/control_types.hpp"
#include "model/types.hpp"

namespace exc::control {

struct EstimatorConfig {
  double period = 1e-3;                // s
  double velocity_cutoff_hz = 25;      // Butterworth low-pass on qd_a
  double acceleration_cutoff_hz = 15;  // filtered derivative of the filtered velocity
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, EstimatorConfig& c) {
  v("period", c.period);
  v("velocity_cutoff_hz", c.velocity_cutoff_hz);
  v("acceleration_cutoff_hz", c.acceleration_cutoff_hz);
}

// The two stages' coefficients, by the bilinear (Tustin) transform at the period.
struct EstimatorCoefficients {
  double b0 = 0, b1 = 0, b2 = 0, a1 = 0, a2 = 0;  // the velocity's Butterworth biquad (prewarped)
  // 1 / (tau s + 1) and s / (tau s + 1) of the acceleration stage: y_k = k (x_k + x_{k-1}) - r y_{k-1},
  // a_k = g (x_k - x_{k-1}) - r a_{k-1}, k = g T / 2.
  double g = 0, r = 0, k = 0;
  explicit EstimatorCoefficients(const EstimatorConfig& c) {
    const double pi = 3.14159265358979323846;
    const double w = std::tan(pi * c.velocity_cutoff_hz * c.period);
    const double norm = 1 / (1 + std::sqrt(2.0) * w + w * w);
    b0 = w * w * norm;
    b1 = 2 * b0;
    b2 = b0;
    a1 = 2 * (w * w - 1) * norm;
    a2 = (1 - std::sqrt(2.0) * w + w * w) * norm;
    const double tau = 1 / (2 * pi * c.acceleration_cutoff_hz);
    g = 2 / (2 * tau + c.period);
    r = (c.period - 2 * tau) / (2 * tau + c.period);
    k = g * c.period / 2;
  }
};

// The gain a of a first-order low-pass y += a (u - y) sampled every `period` s with this cut-off:
// 1 - exp(-2 pi f T), the step-invariant discretisation of 1 / (s / (2 pi f) + 1).
inline double first_order_gain(double cutoff_hz, double period) {
  return 1.0 - std::exp(-2.0 * 3.14159265358979323846 * cutoff_hz * period);
}

// N signals through that first-order low-pass, started at its first sample (no start-up transient).
template <int N>
class FirstOrderLowPass {
 public:
  using Vec = Eigen::Matrix<double, N, 1>;
  explicit FirstOrderLowPass(double gain = 1.0) : gain_(gain) {}
  void reset() { primed_ = false; }
  const Vec& update(const Vec& u) {
    if (primed_) out_ += gain_ * (u - out_);
    else out_ = u;
    primed_ = true;
    return out_;
  }
  const Vec& value() const { return out_; }

 private:
  double gain_ = 1.0;
  bool primed_ = false;
  Vec out_ = Vec::Zero();
};

// N signals through the chain the estimator's acceleration sees (the Butterworth low-pass, then the
// acceleration stage's 1 / (tau s + 1)): a signal filtered here lines up in time with the filtered
// acceleration, so a regression may mix them (the adaptive law's composite update does).
template <int N>
class EstimatorLowPass {
 public:
  using Vec = Eigen::Matrix<double, N, 1>;
  explicit EstimatorLowPass(const EstimatorConfig& c = {}) : c_(c) {}
  void reset() { primed_ = false; }
  const Vec& update(const Vec& x) {
    if (!primed_) {  // at rest at the first sample: no start-up transient
      x1_ = x2_ = y1_ = y2_ = out_ = x;
      primed_ = true;
      return out_;
    }
    const Vec y = c_.b0 * x + c_.b1 * x1_ + c_.b2 * x2_ - c_.a1 * y1_ - c_.a2 * y2_;
    x2_ = x1_;
    x1_ = x;
    y2_ = y1_;
    out_ = c_.k * (y + y1_) - c_.r * out_;
    y1_ = y;
    return out_;
  }
  const Vec& value() const { return out_; }

 private:
  EstimatorCoefficients c_;
  bool primed_ = false;
  Vec x1_ = Vec::Zero(), x2_ = Vec::Zero(), y1_ = Vec::Zero(), y2_ = Vec::Zero(), out_ = Vec::Zero();
};

class StateEstimator {
 public:
  explicit StateEstimator(const EstimatorConfig& c = {}) { configure(c); }

  void configure(const EstimatorConfig& c) {
    config_ = c;
    const EstimatorCoefficients k(c);
    b0_ = k.b0;
    b1_ = k.b1;
    b2_ = k.b2;
    a1_ = k.a1;
    a2_ = k.a2;
    // Filtered derivative a = s/(tau s + 1) v, Tustin: a_k = g (v_k - v_{k-1}) - r a_{k-1}.
    g_ = k.g;
    r_ = k.r;
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
  // The filters' memory is these outputs and the inputs, one cycle back.
  void visit_state(StateVisitor& v) const {
    v.visit("estimator position", q_);
    v.visit("estimator velocity (Butterworth)", v_);
    v.visit("estimator acceleration (filtered derivative)", a_);
  }
  const EstimatorConfig& config() const { return config_; }

 private:
  EstimatorConfig config_;
  double b0_ = 0, b1_ = 0, b2_ = 0, a1_ = 0, a2_ = 0, g_ = 0, r_ = 0;
  bool primed_ = false;
  Vec4 q_ = Vec4::Zero(), v_ = Vec4::Zero(), a_ = Vec4::Zero();
  Vec4 x1_ = Vec4::Zero(), x2_ = Vec4::Zero(), y1_ = Vec4::Zero(), y2_ = Vec4::Zero();
};

}  // namespace exc::control
