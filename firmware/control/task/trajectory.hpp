#pragma once
// C2 trajectories through timed waypoints (the paper's section 5.1): a clamped cubic spline per
// coordinate, with zero velocity at the first and last waypoint. Position, velocity and acceleration
// are continuous everywhere inside; before the first time it holds the first point, after the last
// time the last point (velocity and acceleration zero there).
// Built once at start-up (allocates); evaluate() allocates nothing.
#include <Eigen/Core>
#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/types.hpp"

namespace exc::control {

template <int N>
class CubicSpline {
 public:
  using Point = Eigen::Matrix<double, N, 1>;

  CubicSpline() = default;
  // times strictly increasing, at least two points. Throws std::invalid_argument otherwise (the
  // parsers check first and name the field; this is the last line of defence).
  CubicSpline(std::vector<double> times, std::vector<Point> points) {
    if (times.size() < 2 || times.size() != points.size())
      throw std::invalid_argument("CubicSpline: need >= 2 waypoints with one time each");
    if (!assign(std::move(times), std::move(points))) throw std::invalid_argument("CubicSpline: times must increase");
  }
  // The same without throwing (the settings blob's decoder, app/settings_blob.hpp): false, the spline
  // left as it was, unless there are at least two points, one time each, the times strictly increasing.
  bool assign(std::vector<double> times, std::vector<Point> points) {
    if (times.size() < 2 || times.size() != points.size()) return false;
    for (std::size_t i = 1; i < times.size(); ++i)
      if (!(times[i] > times[i - 1])) return false;
    t_ = std::move(times);
    y_ = std::move(points);
    last_ = 0;
    solve_second_derivatives();
    return true;
  }

  bool empty() const { return t_.empty(); }
  double start_time() const { return t_.front(); }
  double end_time() const { return t_.back(); }
  std::size_t size() const { return t_.size(); }
  const std::vector<double>& times() const { return t_; }
  const std::vector<Point>& points() const { return y_; }

  // Position, velocity, acceleration at time t (s). No allocation.
  void evaluate(double t, Point& y, Point& yd, Point& ydd) const {
    if (t <= t_.front() || t >= t_.back()) {
      y = t <= t_.front() ? y_.front() : y_.back();
      yd.setZero();
      ydd.setZero();
      return;
    }
    const std::size_t i = segment(t);
    const double h = t_[i + 1] - t_[i];
    const double a = t_[i + 1] - t;  // time to the segment end
    const double b = t - t_[i];      // time from the segment start
    const Point& m0 = m_[i];
    const Point& m1 = m_[i + 1];
    // The standard second-derivative form of a cubic spline segment.
    y = (m0 * (a * a * a) + m1 * (b * b * b)) / (6 * h) + (y_[i] / h - m0 * (h / 6)) * a +
        (y_[i + 1] / h - m1 * (h / 6)) * b;
    yd = (-m0 * (a * a) + m1 * (b * b)) / (2 * h) - (y_[i] / h - m0 * (h / 6)) +
         (y_[i + 1] / h - m1 * (h / 6));
    ydd = (m0 * a + m1 * b) / h;
  }

 private:
  std::size_t segment(double t) const {
    // Cached guess first: the loop evaluates at increasing times.
    if (last_ + 1 < t_.size() && t_[last_] <= t && t < t_[last_ + 1]) return last_;
    const auto it = std::upper_bound(t_.begin(), t_.end(), t);
    last_ = static_cast<std::size_t>(it - t_.begin()) - 1;
    return last_;
  }

  // Second derivatives m_i at the knots: tridiagonal system of the C2 conditions with clamped
  // (zero-slope) ends, solved by the Thomas algorithm (diagonally dominant, no pivoting needed). The
  // system's off-diagonals are the knot spacings, read from t_ where needed, and its right-hand side
  // is built in m_ and solved in place: one temporary (the diagonal) beside the result, so a long
  // path's start-up takes 8 bytes a knot more than its spline, not 56 (the Cortex-M7 image's RAM).
  void solve_second_derivatives() {
    const std::size_t n = t_.size();
    // Sub- and super-diagonal of row i: the spacing before and after knot i (none at the ends).
    const auto lower = [this](std::size_t i) { return i == 0 ? 0.0 : t_[i] - t_[i - 1]; };
    const auto upper = [this, n](std::size_t i) { return i + 1 == n ? 0.0 : t_[i + 1] - t_[i]; };
    std::vector<double> diag(n, 0);
    m_.assign(n, Point::Zero());
    std::vector<Point>& rhs = m_;
    for (std::size_t i = 0; i < n; ++i) {
      if (i == 0) {
        const double h = t_[1] - t_[0];
        diag[i] = 2 * h;
        rhs[i] = 6 * (y_[1] - y_[0]) / h;  // minus 6 * start slope (zero)
      } else if (i == n - 1) {
        const double h = t_[i] - t_[i - 1];
        diag[i] = 2 * h;
        rhs[i] = -6 * (y_[i] - y_[i - 1]) / h;  // plus 6 * end slope (zero)
      } else {
        const double h0 = t_[i] - t_[i - 1], h1 = t_[i + 1] - t_[i];
        diag[i] = 2 * (h0 + h1);
        rhs[i] = 6 * ((y_[i + 1] - y_[i]) / h1 - (y_[i] - y_[i - 1]) / h0);
      }
    }
    for (std::size_t i = 1; i < n; ++i) {
      const double w = lower(i) / diag[i - 1];
      diag[i] -= w * upper(i - 1);
      rhs[i] -= w * rhs[i - 1];
    }
    m_[n - 1] = rhs[n - 1] / diag[n - 1];
    for (std::size_t i = n - 1; i-- > 0;) m_[i] = (rhs[i] - upper(i) * m_[i + 1]) / diag[i];
  }

  std::vector<double> t_;
  std::vector<Point> y_;
  std::vector<Point> m_;
  mutable std::size_t last_ = 0;
};

// The desired active-joint trajectory q_d(t) = [swing rad, L_boom, L_arm, L_bucket] (m).
using JointTrajectory = CubicSpline<kNumActive>;

// The most knots of a trajectory the settings blob carries (app/settings_blob.hpp): 40 bytes each in
// the blob and 72 in the spline (1.4 MB at most in the target's RAM). The longest shipped task,
// truck_loading's five cycles sampled every 10 ms, has about 11000; a longer one is refused when its
// blob is made.
inline constexpr std::size_t kMaxTrajectoryKnots = 20000;

// The settings blob's field list: the knots; the decoder builds the spline through them (the same
// arithmetic as the host's, so the same spline bit for bit) or refuses knots that make none.
template <typename Visitor, int N>
void visit_fields(Visitor& v, CubicSpline<N>& s) {
  std::vector<double> times = s.times();
  std::vector<typename CubicSpline<N>::Point> points = s.points();
  v("times", times, kMaxTrajectoryKnots);
  v("points", points, kMaxTrajectoryKnots);
  if (v.decoding() && !s.assign(std::move(times), std::move(points)))
    v.refuse("times", "at least 2 knots, as many points as times, the times strictly increasing");
}

}  // namespace exc::control
