#pragma once
// The ground of a site (a scene's `terrain:`): flat at `height`, or piecewise linear in x along the
// swing plane through up to kMaxPoints points (held flat beyond the ends). The plant's soil is bounded
// by it; the firmware takes it as the site map its soil-contact estimate may use (never needs).
// Fixed-size: copied into the firmware's configuration, read every cycle without allocating.
#include <array>

#include "model/types.hpp"

namespace exc {

struct Terrain {
  static constexpr int kMaxPoints = 64;
  Terrain() { profile.fill(Vec2::Zero()); }
  double height = 0.0;  // m, world z of a flat terrain
  int num_points = 0;   // 0: flat; otherwise the profile below is used
  std::array<Vec2, kMaxPoints> profile;  // (x, z), x strictly increasing

  // World z of the ground at horizontal distance x from the swing axis.
  double height_at(double x) const;
};
// The settings blob's field list (app/settings_blob.hpp): the profile's first num_points points.
template <typename Visitor>
void visit_fields(Visitor& v, Terrain& t) {
  v("height", t.height);
  v.counted("profile", t.profile, t.num_points);
}

}  // namespace exc
