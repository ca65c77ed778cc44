// SPDX-License-Identifier: BSD-3-Clause
// Surface reconstruction (Surface/SurfaceReconstruction.h) on 20k-point clouds of a sphere and a torus, with
// and without noise and normals, the SPH colour-field surface of a particle ball, and hostile inputs.
//
// Bounds are the 100k-point targets (research/surface.md §5) scaled to 20k points: the spacing grows
// by sqrt(5) = 2.24; with noise the error goes as sqrt(sigma h) (the support follows the noise, so the
// neighbours averaged grow as sigma / h): x 1.5; without noise the APSS/quadric fit's error is O(h^3): x 11.
#include "Surface/MeshTopology.h"
#include "Surface/PatchSurface.h"
#include "Surface/SurfaceReconstruction.h"
#include "SurfaceSamples.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using namespace meshfree;
namespace samples = meshfree::testing;

namespace
{
using samples::RingRadius;
using samples::TubeRadius;
using Cloud = samples::SurfaceCloud;

Cloud Sample(bool torus, Index n, double sigma)
{
  return samples::SampleSurface(torus, n, sigma);
}

struct Score
{
  double Rms = 0.0, Max = 0.0, Bias = 0.0, WorstNormal = 0.0; // WorstNormal: largest angle (rad) to the truth
  MeshTopology Topology;
  Index NonFinite = 0;
};

Score Evaluate(const SurfaceMesh& mesh, bool torus)
{
  Score s;
  const Index nv = mesh.NumberOfPoints();
  for (Index v = 0; v < nv; ++v)
  {
    const double* p = &mesh.Points[3 * v];
    const double* n = &mesh.Normals[3 * v];
    if (!std::isfinite(p[0] + p[1] + p[2] + n[0] + n[1] + n[2]))
    {
      ++s.NonFinite;
      continue;
    }
    const double d = samples::SurfaceDistance(p, torus);
    s.Rms += d * d;
    s.Bias += d;
    s.Max = std::max(s.Max, std::fabs(d));
    double t[3];
    samples::SurfaceNormal(p, torus, t);
    const double c = std::max(-1.0, std::min(1.0, n[0] * t[0] + n[1] * t[1] + n[2] * t[2]));
    s.WorstNormal = std::max(s.WorstNormal, std::acos(c));
  }
  s.Rms = std::sqrt(s.Rms / std::max<Index>(1, nv));
  s.Bias /= std::max<Index>(1, nv);
  s.Topology = ComputeMeshTopology(mesh.Triangles, nv);
  return s;
}

SurfaceMesh Reconstruct(const Cloud& c, bool withNormals, SurfaceMethod method, SurfaceReport* out = nullptr)
{
  SurfaceInput in;
  in.Points = c.Points.data();
  in.Count = c.Count();
  in.Normals = withNormals ? c.Normals.data() : nullptr;
  SurfaceOptions options;
  options.Method = method;
  SurfaceMesh mesh;
  SurfaceReport report;
  std::string error;
  EXPECT_TRUE(ReconstructSurface(in, options, mesh, report, error)) << error;
  if (out)
  {
    *out = report;
  }
  return mesh;
}

void ExpectClosed(const Score& s, bool torus)
{
  EXPECT_TRUE(s.Topology.Closed()) << s.Topology.BoundaryEdges << " boundary, " << s.Topology.NonManifoldEdges
                                   << " non-manifold edges";
  EXPECT_EQ(s.Topology.InconsistentEdges, 0);
  EXPECT_EQ(s.Topology.Components, 1);
  EXPECT_EQ(s.Topology.EulerCharacteristic, torus ? 0 : 2);
  EXPECT_EQ(s.NonFinite, 0);
}

struct Case
{
  bool Torus;
  double Sigma;
  bool Normals;
  SurfaceMethod Method;
};

class PointCloudSurface : public ::testing::TestWithParam<Case>
{
};
} // namespace

