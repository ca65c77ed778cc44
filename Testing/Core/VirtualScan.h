// A small virtual range scanner for the surface tests (after Berger et al. 2013, "A benchmark for surface
// reconstruction"): perspective range images of an analytic sphere (radius 1) or torus (R = 1, r = 0.35, axis
// z) from a few viewpoints, with occlusion (first hit along each ray, by sphere tracing the exact signed
// distance), Gaussian noise along the ray, and whatever no viewpoint sees left unsampled.
#ifndef meshfree_VirtualScan_h
#define meshfree_VirtualScan_h

#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace meshfree
{
namespace testing
{

constexpr double ScanRing = 1.0;
constexpr double ScanTube = 0.35;

/// Signed distance to the shape (exact, negative inside).
inline double ShapeDistance(const double* p, bool torus)
{
  if (!torus)
  {
    return std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1.0;
  }
  return std::hypot(std::hypot(p[0], p[1]) - ScanRing, p[2]) - ScanTube;
}

/// Unit outward normal of the shape at (near) p.
inline void ShapeNormal(const double* p, bool torus, double* n)
{
  double q[3] = { p[0], p[1], p[2] };
  if (torus)
  {
    const double rho = std::hypot(p[0], p[1]);
    q[0] = p[0] - ScanRing * p[0] / rho;
    q[1] = p[1] - ScanRing * p[1] / rho;
  }
  const double len = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
  for (int a = 0; a < 3; ++a)
  {
    n[a] = q[a] / len;
  }
}

/// A viewpoint at `distance` from the origin, at azimuth and elevation (degrees), looking at the origin.
inline std::array<double, 3> Viewpoint(double azimuth, double elevation, double distance)
{
  const double a = azimuth * M_PI / 180.0, e = elevation * M_PI / 180.0;
  return { distance * std::cos(e) * std::cos(a), distance * std::cos(e) * std::sin(a), distance * std::sin(e) };
}

struct ScanCloud
{
  std::vector<double> Points, Normals; // 3 per point; Normals exact and outward (at the noise-free hit)
  std::vector<int> View;               // which viewpoint saw the point
  long Count() const { return static_cast<long>(this->Points.size() / 3); }
};

/// Range images of resolution x resolution rays per viewpoint, over a square field of view that just holds the
/// shape; noise sigma along each ray (with depthSquared, sigma (t / D)^2 at range t from a viewpoint at distance D
/// from the origin: a triangulation scanner's error grows with the square of the range).
inline ScanCloud Scan(bool torus, const std::vector<std::array<double, 3>>& eyes, int resolution, double sigma,
  unsigned seed = 7, bool depthSquared = false)
{
  ScanCloud cloud;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  const double extent = torus ? ScanRing + ScanTube : 1.0;
  for (size_t view = 0; view < eyes.size(); ++view)
  {
    const double* eye = eyes[view].data();
    const double distance = std::sqrt(eye[0] * eye[0] + eye[1] * eye[1] + eye[2] * eye[2]);
    // Camera frame: forward towards the origin, right and up completing it.
    const double f[3] = { -eye[0] / distance, -eye[1] / distance, -eye[2] / distance };
    double r[3] = { f[1], -f[0], 0.0 };
    double len = std::hypot(r[0], r[1]);
    if (len < 1e-9)
    {
      r[0] = 1.0;
      r[1] = 0.0;
      len = 1.0;
    }
    r[0] /= len;
    r[1] /= len;
    const double u[3] = { r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0] };
    const double half = std::tan(std::asin(std::min(1.0, extent / distance))) * 1.02;
    for (int i = 0; i < resolution; ++i)
    {
      for (int j = 0; j < resolution; ++j)
      {
        const double sx = half * (2.0 * (i + 0.5) / resolution - 1.0);
        const double sy = half * (2.0 * (j + 0.5) / resolution - 1.0);
        double d[3];
        for (int a = 0; a < 3; ++a)
        {
          d[a] = f[a] + sx * r[a] + sy * u[a];
        }
        const double dl = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (double& c : d)
        {
          c /= dl;
        }
        double t = 0.0;
        bool hit = false;
        for (int it = 0; it < 400 && t < 2.0 * distance; ++it)
        {
          const double p[3] = { eye[0] + t * d[0], eye[1] + t * d[1], eye[2] + t * d[2] };
          const double s = ShapeDistance(p, torus);
          if (s < 1e-10)
          {
            hit = true;
            break;
          }
          t += s;
        }
        if (!hit)
        {
          continue;
        }
        const double p[3] = { eye[0] + t * d[0], eye[1] + t * d[1], eye[2] + t * d[2] };
        double n[3];
        ShapeNormal(p, torus, n);
        if (n[0] * d[0] + n[1] * d[1] + n[2] * d[2] > -0.25)
        {
          continue; // grazing (a real scanner drops returns beyond about 75 degrees of incidence)
        }
        const double e = sigma * (depthSquared ? (t / distance) * (t / distance) : 1.0) * gauss(rng);
        for (int a = 0; a < 3; ++a)
        {
          cloud.Points.push_back(p[a] + e * d[a]);
          cloud.Normals.push_back(n[a]);
        }
        cloud.View.push_back(static_cast<int>(view));
      }
    }
  }
  return cloud;
}

/// A patch of the plane z = 0, 2 x 1.4, sampled on a jittered grid of the given spacing (x the longest axis), with
/// three gaps where the scanner saw nothing: a round one at (-0.5, 0), 1.5 spacings in radius, which samples
/// surround within the trimming's limit; a wedge along x = 0.5 from y = -0.3 to 0.3 widening from 1 to 10
/// spacings; and a wedge along y = -0.5 from x = 0.25 to 0.95 widening from 1 to 8 spacings. The wedges' wide ends
/// lie beyond the limit. Normals +z.
inline ScanCloud GappedPlane(double spacing, unsigned seed = 5)
{
  ScanCloud cloud;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.2 * spacing, 0.2 * spacing);
  const int nx = static_cast<int>(std::lround(2.0 / spacing)), ny = static_cast<int>(std::lround(1.4 / spacing));
  for (int j = 0; j <= ny; ++j)
  {
    for (int i = 0; i <= nx; ++i)
    {
      const double x = -1.0 + i * spacing + jitter(rng), y = -0.7 + j * spacing + jitter(rng);
      const double along = y > -0.3 && y < 0.3 ? spacing * (0.5 + 4.5 * (y + 0.3) / 0.6) : -1.0;
      const double across = x > 0.25 && x < 0.95 ? spacing * (0.5 + 3.5 * (x - 0.25) / 0.7) : -1.0;
      if (std::hypot(x + 0.5, y) < 1.5 * spacing || std::abs(x - 0.5) < along || std::abs(y + 0.5) < across)
      {
        continue;
      }
      cloud.Points.insert(cloud.Points.end(), { x, y, 0.0 });
      cloud.Normals.insert(cloud.Normals.end(), { 0.0, 0.0, 1.0 });
      cloud.View.push_back(0);
    }
  }
  return cloud;
}

} // namespace testing
} // namespace meshfree

#endif
