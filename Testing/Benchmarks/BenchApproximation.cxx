// Benchmark (not a test) of the VTK-free MLS core: evaluations per second of MLS degree 2 with 20
// neighbours in 2D (Halton cloud of N = 10,000 points, probes on a grid), single thread and all threads.
// Usage: BenchApproximation [evaluations (default 1,000,000)]
//
// The CUDA device: BenchApproximation --backend cuda [probes (default 10^7)] [cloud points (default 10^6)]
//   [CPU probes (default 10^6)]: MLS degree 2, Wendland, 2D (unit square) and 3D (unit cube) Halton clouds, probes on
//   an image covering the cloud generated on the device; evaluations/s of the device (whole EvaluateImage after a
//   warm-up run: kernel, output transfers and the CPU's finishing of the points handed back; and the kernel time
//   alone) beside the CPU with all threads on the smaller CPU probe count. Exit 77 without a usable device.
#include "Approximation/Approximation.h"
#include "Common/Parallel.h"
#include "TestFunctions.h"
#include "cuda/Device.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>


namespace
{
using meshfree::testing::Halton;

/// An image of about `count` points covering the unit square (dim 2) or cube (dim 3).
meshfree::ImageGeometry UnitImage(int dim, double count)
{
  meshfree::ImageGeometry image;
  const long side = std::lround(std::pow(count, 1.0 / dim));
  for (int a = 0; a < 3; ++a)
  {
    image.Origin[a] = 0.0;
    image.Dimensions[a] = a < dim ? side : 1;
    image.Spacing[a] = a < dim ? 1.0 / static_cast<double>(side - 1) : 0.0;
  }
  return image;
}

double Seconds(
  meshfree::Approximator& approx, const meshfree::ImageGeometry& image, const meshfree::ApproximationOutput& out)
{
  const auto t0 = std::chrono::steady_clock::now();
  approx.EvaluateImage(image, out);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int DeviceBenchmark(double probes, long cloudPoints, double cpuProbes)
{
  using namespace meshfree;
  std::string reason;
  if (!cuda::Available(&reason))
  {
    std::printf("SKIPPED: no usable CUDA device (%s)\n", reason.c_str());
    return 77;
  }
  std::printf("device: %s; CPU: %s\n", cuda::DeviceName().c_str(), ParallelBackend());
  for (int dim = 2; dim <= 3; ++dim)
  {
    const long n = cloudPoints;
    std::vector<double> xyz(3 * n), values(n);
    for (long i = 0; i < n; ++i)
    {
      for (int a = 0; a < 3; ++a)
      {
        xyz[3 * i + a] = a < dim ? Halton(static_cast<int>(i + 1), a == 0 ? 2 : (a == 1 ? 3 : 5)) : 0.0;
      }
      values[i] = std::sin(6 * xyz[3 * i]) * std::cos(4 * xyz[3 * i + 1]) + xyz[3 * i + 2];
    }
    for (int backend = 0; backend < 2; ++backend)
    {
      const bool device = backend == 0;
      ApproximationOptions options; // MLS, degree 2, Wendland, 20 neighbours
      options.Backend = device ? ApproximationBackend::CUDA : ApproximationBackend::CPU;
      Approximator approx;
      approx.SetOptions(options);
      approx.SetCloud(xyz.data(), n, values.data(), 1);
      const ImageGeometry image = UnitImage(dim, device ? probes : cpuProbes);
      const long m = static_cast<long>(image.NumberOfPoints());
      std::vector<double> out(m);
      ApproximationOutput o;
      o.Values = out.data();
      double warm = 0.0;
      if (device)
      {
        warm = Seconds(approx, image, o); // context, upload
      }
      const double best = Seconds(approx, image, o);
      const ApproximationReport& r = approx.Report();
      std::printf("MLS degree 2, 20 neighbours, %dD, N = %ld, image probes %ld: %s: %.3f s = %.4g evaluations/s", dim,
        n, m, r.Backend.c_str(), best, m / best);
      if (device)
      {
        std::printf(" (kernel %.3f s = %.4g evaluations/s; first run %.3f s; %lld points finished by the CPU)%s%s",
          r.DeviceKernelSeconds, r.DeviceKernelSeconds > 0.0 ? m / r.DeviceKernelSeconds : 0.0, warm,
          static_cast<long long>(r.DeviceToCPU), r.BackendNote.empty() ? "" : " note: ", r.BackendNote.c_str());
      }
      std::printf("\n");
      if (device && r.Backend.rfind("CUDA", 0) != 0)
      {
        std::printf("FAILED: the device did not run (%s)\n", r.BackendNote.c_str());
        return 1;
      }
    }
  }
  return 0;
}
} // namespace

int main(int argc, char* argv[])
{
  using namespace meshfree;
  if (argc > 2 && std::strcmp(argv[1], "--backend") == 0 && std::strcmp(argv[2], "cuda") == 0)
  {
    const double probes = argc > 3 ? std::atof(argv[3]) : 1e7;
    const long cloud = argc > 4 ? std::atol(argv[4]) : 1000000;
    const double cpuProbes = argc > 5 ? std::atof(argv[5]) : 1e6;
    return DeviceBenchmark(probes, cloud, cpuProbes);
  }
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
  ApproximationOptions options; // MLS, degree 2, Wendland, 20 neighbours
  options.Backend = ApproximationBackend::CPU;
  approx.SetOptions(options);
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