TEST_P(PointCloudSurface, ClosedAccurateOutward)
{
  const Case k = GetParam();
  const Cloud cloud = Sample(k.Torus, 20000, k.Sigma);
  SurfaceReport report;
  const SurfaceMesh mesh = Reconstruct(cloud, k.Normals, k.Method, &report);
  const Score s = Evaluate(mesh, k.Torus);
  ExpectClosed(s, k.Torus);
  EXPECT_EQ(report.NormalsEstimated, !k.Normals);
  // Outward: the enclosed volume is the shape's.
  const double truth = k.Torus ? 2.0 * M_PI * M_PI * RingRadius * TubeRadius * TubeRadius : 4.0 / 3.0 * M_PI;
  EXPECT_NEAR(EnclosedVolume(mesh.Points, mesh.Triangles), truth, 0.01 * truth);
  if (k.Sigma > 0.0)
  {
    // 100k targets rms 1.3e-3, max 6e-3 (with or without normals), x 1.5 for 20k points.
    EXPECT_LT(s.Rms, 2.0e-3);
    EXPECT_LT(s.Max, 9.0e-3);
    EXPECT_LT(std::fabs(s.Bias), 2.0e-4);
  }
  else if (k.Normals)
  {
    // 100k target rms 2e-5 with exact normals, x 11 for 20k points.
    EXPECT_LT(s.Rms, 2.2e-4);
    EXPECT_LT(s.Max, 2.0e-3);
  }
  else
  {
    EXPECT_LT(s.Rms, 5.0e-4);
    EXPECT_LT(s.Max, 4.0e-3);
  }
  // Vertex normals are the field's outward gradient.
  EXPECT_LT(s.WorstNormal, k.Sigma > 0.0 ? 0.5 : 0.2);
}

INSTANTIATE_TEST_SUITE_P(Shapes, PointCloudSurface,
  ::testing::Values(Case{ false, 0.0, true, SurfaceMethod::MLS }, Case{ true, 0.0, true, SurfaceMethod::MLS },
    Case{ false, 0.005, true, SurfaceMethod::MLS }, Case{ true, 0.005, true, SurfaceMethod::MLS },
    Case{ false, 0.0, false, SurfaceMethod::MLS }, Case{ true, 0.0, false, SurfaceMethod::MLS },
    Case{ false, 0.005, false, SurfaceMethod::MLS }, Case{ true, 0.005, false, SurfaceMethod::MLS },
    Case{ false, 0.0, true, SurfaceMethod::WLS }, Case{ true, 0.0, true, SurfaceMethod::WLS },
    Case{ false, 0.005, false, SurfaceMethod::WLS }, Case{ true, 0.005, false, SurfaceMethod::WLS }),
  [](const ::testing::TestParamInfo<Case>& info) {
    const Case& k = info.param;
    return std::string(SurfaceMethodName(k.Method)) + (k.Torus ? "Torus" : "Sphere") +
      (k.Sigma > 0.0 ? "Noisy" : "Exact") + (k.Normals ? "WithNormals" : "PositionsOnly");
  });

TEST(SurfaceReconstruction, SphereIsReproducedExactly)
{
  // APSS fits spheres exactly: only rounding remains.
  const Cloud cloud = Sample(false, 20000, 0.0);
  const Score s = Evaluate(Reconstruct(cloud, true, SurfaceMethod::MLS), false);
  EXPECT_LT(s.Max, 1e-6);
}

namespace
{
/// A jittered cubic lattice filling the ball of radius `radius` (particles at least half a spacing inside).
std::vector<double> LatticeBall(double radius, double spacing, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.1 * spacing, 0.1 * spacing);
  std::vector<double> p;
  const int m = static_cast<int>(std::ceil(radius / spacing)) + 1;
  for (int i = -m; i <= m; ++i)
  {
    for (int j = -m; j <= m; ++j)
    {
      for (int k = -m; k <= m; ++k)
      {
        const double x[3] = { (i + 0.5) * spacing, (j + 0.5) * spacing, (k + 0.5) * spacing };
        if (std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) <= radius - 0.5 * spacing)
        {
          for (double c : x)
          {
            p.push_back(c + jitter(rng));
          }
        }
      }
    }
  }
  return p;
}
} // namespace

