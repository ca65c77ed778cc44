// SPDX-License-Identifier: BSD-3-Clause
// What the C++ MPI tests share: a check that reports on its rank and counts failures, and a seeded random cloud
// that every rank builds alike.
#ifndef MPITestSupport_h
#define MPITestSupport_h

#include <cstdio>
#include <random>
#include <vector>

namespace mpitest
{
inline int Rank = 0;
inline int Failures = 0;

/// Prints "ERROR: rank R: what (value)" and counts a failure when !ok.
inline void Check(bool ok, const char* what, double value = 0.0)
{
  if (!ok)
  {
    std::printf("ERROR: rank %d: %s (%g)\n", Rank, what, value);
    ++Failures;
  }
}

/// n points (x, y, z interleaved) uniform in [lo, hi)^3, the same on every rank for the same seed.
inline std::vector<double> RandomPoints(int n, unsigned seed, double lo = 0.0, double hi = 1.0)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> xyz(3 * static_cast<size_t>(n));
  for (double& v : xyz)
  {
    v = u(rng);
  }
  return xyz;
}
} // namespace mpitest

#endif
