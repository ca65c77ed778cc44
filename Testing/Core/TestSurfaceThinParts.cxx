// SPDX-License-Identifier: BSD-3-Clause
// Parts thinner than the fits' support stay whole (issue 23, "no stray pieces, thin parts whole"): a thin slab
// and a thin capsule (rod), sampled on their surface with noise, positions only, reconstructed by MLS and WLS:
// one closed piece of the right topology, neither torn (no holes, no boundary) nor doubled or collapsed (every
// vertex near the true surface, the enclosed volume near the true one). And a closed block whose top face has
// steps, scanned from above and around with the underside unseen, reconstructed by WLS with hole filling: no
// crack (closed, one piece) and no vertex on the stepped face off it by more than the noise allows.
#include "Surface/MeshTopology.h"
#include "Surface/SurfaceReconstruction.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

using namespace meshfree;

namespace
{
/// Exact signed distance to the box |x| <= h (half extents), negative inside.
double BoxDistance(const double* p, const double* h)
{
  double outside = 0.0, inside = -1e300;
  for (int a = 0; a < 3; ++a)
  {
    const double d = std::fabs(p[a]) - h[a];
    outside += d > 0.0 ? d * d : 0.0;
    inside = std::max(inside, d);
  }
  return outside > 0.0 ? std::sqrt(outside) : inside;
}

/// n samples uniform by area on the surface of the box |x| <= h, noise sigma along the face normal.
std::vector<double> SampleBox(const double* h, int n, double sigma, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> g;
  const double faces[3] = { h[1] * h[2], h[0] * h[2], h[0] * h[1] }; // area of a face normal to axis a, / 4
  const double total = 2.0 * (faces[0] + faces[1] + faces[2]);
  std::uniform_real_distribution<double> pick(0.0, total);
  std::vector<double> points;
  points.reserve(static_cast<size_t>(3 * n));
  for (int i = 0; i < n; ++i)
  {
    double r = pick(rng);
    int axis = 0;
    while (axis < 2 && r >= 2.0 * faces[axis])
    {
      r -= 2.0 * faces[axis];
      ++axis;
    }
    const double side = r < faces[axis] ? -1.0 : 1.0;
    double p[3];
    for (int a = 0; a < 3; ++a)
    {
      p[a] = a == axis ? side * (h[a] + sigma * g(rng)) : h[a] * u(rng);
    }
    points.insert(points.end(), p, p + 3);
  }
  return points;
}

/// Exact signed distance to the capsule of radius r around the segment z in [-l, l] on the z axis.
double CapsuleDistance(const double* p, double r, double l)
{
  const double z = std::max(-l, std::min(l, p[2]));
  return std::sqrt(p[0] * p[0] + p[1] * p[1] + (p[2] - z) * (p[2] - z)) - r;
}

/// n samples uniform by area on that capsule, noise sigma along the normal.
std::vector<double> SampleCapsule(double r, double l, int n, double sigma, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g;
  const double side = 2.0 * M_PI * r * 2.0 * l, caps = 4.0 * M_PI * r * r;
  std::vector<double> points;
  for (int i = 0; i < n; ++i)
  {
    double dir[3], centre[3] = { 0.0, 0.0, 0.0 };
    if (u(rng) * (side + caps) < side)
    {
      const double phi = 2.0 * M_PI * u(rng);
      dir[0] = std::cos(phi);
      dir[1] = std::sin(phi);
      dir[2] = 0.0;
      centre[2] = l * (2.0 * u(rng) - 1.0);
    }
    else
    {
      const double z = 2.0 * u(rng) - 1.0, phi = 2.0 * M_PI * u(rng), s = std::sqrt(1.0 - z * z);
      dir[0] = s * std::cos(phi);
      dir[1] = s * std::sin(phi);
      dir[2] = z;
      centre[2] = z > 0.0 ? l : -l;
    }
    const double rr = r + sigma * g(rng);
    for (int a = 0; a < 3; ++a)
    {
      points.push_back(centre[a] + rr * dir[a]);
    }
  }
  return points;
}

struct Result
{
  SurfaceMesh Mesh;
  SurfaceReport Report;
  MeshTopology Topology;
  double Volume = 0.0;
};

Result Reconstruct(const std::vector<double>& points, SurfaceMethod method, HoleFillingMode fill = HoleFillingMode::Auto)
{
  SurfaceInput in;
  in.Points = points.data();
  in.Count = static_cast<Index>(points.size() / 3);
  SurfaceOptions options;
  options.Method = method;
  options.HoleFilling = fill;
  Result r;
  std::string error;
  EXPECT_TRUE(ReconstructSurface(in, options, r.Mesh, r.Report, error)) << error;
  r.Topology = ComputeMeshTopology(r.Mesh.Triangles, r.Mesh.NumberOfPoints());
  r.Volume = r.Topology.Closed() ? EnclosedVolume(r.Mesh.Points, r.Mesh.Triangles) : 0.0;
  return r;
}

/// Largest |distance| of the mesh's vertices to the true surface.
template <typename Distance>
double WorstVertex(const SurfaceMesh& mesh, Distance distance)
{
  double worst = 0.0;
  for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
  {
    worst = std::max(worst, std::fabs(distance(&mesh.Points[3 * v])));
  }
  return worst;
}
} // namespace