TEST(SurfaceReconstruction, FluidBallEnclosesTheParticlesVolume)
{
  const double spacing = 0.06;
  const std::vector<double> particles = LatticeBall(1.0, spacing, 3);
  const Index n = static_cast<Index>(particles.size() / 3);
  ASSERT_GT(n, 15000);
  const double volume = static_cast<double>(n) * spacing * spacing * spacing;
  const double radius = std::cbrt(volume * 3.0 / (4.0 * M_PI)); // the volume-equivalent ball
  for (bool anisotropic : { false, true })
  {
    SurfaceInput in;
    in.Points = particles.data();
    in.Count = n;
    SurfaceOptions options;
    options.Method = SurfaceMethod::SPH;
    options.Anisotropic = anisotropic;
    SurfaceMesh mesh;
    SurfaceReport report;
    std::string error;
    ASSERT_TRUE(ReconstructSurface(in, options, mesh, report, error)) << error;
    const MeshTopology topo = ComputeMeshTopology(mesh.Triangles, mesh.NumberOfPoints());
    EXPECT_TRUE(topo.Closed()) << "anisotropic " << anisotropic;
    EXPECT_EQ(topo.EulerCharacteristic, 2);
    EXPECT_EQ(topo.Components, 1);
    // The default level encloses the particles' volume (issue: within 5 %).
    const double enclosed = EnclosedVolume(mesh.Points, mesh.Triangles);
    EXPECT_NEAR(enclosed, volume, 0.05 * volume) << "anisotropic " << anisotropic;
    EXPECT_NEAR(report.ParticleVolume, volume, 0.05 * volume);
    // Mean signed distance to the volume-equivalent sphere within +-0.1 H (research §5 target).
    double bias = 0.0;
    for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
    {
      const double* p = &mesh.Points[3 * v];
      bias += std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - radius;
    }
    bias /= static_cast<double>(mesh.NumberOfPoints());
    EXPECT_LT(std::fabs(bias), 0.1 * report.SupportRadius) << "anisotropic " << anisotropic;
  }
}

namespace
{
/// Heights of the mesh vertices on the top face of a block (normal within 25 degrees of +z, away from the
/// edges): their spread measures the "ball pit" bumps of a flat free surface.
double TopFaceSpread(const SurfaceMesh& mesh, double xmin, double xmax, double margin)
{
  double sum = 0.0, sum2 = 0.0;
  Index count = 0;
  for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
  {
    const double* p = &mesh.Points[3 * v];
    const double* n = &mesh.Normals[3 * v];
    if (n[2] > 0.9 && p[0] > xmin + margin && p[0] < xmax - margin && p[1] > xmin + margin && p[1] < xmax - margin)
    {
      sum += p[2];
      sum2 += p[2] * p[2];
      ++count;
    }
  }
  EXPECT_GT(count, 100);
  const double mean = sum / std::max<Index>(count, 1);
  return std::sqrt(std::max(0.0, sum2 / std::max<Index>(count, 1) - mean * mean));
}
/// 40 x 40 x `layers` particles of spacing s from the origin, jittered by 10 % of the spacing.
std::vector<double> JitteredSlab(int layers, double s, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.1 * s, 0.1 * s);
  std::vector<double> particles;
  for (int k = 0; k < layers; ++k)
  {
    for (int j = 0; j < 40; ++j)
    {
      for (int i = 0; i < 40; ++i)
      {
        particles.insert(particles.end(), { (i + 0.5) * s + jitter(rng), (j + 0.5) * s + jitter(rng), (k + 0.5) * s + jitter(rng) });
      }
    }
  }
  return particles;
}
} // namespace

TEST(SurfaceReconstruction, AnisotropicKernelsKeepAFlatSurfaceFlat)
{
  // A resting block: 40 x 40 x 12 particles, jittered by 10 % of the spacing.
  const double s = 0.05;
  const std::vector<double> particles = JitteredSlab(12, s, 5);
  const Index n = static_cast<Index>(particles.size() / 3);
  const double volume = n * s * s * s;
  double spread[2];
  for (int anisotropic = 0; anisotropic < 2; ++anisotropic)
  {
    SurfaceInput in;
    in.Points = particles.data();
    in.Count = n;
    SurfaceOptions options;
    options.Method = SurfaceMethod::SPH;
    options.Anisotropic = anisotropic == 1;
    SurfaceMesh mesh;
    SurfaceReport report;
    std::string error;
    ASSERT_TRUE(ReconstructSurface(in, options, mesh, report, error)) << error;
    const MeshTopology topo = ComputeMeshTopology(mesh.Triangles, mesh.NumberOfPoints());
    EXPECT_TRUE(topo.Closed());
    EXPECT_EQ(topo.EulerCharacteristic, 2);
    // The block's corners are rounded by the kernel; its volume is kept within the 5 %.
    EXPECT_NEAR(EnclosedVolume(mesh.Points, mesh.Triangles), volume, 0.05 * volume) << "anisotropic " << anisotropic;
    spread[anisotropic] = TopFaceSpread(mesh, 0.0, 40 * s, 3 * s);
  }
  // Measured: 0.043 s (isotropic) and 0.040 s (anisotropic) - a half-ball neighbourhood is only mildly flat.
  EXPECT_LT(spread[1], spread[0]);
}

