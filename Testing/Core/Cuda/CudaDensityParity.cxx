// On a CUDA device: the density kernel gives the bits of the CPU function it shares (SPH/SPHDensity.h) for a
// random cloud with wall dummies, poly6 and spiky. Exit 77 (skipped) without a usable device.
#include "SPH/SPHDensity.h"
#include "cuda/Device.h"
#include "cuda/SPHDensity.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace
{
// CSR rows of every point of `to` within 1.5 h of each point of `from` (some beyond h: the function skips them).
void Rows(const std::vector<double>& from, const std::vector<double>& to, double h, bool self,
  std::vector<std::int64_t>& start, std::vector<std::int32_t>& rows)
{
  const std::size_t n = from.size() / 3, m = to.size() / 3;
  start.assign(n + 1, 0);
  rows.clear();
  for (std::size_t i = 0; i < n; ++i)
  {
    for (std::size_t j = 0; j < m; ++j)
    {
      double r2 = 0.0;
      for (int k = 0; k < 3; ++k)
      {
        r2 += (from[3 * i + k] - to[3 * j + k]) * (from[3 * i + k] - to[3 * j + k]);
      }
      if ((!self || i != j) && r2 < 2.25 * h * h)
      {
        rows.push_back(static_cast<std::int32_t>(j));
      }
    }
    start[i + 1] = static_cast<std::int64_t>(rows.size());
  }
}
}

int main()
{
  std::string reason;
  if (!meshfree::cuda::Available(&reason))
  {
    std::printf("SKIPPED: no usable CUDA device (%s)\n", reason.c_str());
    return 77;
  }
  std::printf("device: %s\n", meshfree::cuda::DeviceName().c_str());
  std::mt19937_64 random(15);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double h = 0.1;
  std::vector<double> x(3 * 3000), walls(3 * 500);
  for (double& v : x)
  {
    v = unit(random);
  }
  for (std::size_t b = 0; b < walls.size() / 3; ++b)
  {
    walls[3 * b] = unit(random);
    walls[3 * b + 1] = unit(random);
    walls[3 * b + 2] = -0.02 * unit(random);
  }
  std::vector<std::int64_t> fs, bs;
  std::vector<std::int32_t> fn, bn;
  Rows(x, x, h, true, fs, fn);
  Rows(x, walls, h, false, bs, bn);
  const std::int64_t n = static_cast<std::int64_t>(x.size() / 3);
  int failures = 0;
  for (int spiky = 0; spiky < 2; ++spiky)
  {
    meshfree::SPHDensityConstants c;
    c.H = h;
    c.H2 = h * h;
    c.Mass = 0.001;
    c.DensityNorm = spiky ? 4774.648292756860 : 1.5666814710608448e+09;
    c.SpikyDensity = spiky;
    std::vector<double> cpu(n), gpu(n, -1.0);
    for (std::int64_t i = 0; i < n; ++i)
    {
      cpu[i] = meshfree::SPHParticleDensity(i, x.data(), fs.data(), fn.data(), walls.data(), bs.data(), bn.data(), c);
    }
    std::string error;
    if (!meshfree::cuda::SPHDensityFromHost(n, x.data(), fs.data(), fn.data(),
          static_cast<std::int64_t>(walls.size() / 3), walls.data(), bs.data(), bn.data(), c, gpu.data(), &error))
    {
      std::printf("FAILED: the launcher: %s\n", error.c_str());
      return 1;
    }
    std::int64_t differ = 0;
    for (std::int64_t i = 0; i < n; ++i)
    {
      differ += std::memcmp(&cpu[i], &gpu[i], sizeof(double)) != 0 ? 1 : 0;
    }
    std::printf("%s: %lld of %lld densities differ from the CPU bits\n", spiky ? "spiky" : "poly6",
      static_cast<long long>(differ), static_cast<long long>(n));
    failures += differ != 0 ? 1 : 0;
  }
  return failures == 0 ? 0 : 1;
}
