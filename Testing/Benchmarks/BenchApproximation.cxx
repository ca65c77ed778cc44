// Benchmark (not a test) of the VTK-free MLS core: evaluations per second of MLS degree 2 with 20
// neighbours in 2D (Halton cloud of N = 10,000 points, probes on a grid), single thread and all threads.
// Usage: BenchApproximation [evaluations (default 1,000,000)]
#include "TestFunctions.h"
#include "Approximation/Approximation.h"
#include "Common/Parallel.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>


namespace
{
using meshfree::testing::Halton;
}

int main(int argc, char* argv[])
{
  using namespace meshfree;
  const int n = 10000;
  const long requested = argc > 1 ? std::atol(argv[1]) : 1000000;
  const int side = static_cast<int>(std::sqrt(static_cast<double>(requested)));
  const long m = static_cast<long>(side) * side;
  std::vector<double> xyz(3 * n), values(n), eval(3 * m), out(m);
  for (int i = 0; i < n; ++i)
  {
    xyz[3 * i] = Halton(i + 1, 2);
    xyz[3 * i + 1] = Halton(i + 1, 3);
    xyz[3 * i + 2] = 0.0;
    values[i] = std::sin(6 * xyz[3 * i]) * std::cos(4 * xyz[3 * i + 1]);
  }
  for (long k = 0; k < m; ++k)
  {
    eval[3 * k] = static_cast<double>(k % side) / (side - 1);
    eval[3 * k + 1] = static_cast<double>(k / side) / (side - 1);
    eval[3 * k + 2] = 0.0;
  }
  Approximator approx;
  approx.SetOptions(ApproximationOptions()); // MLS, degree 2, Wendland, 20 neighbours
  approx.SetCloud(xyz.data(), n, values.data(), 1);
  ApproximationOutput o;
  o.Values = out.data();
  const int maxThreads = meshfree::MaxThreads();
  for (int threads : { 1, maxThreads })
  {
    meshfree::SetMaxThreads(threads);
    double best = 1e300;
    for (int repeat = 0; repeat < 3; ++repeat)
    {
      const auto t0 = std::chrono::steady_clock::now();
      approx.Evaluate(eval.data(), m, o);
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf("MLS degree 2, 20 neighbours, 2D, N = %d: %ld evaluations, %d thread(s): %.3f s = %.3g "
                "evaluations/s\n",
      n, m, threads, best, m / best);
  }
  return 0;
}
