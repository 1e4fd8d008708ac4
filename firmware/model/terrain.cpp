#include "model/terrain.hpp"

namespace exc {

double Terrain::height_at(double x) const {
  if (num_points <= 0) return height;
  if (x <= profile[0].x()) return profile[0].y();
  for (int i = 1; i < num_points; ++i) {
    if (x <= profile[i].x()) {
      const Vec2& a = profile[i - 1];
      const Vec2& b = profile[i];
      const double s = (x - a.x()) / (b.x() - a.x());
      return a.y() + s * (b.y() - a.y());
    }
  }
  return profile[num_points - 1].y();
}

}  // namespace exc