TEST(SurfaceThinParts, ThinSlabStaysOneClosedSheet)
{
  // A slab 2 x 2 x 0.06: 24,000 samples (spacing about 0.018), so its thickness is about two thirds of the
  // fits' support (0.093, reported below); noise 0.001. Measured: closed, one piece, volume within 6 %, the
  // faces within 3 sigma. Limit (not tested): at half the support and below (thickness 0.04-0.05 here) the
  // two sides' spread is taken for noise, the support grows and the sheet collapses into one open layer.
  const double h[3] = { 1.0, 1.0, 0.03 };
  const double sigma = 0.001;
  const std::vector<double> points = SampleBox(h, 24000, sigma, 3);
  for (SurfaceMethod method : { SurfaceMethod::MLS, SurfaceMethod::WLS })
  {
    const Result r = Reconstruct(points, method);
    // The faces, away from the rim the support rounds: every vertex there near the face it belongs to.
    const double rim = 1.0 - r.Report.SupportRadius;
    const double worst = WorstVertex(r.Mesh, [&](const double* p) {
      return std::fabs(p[0]) < rim && std::fabs(p[1]) < rim ? std::fabs(p[2]) - h[2] : 0.0;
    });
    const double volume = 8.0 * h[0] * h[1] * h[2];
    std::printf("slab, %s: support %.3f (thickness %.3f), %ld triangles, %ld boundary edges, %ld pieces, chi %ld, "
                "volume %.4f (true %.4f), worst face vertex %.2f sigma\n",
      SurfaceMethodName(method), r.Report.SupportRadius, 2.0 * h[2], static_cast<long>(r.Topology.Triangles),
      static_cast<long>(r.Topology.BoundaryEdges), static_cast<long>(r.Topology.Components),
      static_cast<long>(r.Topology.EulerCharacteristic), r.Volume, volume, worst / sigma);
    EXPECT_GT(r.Report.SupportRadius, 2.0 * h[2]) << "the slab must be thinner than the support";
    EXPECT_TRUE(r.Topology.Closed()) << SurfaceMethodName(method);
    EXPECT_EQ(r.Topology.Components, 1) << SurfaceMethodName(method);
    EXPECT_EQ(r.Topology.EulerCharacteristic, 2) << SurfaceMethodName(method);
    // Neither collapsed nor doubled: the enclosed volume within 10 % and the faces' vertices within 3 sigma of
    // them (measured 1.1-1.3 sigma).
    EXPECT_NEAR(r.Volume, volume, 0.1 * volume) << SurfaceMethodName(method);
    EXPECT_LT(worst, 3.0 * sigma) << SurfaceMethodName(method);
  }
}

TEST(SurfaceThinParts, ThinRodStaysOneClosedTube)
{
  // A capsule of radius 0.02 around a segment of length 1: 2,500 samples (spacing about 0.007), so the fits'
  // support (0.036, reported below) is about the rod's diameter; noise 0.0005. Measured: closed, one piece, volume
  // -1.4 % (MLS) / -3.7 % (WLS), worst vertex 0.0024 / 0.0009 (at the caps). Limit (not tested): with 1,500
  // samples the support grows to twice the diameter and the tube swells (volume +7 % / +23 %).
  const double radius = 0.02, half = 0.5, sigma = 0.0005;
  const std::vector<double> points = SampleCapsule(radius, half, 2500, sigma, 4);
  for (SurfaceMethod method : { SurfaceMethod::MLS, SurfaceMethod::WLS })
  {
    const Result r = Reconstruct(points, method);
    const double worst = WorstVertex(r.Mesh, [&](const double* p) { return CapsuleDistance(p, radius, half); });
    const double volume = M_PI * radius * radius * 2.0 * half + 4.0 / 3.0 * M_PI * radius * radius * radius;
    std::printf("rod, %s: support %.4f (diameter %.3f), %ld triangles, %ld boundary edges, %ld pieces, chi %ld, "
                "volume %.3e (true %.3e), worst vertex %.4f\n",
      SurfaceMethodName(method), r.Report.SupportRadius, 2.0 * radius, static_cast<long>(r.Topology.Triangles),
      static_cast<long>(r.Topology.BoundaryEdges), static_cast<long>(r.Topology.Components),
      static_cast<long>(r.Topology.EulerCharacteristic), r.Volume, volume, worst);
    EXPECT_GT(r.Report.SupportRadius, 0.8 * 2.0 * radius) << "the rod must be about as thin as the support";
    EXPECT_TRUE(r.Topology.Closed()) << SurfaceMethodName(method);
    EXPECT_EQ(r.Topology.Components, 1) << SurfaceMethodName(method);
    EXPECT_EQ(r.Topology.EulerCharacteristic, 2) << SurfaceMethodName(method);
    EXPECT_NEAR(r.Volume, volume, 0.1 * volume) << SurfaceMethodName(method);
    EXPECT_LT(worst, 0.15 * radius) << SurfaceMethodName(method);
  }
}

