// Scattered-data test material shared by the approximation tests and benchmarks.
#ifndef meshfree_TestFunctions_h
#define meshfree_TestFunctions_h

#include <cmath>

namespace meshfree
{
namespace testing
{
/// The i-th element (i >= 1) of the van der Corput sequence in `base`; pairs of coprime bases give
/// Halton points in the unit square/cube.
inline double Halton(int i, int base)
{
  double f = 1.0, r = 0.0;
  for (; i > 0; i /= base)
  {
    f /= base;
    r += f * (i % base);
  }
  return r;
}

/// Franke's function F1 exactly as in Franke (1982) and Renka's TSTFN1 - not Fasshauer's variant, which
/// squares the (9y + 1) term (research/mls.md).
inline double Franke(double x, double y)
{
  return 0.75 * std::exp(-((9 * x - 2) * (9 * x - 2) + (9 * y - 2) * (9 * y - 2)) / 4) +
    0.75 * std::exp(-(9 * x + 1) * (9 * x + 1) / 49 - (9 * y + 1) / 10) +
    0.5 * std::exp(-((9 * x - 7) * (9 * x - 7) + (9 * y - 3) * (9 * y - 3)) / 4) -
    0.2 * std::exp(-(9 * x - 4) * (9 * x - 4) - (9 * y - 7) * (9 * y - 7));
}
} // namespace testing
} // namespace meshfree

#endif
