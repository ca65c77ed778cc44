// Clouds sampled from analytic surfaces, shared by the surface-reconstruction and normals tests: uniform by
// area on the unit sphere and on the torus R = 1, r = 0.35 (axis z), and on the cube [-1, 1]^3, isotropic Gaussian
// noise, exact normals.
#ifndef meshfree_SurfaceSamples_h
#define meshfree_SurfaceSamples_h

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace meshfree
{
namespace testing
{
constexpr double RingRadius = 1.0;
constexpr double TubeRadius = 0.35;

struct SurfaceCloud
{
  std::vector<double> Points, Normals; // 3 per point; Normals exact and outward
  bool Torus = false;
  std::int64_t Count() const { return static_cast<std::int64_t>(this->Points.size() / 3); }
};

/// n points uniform by area on the unit sphere or the torus, Gaussian noise sigma per axis.
inline SurfaceCloud SampleSurface(bool torus, std::int64_t n, double sigma, unsigned seed = 12345)
{
  SurfaceCloud c;
  c.Torus = torus;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  while (c.Count() < n)
  {
    double p[3], m[3];
    if (!torus)
    {
      for (int a = 0; a < 3; ++a)
      {
        p[a] = g(rng);
      }
      const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      for (int a = 0; a < 3; ++a)
      {
        p[a] /= r;
        m[a] = p[a];
      }
    }
    else
    {
      const double u = 2.0 * M_PI * u01(rng), v = 2.0 * M_PI * u01(rng);
      if (u01(rng) * (RingRadius + TubeRadius) >= RingRadius + TubeRadius * std::cos(v))
      {
        continue; // area element (R + r cos v)
      }
      const double ring = RingRadius + TubeRadius * std::cos(v);
      p[0] = ring * std::cos(u);
      p[1] = ring * std::sin(u);
      p[2] = TubeRadius * std::sin(v);
      m[0] = std::cos(v) * std::cos(u);
      m[1] = std::cos(v) * std::sin(u);
      m[2] = std::sin(v);
    }
    for (int a = 0; a < 3; ++a)
    {
      c.Points.push_back(p[a] + sigma * g(rng));
      c.Normals.push_back(m[a]);
    }
  }
  return c;
}

/// n points uniform by area on the cube [-1, 1]^3, Gaussian noise sigma per axis; Normals: the face's.
inline SurfaceCloud SampleCube(std::int64_t n, double sigma, unsigned seed)
{
  SurfaceCloud c;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::int64_t i = 0; i < n; ++i)
  {
    const int face = static_cast<int>(rng() % 6);
    double p[3] = { u(rng), u(rng), u(rng) };
    p[face / 2] = face % 2 ? -1.0 : 1.0;
    for (int a = 0; a < 3; ++a)
    {
      c.Points.push_back(p[a] + sigma * g(rng));
      c.Normals.push_back(a == face / 2 ? p[a] : 0.0);
    }
  }
  return c;
}

/// Signed distance to the analytic surface (positive outside).
inline double SurfaceDistance(const double* p, bool torus)
{
  if (!torus)
  {
    return std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1.0;
  }
  return std::hypot(std::hypot(p[0], p[1]) - RingRadius, p[2]) - TubeRadius;
}

/// The exact outward unit normal at the surface point nearest to p.
inline void SurfaceNormal(const double* p, bool torus, double n[3])
{
  double q[3] = { p[0], p[1], p[2] };
  if (torus)
  {
    const double rho = std::hypot(p[0], p[1]);
    q[0] -= RingRadius * p[0] / rho;
    q[1] -= RingRadius * p[1] / rho;
  }
  const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
  for (int a = 0; a < 3; ++a)
  {
    n[a] = q[a] / len;
  }
}
} // namespace testing
} // namespace meshfree

#endif