TEST(SurfaceThinParts, SteppedBlockScanClosesWithoutCracks)
{
  // A block [-1, 1]^2 x [0, top(x)] whose top has three levels 0.5 / 0.6 / 0.7 (steps at x = -1/3, 1/3), sampled
  // like a scan from above and around (top, risers and sides; the underside z = 0 unseen), 30,000 samples, noise
  // 0.001 along the faces' normals, positions only. WLS with hole filling: closed, one piece, chi 2
  // (no crack between the patches along the steps or across the filled underside), and every vertex on the
  // top faces, away from the steps and the rim by one support, within 3 sigma of its level (measured 1.3).
  const double sigma = 0.001;
  const double levels[3] = { 0.5, 0.6, 0.7 };
  const auto level = [&](double x) { return levels[x < -1.0 / 3.0 ? 0 : (x < 1.0 / 3.0 ? 1 : 2)]; };
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  std::normal_distribution<double> g;
  // Areas: top 4, risers 2 x 0.1 x 2, sides: x = -1 (0.5 x 2), x = 1 (0.7 x 2), y = +-1 (integral of top = 1.2 each).
  const double areas[4] = { 4.0, 0.4, 1.0 + 1.4, 2.4 };
  const double total = areas[0] + areas[1] + areas[2] + areas[3];
  std::vector<double> points;
  for (int i = 0; i < 30000; ++i)
  {
    const double r = unit(rng) * total;
    const double e = sigma * g(rng);
    if (r < areas[0])
    {
      const double x = u(rng), y = u(rng);
      points.insert(points.end(), { x, y, level(x) + e });
    }
    else if (r < areas[0] + areas[1])
    {
      const double x = unit(rng) < 0.5 ? -1.0 / 3.0 : 1.0 / 3.0;
      const double z = level(x - 0.01) + 0.1 * unit(rng);
      points.insert(points.end(), { x - e, u(rng), z });
    }
    else if (r < areas[0] + areas[1] + areas[2])
    {
      const bool left = unit(rng) * 2.4 < 1.0;
      const double x = left ? -1.0 - e : 1.0 + e;
      points.insert(points.end(), { x, u(rng), (left ? 0.5 : 0.7) * unit(rng) });
    }
    else
    {
      double x, z;
      do
      {
        x = u(rng);
        z = 0.7 * unit(rng);
      } while (z > level(x));
      points.insert(points.end(), { x, unit(rng) < 0.5 ? -1.0 - e : 1.0 + e, z });
    }
  }
  // HoleFilling On: the cloud's OpenShare, 0.44 (the underside's 4 over the data's 9.2), is near Auto's 0.45.
  const Result r = Reconstruct(points, SurfaceMethod::WLS, HoleFillingMode::On);
  double worst = 0.0;
  Index counted = 0;
  const double keep = r.Report.SupportRadius;
  for (Index v = 0; v < r.Mesh.NumberOfPoints(); ++v)
  {
    const double* p = &r.Mesh.Points[3 * v];
    const bool awayFromEdges = std::fabs(p[0]) < 1.0 - keep && std::fabs(p[1]) < 1.0 - keep &&
      std::fabs(std::fabs(p[0]) - 1.0 / 3.0) > keep;
    if (awayFromEdges && p[2] > 0.4)
    {
      worst = std::max(worst, std::fabs(p[2] - level(p[0])));
      ++counted;
    }
  }
  std::printf("stepped block, WLS: open share %.2f, filled %d, support %.3f, %ld boundary edges, %ld pieces, chi %ld, "
              "%ld top vertices, worst %.2f sigma off its level\n",
    r.Report.OpenShare, r.Report.HolesFilled ? 1 : 0, r.Report.SupportRadius,
    static_cast<long>(r.Topology.BoundaryEdges), static_cast<long>(r.Topology.Components),
    static_cast<long>(r.Topology.EulerCharacteristic), static_cast<long>(counted), worst / sigma);
  EXPECT_TRUE(r.Report.HolesFilled);
  EXPECT_EQ(r.Topology.BoundaryEdges, 0);
  EXPECT_EQ(r.Topology.NonManifoldEdges, 0);
  EXPECT_EQ(r.Topology.Components, 1);
  EXPECT_EQ(r.Topology.EulerCharacteristic, 2);
  EXPECT_GT(counted, 1000);
  EXPECT_LT(worst, 3.0 * sigma);
}
