// SPDX-License-Identifier: BSD-3-Clause
// Hostile inputs for surface reconstruction and normals: empty, one point, collinear, a flat disc, NaN
// coordinates, clouds offset by 1e6 or scaled by 1e+-6, duplicates, outliers - no crash, no NaN, a defined
// output.
#include "Surface/CloudNormals.h"
#include "Surface/MeshTopology.h"
#include "Surface/SurfaceReconstruction.h"
#include "SurfaceSamples.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace meshfree;
namespace samples = meshfree::testing;

namespace
{
SurfaceMesh Reconstruct(const std::vector<double>& points, SurfaceMethod method, SurfaceReport* report = nullptr,
  const double* normals = nullptr)
{
  SurfaceInput in;
  in.Points = points.data();
  in.Count = static_cast<Index>(points.size() / 3);
  in.Normals = normals;
  SurfaceOptions options;
  options.Method = method;
  SurfaceMesh mesh;
  SurfaceReport r;
  std::string error;
  EXPECT_TRUE(ReconstructSurface(in, options, mesh, r, error)) << error;
  EXPECT_EQ(mesh.Normals.size(), mesh.Points.size());
  for (double v : mesh.Points)
  {
    EXPECT_TRUE(std::isfinite(v));
  }
  for (double v : mesh.Normals)
  {
    EXPECT_TRUE(std::isfinite(v));
  }
  for (Index id : mesh.Triangles)
  {
    EXPECT_TRUE(id >= 0 && id < mesh.NumberOfPoints());
  }
  if (report)
  {
    *report = r;
  }
  return mesh;
}

constexpr SurfaceMethod AllMethods[] = { SurfaceMethod::MLS, SurfaceMethod::WLS, SurfaceMethod::SPH };

/// rms distance of the mesh vertices to a sphere of the given centre and radius, relative to the radius.
double RelativeRms(const SurfaceMesh& mesh, const double centre[3], double radius)
{
  double sum = 0.0;
  for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
  {
    const double* p = &mesh.Points[3 * v];
    const double d = std::sqrt((p[0] - centre[0]) * (p[0] - centre[0]) + (p[1] - centre[1]) * (p[1] - centre[1]) +
                       (p[2] - centre[2]) * (p[2] - centre[2])) - radius;
    sum += d * d;
  }
  return std::sqrt(sum / std::max<Index>(1, mesh.NumberOfPoints())) / radius;
}
} // namespace

TEST(SurfaceHostile, EmptyOneAndCollinear)
{
  for (SurfaceMethod m : AllMethods)
  {
    EXPECT_EQ(Reconstruct({}, m).NumberOfTriangles(), 0);
    const SurfaceMesh one = Reconstruct({ 1.0, 2.0, 3.0 }, m);
    std::vector<double> line;
    for (int i = 0; i < 200; ++i)
    {
      line.insert(line.end(), { 0.01 * i, 0.0, 0.0 });
    }
    const SurfaceMesh tube = Reconstruct(line, m);
    if (m == SurfaceMethod::SPH)
    {
      // Particles always have a volume: one particle is a droplet, a line a thread - closed either way.
      EXPECT_TRUE(ComputeMeshTopology(one.Triangles, one.NumberOfPoints()).Closed());
      EXPECT_TRUE(ComputeMeshTopology(tube.Triangles, tube.NumberOfPoints()).Closed());
    }
    else
    {
      // A surface needs a plane through each neighbourhood: nothing to reconstruct.
      EXPECT_EQ(one.NumberOfTriangles(), 0);
      EXPECT_EQ(tube.NumberOfTriangles(), 0);
    }
  }
}

TEST(SurfaceHostile, NoFinitePoint)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<double> p = { nan, 0.0, 0.0, 1.0, nan, 0.0, 0.0, 0.0, std::numeric_limits<double>::infinity() };
  for (SurfaceMethod m : AllMethods)
  {
    SurfaceReport report;
    EXPECT_EQ(Reconstruct(p, m, &report).NumberOfTriangles(), 0);
    EXPECT_EQ(report.InvalidPoints, 3);
  }
  CloudNormalsResult r;
  ComputeCloudNormals(p.data(), 3, nullptr, CloudNormalsOptions(), r);
  EXPECT_EQ(r.Invalid, 3);
  for (double v : r.Normals)
  {
    EXPECT_EQ(v, 0.0);
  }
}

