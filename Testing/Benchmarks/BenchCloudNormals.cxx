// Meshless Normals' core (ComputeCloudNormals) on bench_scale.py's scan-like cloud, without VTK: the time of
// its stages and a digest of every output array's bits (to check that a speed-up leaves the results unchanged).
// Usage: BenchCloudNormals [--points N] [--repeat R] [--curvature 0|1] [--shuffle 0|1] [--full 0|1] [--wide 0|1]
//        [--support RADIUS] [--xyz CLOUD.xyz] [--noise FRACTION] [--accuracy 0|1] [--vector 0|1] [--alone 0|1]
// The cloud: a sphere (radius 0.5) inside a torus (R = 1, r = 0.25), points spread evenly over their area, each
// moved along its normal by Gaussian noise of 0.1 % of the bounding box's diagonal (bench_scale.py's formula;
// libm's log/cos may differ from numpy's in the last bit). --xyz reads "x y z" lines instead. --shuffle 1 permutes
// the input (a fixed permutation) and digests the results in the original order: the digest must not change.
// --wide 0 and --support R: NormalOptions::WideNormals and ::SupportRadius (Meshless Surface's narrow normals, a
// fixed radius). Stages: the grid and EstimateNormals timed alone, then the whole ComputeCloudNormals (grid, normals,
// orientation, curvature; --full 0 skips it and times the cloud's scale, EstimateCloudScale, alone instead;
// --alone 0 skips the grid and EstimateNormals timed alone: ComputeCloudNormals only, as the plugin runs it, e.g.
// under a profiler). Threads: all the CPUs, or MESHFREE_NUM_THREADS.
// --noise: sigma as a fraction of the diagonal (default 0.001). --accuracy 1: the Curvature's relative error against
// the exact mean curvature (sphere 1 / rs; torus (R + 2 r cos v) / (2 r (R + r cos v))), mean / p99 / max, separately
// on the sphere and the torus (points with Curvature 0 or an invalid normal count as error 1).
// --vector 0: the portable code instead of the vector kernels (the grid's distance filter and the fits' sums):
// the digest must not change.
#include "Common/NeighborGrid.h"
#include "Common/Parallel.h"
#include "Surface/CloudNormals.h"
#include "Surface/SurfaceNormals.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <sys/resource.h>

