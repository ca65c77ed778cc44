// The cloud of the MLS back-end tests (TestApproximationBackend, Cuda/CudaMLSParity): n random points in [-1, 1]^3
// (dim 3) or on a tilted plane (dim 2), the first 40 of them on a nearly collinear strip far from the rest, whose
// probes need the robust path or a fallback; two value components (a smooth function, noise).
#ifndef meshfree_StripCloud_h
#define meshfree_StripCloud_h

#include <cmath>
#include <random>
#include <vector>

namespace meshfree
{
namespace testing
{

inline void MakeStripCloud(int dim, int n, std::vector<double>& xyz, std::vector<double>& values, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  xyz.assign(3 * n, 0.0);
  values.assign(2 * n, 0.0);
  for (int i = 0; i < n; ++i)
  {
    double* x = &xyz[3 * i];
    x[0] = u(rng);
    x[1] = u(rng);
    x[2] = dim == 3 ? u(rng) : 0.3 * x[0] + 0.1 * x[1] + 2.0;
    if (i < 40) // the strip
    {
      x[0] = 2.0 + 1e-3 * i;
      x[1] = 2.0 + 1e-9 * u(rng);
      x[2] = dim == 3 ? 2.0 : 0.3 * x[0] + 0.1 * x[1] + 2.0;
    }
    values[2 * i] = std::sin(3.0 * x[0]) + x[1] * x[2];
    values[2 * i + 1] = u(rng);
  }
}

} // namespace testing
} // namespace meshfree

#endif