TEST(SurfaceReconstruction, AnisotropicKernelsKeepAThinSheetThin)
{
  // A sheet two particles thick (true thickness 2 s, volume N s^3).
  const double s = 0.05;
  const std::vector<double> particles = JitteredSlab(2, s, 6);
  const Index n = static_cast<Index>(particles.size() / 3);
  double thickness[2], volume[2];
  for (int anisotropic = 0; anisotropic < 2; ++anisotropic)
  {
    SurfaceInput in;
    in.Points = particles.data();
    in.Count = n;
    SurfaceOptions options;
    options.Method = SurfaceMethod::SPH;
    options.Anisotropic = anisotropic == 1;
    SurfaceMesh mesh;
    SurfaceReport report;
    std::string error;
    ASSERT_TRUE(ReconstructSurface(in, options, mesh, report, error)) << error;
    const MeshTopology topo = ComputeMeshTopology(mesh.Triangles, mesh.NumberOfPoints());
    EXPECT_TRUE(topo.Closed());
    EXPECT_EQ(topo.Components, 1);
    EXPECT_EQ(topo.EulerCharacteristic, 2);
    double zmin = 1e9, zmax = -1e9;
    for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
    {
      const double* p = &mesh.Points[3 * v];
      if (p[0] > 5 * s && p[0] < 35 * s && p[1] > 5 * s && p[1] < 35 * s)
      {
        zmin = std::min(zmin, p[2]);
        zmax = std::max(zmax, p[2]);
      }
    }
    thickness[anisotropic] = (zmax - zmin) / s;
    volume[anisotropic] = EnclosedVolume(mesh.Points, mesh.Triangles) / (n * s * s * s);
  }
  // Measured: isotropic 2.45 s thick, 10 % too much volume; anisotropic 2.27 s, 2 %.
  EXPECT_LT(thickness[1], thickness[0]);
  EXPECT_LT(thickness[1], 2.35);
  EXPECT_NEAR(volume[1], 1.0, 0.05);
}

TEST(SurfaceReconstruction, WLSPatchesIgnoreAStrayNormal)
{
  // The plane z = 0 (normals +z) and one point half a support beneath it whose normal lies almost along the
  // plane, alone in its patch cell. Its patch's frame follows the normals of its whole support: the field
  // keeps its sign on each side of the plane. (Measured at 1M points, sigma 0.005, before: the stray frame
  // set a patch across the surface and a spurious closed piece 0.04 inside the sphere.)
  const double h = 0.01, rho = 0.05;
  std::vector<double> points, normals;
  for (int i = -30; i <= 30; ++i)
  {
    for (int j = -30; j <= 30; ++j)
    {
      const double p[3] = { i * h, j * h, 0.0 }, n[3] = { 0.0, 0.0, 1.0 };
      points.insert(points.end(), p, p + 3);
      normals.insert(normals.end(), n, n + 3);
    }
  }
  const double stray[3] = { 0.0012, 0.0013, -0.5 * rho };
  const double tilted[3] = { 0.995, 0.0, 0.0999 };
  points.insert(points.end(), stray, stray + 3);
  normals.insert(normals.end(), tilted, tilted + 3);
  const Index n = static_cast<Index>(points.size() / 3);
  NeighborGrid grid;
  grid.Build(points.data(), n);
  const std::vector<double> radii(static_cast<size_t>(n), rho);
  PatchSurface field;
  field.SetCloud(grid, normals.data(), radii.data());
  FieldScratch scratch;
  int deep = 0;
  for (double z = -0.95 * rho; z <= 0.5 * rho; z += 0.05 * rho)
  {
    for (double dx = -rho; dx <= rho; dx += 0.25 * rho)
    {
      const double x[3] = { stray[0] + dx, stray[1], z };
      double value = 0.0;
      if (!field.Evaluate(x, value, nullptr, scratch))
      {
        continue; // farther than a support from every patch: undefined, as it should be
      }
      deep += z < -0.3 * rho ? 1 : 0;
      // The stray point is data too and pulls its patch's height towards it; the sign must stay the side's.
      if (std::fabs(z) > 0.01 * rho)
      {
        EXPECT_EQ(value < 0.0, z < 0.0) << "f = " << value << " at x " << x[0] << ", z " << z;
      }
    }
  }
  EXPECT_GT(deep, 50); // the region beneath the stray point was evaluated
}