TEST(SurfaceHostile, FlatDiscIsAnOpenSheetInItsPlane)
{
  std::vector<double> disc;
  for (int i = 0; i < 5000; ++i)
  {
    const double a = 2.399963 * i, r = std::sqrt(i / 5000.0);
    disc.insert(disc.end(), { r * std::cos(a), r * std::sin(a), 0.0 });
  }
  for (SurfaceMethod m : { SurfaceMethod::MLS, SurfaceMethod::WLS })
  {
    const SurfaceMesh mesh = Reconstruct(disc, m);
    ASSERT_GT(mesh.NumberOfTriangles(), 1000);
    const MeshTopology topo = ComputeMeshTopology(mesh.Triangles, mesh.NumberOfPoints());
    EXPECT_GT(topo.BoundaryEdges, 0); // an open sheet, not a closed invented volume
    EXPECT_EQ(topo.NonManifoldEdges, 0);
    for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
    {
      ASSERT_LT(std::fabs(mesh.Points[3 * v + 2]), 1e-9);
    }
  }
}

namespace
{
/// The cloud each method is meant for: points on the unit sphere (MLS, WLS), or particles filling the unit
/// ball on a jittered lattice (SPH).
std::vector<double> UnitSphereInput(SurfaceMethod m)
{
  if (m != SurfaceMethod::SPH)
  {
    return samples::SampleSurface(false, 20000, 0.0).Points;
  }
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> jitter(-0.005, 0.005);
  std::vector<double> p;
  const double s = 0.05;
  for (int i = -20; i < 20; ++i)
  {
    for (int j = -20; j < 20; ++j)
    {
      for (int k = -20; k < 20; ++k)
      {
        const double x[3] = { (i + 0.5) * s, (j + 0.5) * s, (k + 0.5) * s };
        if (x[0] * x[0] + x[1] * x[1] + x[2] * x[2] < (1.0 - 0.5 * s) * (1.0 - 0.5 * s))
        {
          p.insert(p.end(), { x[0] + jitter(rng), x[1] + jitter(rng), x[2] + jitter(rng) });
        }
      }
    }
  }
  return p;
}
} // namespace

TEST(SurfaceHostile, NaNPointsAreIgnored)
{
  for (SurfaceMethod m : AllMethods)
  {
    std::vector<double> points = UnitSphereInput(m);
    for (int i = 0; i < 100; ++i)
    {
      points[3 * (i * 137) + i % 3] = i % 2 ? std::numeric_limits<double>::quiet_NaN()
                                            : std::numeric_limits<double>::infinity();
    }
    SurfaceReport report;
    const SurfaceMesh mesh = Reconstruct(points, m, &report);
    EXPECT_EQ(report.InvalidPoints, 100);
    const MeshTopology topo = ComputeMeshTopology(mesh.Triangles, mesh.NumberOfPoints());
    EXPECT_TRUE(topo.Closed());
    EXPECT_EQ(topo.EulerCharacteristic, 2);
  }
}

