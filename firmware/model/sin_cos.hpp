#pragma once
// The sine and cosine of one angle in one call where the C library has one: glibc's sincos on the
// host (the arithmetic the model was measured and tested with), the two calls elsewhere (newlib, the
// firmware's image, declares sincos only under _GNU_SOURCE and computes it as these two).
#include <cmath>

namespace exc {

inline void sin_cos(double angle, double* sine, double* cosine) {
#if defined(__GLIBC__)
  ::sincos(angle, sine, cosine);
#else
  *sine = std::sin(angle);
  *cosine = std::cos(angle);
#endif
}

}  // namespace exc