namespace
{
double Seconds(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// CPU seconds of the process (all threads; on a shared machine steadier than the wall clock).
double CpuSeconds()
{
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
    1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

std::uint64_t Mix(std::uint64_t x)
{
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

double Uniform(std::int64_t i, std::uint64_t seed)
{
  const std::uint64_t x = Mix((static_cast<std::uint64_t>(i) * 2 + seed) * 0x9E3779B97F4A7C15ULL);
  return (static_cast<double>(x >> 11) + 0.5) / static_cast<double>(1ULL << 53);
}

std::vector<double> ScanCloud(
  std::int64_t count, double noiseFraction, std::vector<double>& exact, std::int64_t& sphereCount)
{
  const double pi = 3.141592653589793238462643383279502884;
  const double R = 1.0, r = 0.25, rs = 0.5;
  const double sphereArea = 4 * pi * rs * rs, torusArea = 4 * pi * pi * R * r;
  const std::int64_t onSphere = std::llround(count * sphereArea / (sphereArea + torusArea));
  const double sigma = noiseFraction * std::sqrt(2.5 * 2.5 + 2.5 * 2.5 + 0.5 * 0.5);
  std::vector<double> xyz(3 * static_cast<size_t>(count));
  exact.assign(static_cast<size_t>(count), 0.0);
  sphereCount = onSphere;
  for (std::int64_t i = 0; i < count; ++i)
  {
    double p[3], n[3];
    if (i < onSphere)
    {
      const double k = static_cast<double>(i);
      const double z = 1.0 - 2.0 * (k + 0.5) / static_cast<double>(onSphere);
      const double phi = k * pi * (3.0 - std::sqrt(5.0));
      const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
      n[0] = rho * std::cos(phi);
      n[1] = rho * std::sin(phi);
      n[2] = z;
      for (int a = 0; a < 3; ++a)
      {
        p[a] = rs * n[a];
      }
      exact[i] = 1.0 / rs;
    }
    else
    {
      const double k = static_cast<double>(i - onSphere);
      const double g = 1.32471795724474602596;
      const double u = std::fmod(0.5 + k / g, 1.0), w = std::fmod(0.5 + k / (g * g), 1.0);
      const double theta = 2 * pi * u;
      double v = 2 * pi * w;
      for (int it = 0; it < 8; ++it)
      {
        v -= (R * v + r * std::sin(v) - 2 * pi * R * w) / (R + r * std::cos(v));
      }
      n[0] = std::cos(v) * std::cos(theta);
      n[1] = std::cos(v) * std::sin(theta);
      n[2] = std::sin(v);
      p[0] = (R + r * std::cos(v)) * std::cos(theta);
      p[1] = (R + r * std::cos(v)) * std::sin(theta);
      p[2] = r * std::sin(v);
      exact[i] = (R + 2 * r * std::cos(v)) / (2 * r * (R + r * std::cos(v)));
    }
    const double noise = sigma * std::sqrt(-2 * std::log(Uniform(i, 1))) * std::cos(2 * pi * Uniform(i, 2));
    for (int a = 0; a < 3; ++a)
    {
      xyz[3 * i + a] = p[a] + noise * n[a];
    }
  }
  return xyz;
}

/// FNV-1a over the bytes of the values.
template <class T>
std::uint64_t Digest(const std::vector<T>& values, std::uint64_t h = 1469598103934665603ULL)
{
  const unsigned char* bytes = reinterpret_cast<const unsigned char*>(values.data());
  for (size_t b = 0; b < values.size() * sizeof(T); ++b)
  {
    h = (h ^ bytes[b]) * 1099511628211ULL;
  }
  return h;
}

/// Mean, 99th percentile and largest of the relative errors |k - h| / |h| over the points [begin, end).
void PrintErrors(const char* name, const std::vector<double>& k, const std::vector<double>& h,
  const std::vector<unsigned char>& valid, size_t begin, size_t end)
{
  std::vector<double> e;
  for (size_t i = begin; i < end; ++i)
  {
    e.push_back(valid[i] && k[i] != 0.0 && std::isfinite(k[i]) ? std::fabs(k[i] - h[i]) / std::fabs(h[i]) : 1.0);
  }
  if (e.empty())
  {
    return;
  }
  double mean = 0.0;
  for (double x : e)
  {
    mean += x;
  }
  mean /= static_cast<double>(e.size());
  std::sort(e.begin(), e.end());
  std::printf("curvature error %s (%zu points): mean %.4g, p99 %.4g, max %.4g\n", name, e.size(), mean,
    e[std::min(e.size() - 1, e.size() * 99 / 100)], e.back());
}
} // namespace

int main(int argc, char** argv)
{
  std::int64_t count = 1000000;
  int repeat = 1;
  bool curvature = true, shuffle = false, full = true, accuracy = false, alone = true;
  double noiseFraction = 0.001;
  std::string xyzFile;
  meshfree::NormalOptions neighborhood;
  for (int a = 1; a + 1 < argc; a += 2)
  {
    const std::string key = argv[a], value = argv[a + 1];
    if (key == "--points")
    {
      count = std::atoll(value.c_str());
    }
    else if (key == "--repeat")
    {
      repeat = std::atoi(value.c_str());
    }
    else if (key == "--curvature")
    {
      curvature = value != "0";
    }
    else if (key == "--full")
    {
      full = value != "0";
    }
    else if (key == "--alone")
    {
      alone = value != "0";
    }
    else if (key == "--shuffle")
    {
      shuffle = value != "0";
    }
    else if (key == "--wide")
    {
      neighborhood.WideNormals = value != "0";
    }
    else if (key == "--support")
    {
      neighborhood.SupportRadius = std::atof(value.c_str());
    }
    else if (key == "--noise")
    {
      noiseFraction = std::atof(value.c_str());
    }
    else if (key == "--accuracy")
    {
      accuracy = value != "0";
    }
    else if (key == "--vector")
    {
      meshfree::NeighborGrid::SetVectorized(value != "0");
      meshfree::SetNormalKernelsVectorized(value != "0");
    }
    else if (key == "--xyz")
    {
      xyzFile = value;
    }
    else
    {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
      return 2;
    }
  }
  std::vector<double> xyz, exact;
  std::int64_t sphereCount = 0;
  if (!xyzFile.empty())
  {
    FILE* f = std::fopen(xyzFile.c_str(), "r");
    if (!f)
    {
      std::fprintf(stderr, "cannot read %s\n", xyzFile.c_str());
      return 1;
    }
    double p[3];
    while (std::fscanf(f, "%lf %lf %lf", &p[0], &p[1], &p[2]) == 3)
    {
      xyz.insert(xyz.end(), p, p + 3);
    }
    std::fclose(f);
    count = static_cast<std::int64_t>(xyz.size() / 3);
  }
  else
  {
    xyz = ScanCloud(count, noiseFraction, exact, sphereCount);
  }
  // A fixed permutation: input position j holds point perm[j].
  std::vector<std::int64_t> perm(static_cast<size_t>(count));
  for (std::int64_t j = 0; j < count; ++j)
  {
    perm[j] = j;
  }
  if (shuffle)
  {
    for (std::int64_t j = count - 1; j > 0; --j)
    {
      std::swap(perm[j], perm[Mix(static_cast<std::uint64_t>(j) + 12345) % static_cast<std::uint64_t>(j + 1)]);
    }
    std::vector<double> moved(xyz.size());
    for (std::int64_t j = 0; j < count; ++j)
    {
      std::memcpy(&moved[3 * j], &xyz[3 * perm[j]], 3 * sizeof(double));
    }
    xyz.swap(moved);
  }
  std::printf("%lld points, %d threads, curvature %d, shuffle %d\n", static_cast<long long>(count),
    meshfree::MaxThreads(), curvature ? 1 : 0, shuffle ? 1 : 0);
  for (int rep = 0; rep < repeat; ++rep)
  {
    auto start = std::chrono::steady_clock::now();
    double cpu = CpuSeconds();
    meshfree::NeighborGrid grid;
    double gridSeconds = 0.0, normalSeconds = 0.0, normalCpu = 0.0;
    if (alone || !full)
    {
      grid.Build(xyz.data(), static_cast<meshfree::Index>(count));
      gridSeconds = Seconds(start);
      start = std::chrono::steady_clock::now();
      meshfree::NormalField field;
      meshfree::EstimateNormals(grid, neighborhood, field);
      normalSeconds = Seconds(start);
      normalCpu = CpuSeconds() - cpu;
    }

    if (!full)
    {
      // The cloud's scale alone (EstimateNormals computes it first: its sample's jets, a cost that does not grow
      // with the cloud).
      start = std::chrono::steady_clock::now();
      cpu = CpuSeconds();
      meshfree::EstimateCloudScale(grid, neighborhood);
      std::printf("grid %.3f s, EstimateNormals %.3f s (grid + normals: cpu %.3f s), of which the scale ~%.3f s "
                  "(cpu %.3f s)\n",
        gridSeconds, normalSeconds, normalCpu, Seconds(start), CpuSeconds() - cpu);
      continue;
    }
    meshfree::CloudNormalsOptions options;
    options.ComputeCurvature = curvature;
    options.Neighborhood = neighborhood;
    meshfree::CloudNormalsResult result;
    start = std::chrono::steady_clock::now();
    cpu = CpuSeconds();
    meshfree::ComputeCloudNormals(xyz.data(), static_cast<meshfree::Index>(count), nullptr, options, result);
    const double totalSeconds = Seconds(start);
    const double totalCpu = CpuSeconds() - cpu;
    // The results in the original order.
    std::vector<double> normals(3 * static_cast<size_t>(count)), curv(count), variation(count), confidence(count),
      radius(count);
    std::vector<unsigned char> valid(count);
    for (std::int64_t j = 0; j < count; ++j)
    {
      const std::int64_t i = perm[j];
      std::memcpy(&normals[3 * i], &result.Normals[3 * j], 3 * sizeof(double));
      curv[i] = result.Curvature[j];
      variation[i] = result.SurfaceVariation[j];
      confidence[i] = result.Confidence[j];
      radius[i] = result.Radius[j];
      valid[i] = result.Valid[j];
    }
    // ComputeCloudNormals builds its grid and estimates the normals again: beyond those, it orients them and fits
    // the curvature's spheres.
    if (alone)
    {
      std::printf("grid %.3f s, EstimateNormals %.3f s (cpu %.3f s); ComputeCloudNormals %.3f s (cpu %.3f s, of "
                  "which orientation + curvature ~%.3f s cpu)\n",
        gridSeconds, normalSeconds, normalCpu, totalSeconds, totalCpu, totalCpu - normalCpu);
    }
    else
    {
      std::printf("ComputeCloudNormals %.3f s (cpu %.3f s)\n", totalSeconds, totalCpu);
    }
    std::printf("noise %.4g, spacing %.4g, normal radius %.4g, fits radius %.4g, fit noise %.4g, curvature %.4g, "
                "invalid %lld, outliers %lld\n",
      result.Scale.Noise, result.Scale.Spacing, result.Scale.NormalRadius, result.Scale.Radius, result.Scale.FitNoise,
      result.Scale.Curvature, static_cast<long long>(result.Invalid), static_cast<long long>(result.Outliers));
    std::printf("digest: normals %016llx curvature %016llx variation %016llx confidence %016llx radius %016llx "
                "valid %016llx\n",
      static_cast<unsigned long long>(Digest(normals)), static_cast<unsigned long long>(Digest(curv)),
      static_cast<unsigned long long>(Digest(variation)), static_cast<unsigned long long>(Digest(confidence)),
      static_cast<unsigned long long>(Digest(radius)), static_cast<unsigned long long>(Digest(valid)));
    if (accuracy && curvature && !exact.empty())
    {
      PrintErrors("sphere", curv, exact, valid, 0, static_cast<size_t>(sphereCount));
      PrintErrors("torus", curv, exact, valid, static_cast<size_t>(sphereCount), exact.size());
    }
    std::fflush(stdout);
  }
  return 0;
}