TEST(SurfaceHostile, OffsetAndScaledClouds)
{
  for (SurfaceMethod m : AllMethods)
  {
    const std::vector<double> unit = UnitSphereInput(m);
    for (double scale : { 1e-6, 1.0, 1e6 })
    {
      for (double offset : { 0.0, 1e6 })
      {
        std::vector<double> p(unit);
        const double centre[3] = { offset * scale, -offset * scale, 0.5 * offset * scale };
        for (size_t i = 0; i < p.size(); ++i)
        {
          p[i] = p[i] * scale + centre[i % 3];
        }
        const SurfaceMesh mesh = Reconstruct(p, m);
        const MeshTopology topo = ComputeMeshTopology(mesh.Triangles, mesh.NumberOfPoints());
        EXPECT_TRUE(topo.Closed()) << "scale " << scale << " offset " << offset << " " << SurfaceMethodName(m);
        EXPECT_EQ(topo.EulerCharacteristic, 2);
        // Relative accuracy does not depend on the scale; the offset costs the digits it takes (1e6 of a
        // unit radius leaves 1e-10).
        const double bound = m == SurfaceMethod::SPH ? 0.05 : (offset > 0.0 ? 1e-4 : 1e-5);
        EXPECT_LT(RelativeRms(mesh, centre, scale), bound) << "scale " << scale << " offset " << offset << " "
                                                           << SurfaceMethodName(m);
      }
    }
  }
}

TEST(SurfaceHostile, DuplicatesAndOutliers)
{
  const samples::SurfaceCloud cloud = samples::SampleSurface(true, 20000, 0.0);
  // Every point three times.
  std::vector<double> tripled;
  for (int copy = 0; copy < 3; ++copy)
  {
    tripled.insert(tripled.end(), cloud.Points.begin(), cloud.Points.end());
  }
  // 1 % of uniform outliers in the bounding box.
  std::vector<double> noisy(cloud.Points);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> box(-1.5, 1.5);
  for (int i = 0; i < 200; ++i)
  {
    noisy.insert(noisy.end(), { box(rng), box(rng), 0.3 * box(rng) });
  }
  for (SurfaceMethod m : { SurfaceMethod::MLS, SurfaceMethod::WLS })
  {
    const SurfaceMesh dup = Reconstruct(tripled, m);
    const MeshTopology d = ComputeMeshTopology(dup.Triangles, dup.NumberOfPoints());
    EXPECT_TRUE(d.Closed());
    EXPECT_EQ(d.EulerCharacteristic, 0);
    const SurfaceMesh out = Reconstruct(noisy, m);
    const MeshTopology o = ComputeMeshTopology(out.Triangles, out.NumberOfPoints());
    // Isolated outliers have too few neighbours to carry a surface: no spurious blobs, the torus stays closed.
    EXPECT_TRUE(o.Closed()) << SurfaceMethodName(m);
    EXPECT_EQ(o.Components, 1) << SurfaceMethodName(m);
    EXPECT_EQ(o.EulerCharacteristic, 0) << SurfaceMethodName(m);
  }
}

TEST(SurfaceHostile, AbsurdOptionsAreRefused)
{
  const std::vector<double> p = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
  SurfaceInput in;
  in.Points = p.data();
  in.Count = 3;
  SurfaceMesh mesh;
  SurfaceReport report;
  std::string error;
  SurfaceOptions bad;
  bad.NeighborCount = 1;
  EXPECT_FALSE(ReconstructSurface(in, bad, mesh, report, error));
  EXPECT_FALSE(error.empty());
  bad = SurfaceOptions();
  bad.CellSize = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(ReconstructSurface(in, bad, mesh, report, error));
  bad = SurfaceOptions();
  bad.Method = SurfaceMethod::SPH;
  bad.Level = 1.5;
  EXPECT_FALSE(ReconstructSurface(in, bad, mesh, report, error));
  bad = SurfaceOptions();
  bad.SupportRadius = -1.0;
  EXPECT_FALSE(ReconstructSurface(in, bad, mesh, report, error));
  // A cell size so small the lattice would need more than 2^21 cells per axis is enlarged, not refused.
  const samples::SurfaceCloud cloud = samples::SampleSurface(false, 5000, 0.0);
  in.Points = cloud.Points.data();
  in.Count = cloud.Count();
  SurfaceOptions tiny;
  tiny.CellSize = 1e-9;
  tiny.MaximumRounds = 3; // growth on such a fine lattice takes many rounds: stop early, still defined
  EXPECT_TRUE(ReconstructSurface(in, tiny, mesh, report, error)) << error;
  EXPECT_TRUE(report.CellSizeEnlarged);
  EXPECT_TRUE(report.Contour.RoundLimitReached);
}
