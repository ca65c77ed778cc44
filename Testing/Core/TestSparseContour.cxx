// SPDX-License-Identifier: BSD-3-Clause
// Sparse continuation contouring (SparseContour.h) on analytic fields: closed, oriented, accurate, and
// only as much work as the surface needs.
#include "Surface/MeshTopology.h"
#include "Surface/SparseContour.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

using namespace meshfree;

namespace
{
/// Signed distance to a sphere (or, with a tube radius, a torus about z), undefined beyond `reach`.
class AnalyticField : public ImplicitField
{
public:
  double Radius = 1.0;
  double Tube = 0.0; // > 0: torus
  double Reach = 1e300;
  mutable std::int64_t Evaluations = 0;
  bool Evaluate(const double x[3], double& value, double gradient[3], FieldScratch&) const override
  {
#pragma omp atomic
    ++this->Evaluations;
    if (this->Tube > 0.0)
    {
      const double rho = std::hypot(x[0], x[1]);
      const double q = rho - this->Radius;
      value = std::hypot(q, x[2]) - this->Tube;
      if (gradient)
      {
        const double d = std::hypot(q, x[2]);
        gradient[0] = q / d * x[0] / rho;
        gradient[1] = q / d * x[1] / rho;
        gradient[2] = x[2] / d;
      }
    }
    else
    {
      const double r = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
      value = r - this->Radius;
      if (gradient)
      {
        for (int a = 0; a < 3; ++a)
        {
          gradient[a] = x[a] / r;
        }
      }
    }
    return std::fabs(value) < this->Reach;
  }
};

/// Independent random values at lattice corners inside a box, +1 outside: every ambiguous face occurs.
class RandomField : public ImplicitField
{
public:
  double Cell = 1.0;
  int Size = 12;
  bool Evaluate(const double x[3], double& value, double*, FieldScratch&) const override
  {
    long c[3];
    bool inside = true;
    for (int a = 0; a < 3; ++a)
    {
      c[a] = std::lround(x[a] / this->Cell);
      inside = inside && c[a] >= 2 && c[a] <= this->Size;
    }
    if (!inside)
    {
      value = 1.0;
      return true;
    }
    std::uint64_t h = static_cast<std::uint64_t>(c[0] * 73856093L ^ c[1] * 19349663L ^ c[2] * 83492791L);
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdULL;
    h ^= h >> 33;
    value = static_cast<double>(h % 2001) / 1000.0 - 1.0;
    return true;
  }
};

std::vector<std::uint64_t> SeedsOnSphere(int n, double radius, const ContourOptions& options)
{
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g;
  std::vector<std::uint64_t> seeds;
  for (int i = 0; i < n; ++i)
  {
    double p[3] = { g(rng), g(rng), g(rng) };
    const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (double& v : p)
    {
      v *= radius / r;
    }
    Index c[3];
    if (SparseContour::CellOf(p, options, c))
    {
      seeds.push_back(SparseContour::CellKey(c[0], c[1], c[2]));
    }
  }
  return seeds;
}
} // namespace

TEST(SparseContour, SphereIsClosedOrientedAndAccurate)
{
  AnalyticField field;
  ContourOptions options;
  options.CellSize = 0.05;
  options.Origin[0] = options.Origin[1] = options.Origin[2] = -1.5;
  TriangleMesh mesh;
  ContourReport report;
  // A few seeds are enough: continuation finds the rest of the surface.
  ASSERT_TRUE(SparseContour().Run(field, SeedsOnSphere(5, 1.0, options), options, mesh, report));
  const MeshTopology topo = ComputeMeshTopology(mesh.Triangles, mesh.NumberOfPoints());
  EXPECT_TRUE(topo.Closed());
  EXPECT_EQ(topo.InconsistentEdges, 0);
  EXPECT_EQ(topo.Components, 1);
  EXPECT_EQ(topo.EulerCharacteristic, 2);
  EXPECT_EQ(report.UndefinedCorners, 0);
  // Outward triangles enclose the ball's volume (to the linear interpolation's O(h^2)).
  const double volume = EnclosedVolume(mesh.Points, mesh.Triangles);
  EXPECT_NEAR(volume, 4.0 / 3.0 * M_PI, 0.01 * 4.0 / 3.0 * M_PI);
  double worst = 0.0;
  for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
  {
    const double* p = &mesh.Points[3 * v];
    worst = std::max(worst, std::fabs(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1.0));
  }
  EXPECT_LT(worst, 0.05 * 0.05); // linear interpolation of a distance: O(cell^2 / radius)
  // Only a band: the corners evaluated are a small multiple of the surface cells, far fewer than the box's.
  const double boxCorners = std::pow(3.0 / 0.05, 3);
  EXPECT_LT(static_cast<double>(report.EvaluatedCorners), 0.1 * boxCorners);
  EXPECT_LT(static_cast<double>(field.Evaluations), 0.1 * boxCorners);
}

TEST(SparseContour, TorusHasGenusOne)
{
  AnalyticField field;
  field.Tube = 0.35;
  ContourOptions options;
  options.CellSize = 0.04;
  options.Origin[0] = options.Origin[1] = options.Origin[2] = -2.0;
  std::vector<std::uint64_t> seeds;
  Index c[3];
  const double p[3] = { 1.35, 0.0, 0.0 };
  ASSERT_TRUE(SparseContour::CellOf(p, options, c));
  seeds.push_back(SparseContour::CellKey(c[0], c[1], c[2]));
  TriangleMesh mesh;
  ContourReport report;
  ASSERT_TRUE(SparseContour().Run(field, seeds, options, mesh, report));
  const MeshTopology topo = ComputeMeshTopology(mesh.Triangles, mesh.NumberOfPoints());
  EXPECT_TRUE(topo.Closed());
  EXPECT_EQ(topo.InconsistentEdges, 0);
  EXPECT_EQ(topo.EulerCharacteristic, 0);
  const double volume = EnclosedVolume(mesh.Points, mesh.Triangles);
  EXPECT_NEAR(volume, 2.0 * M_PI * M_PI * 1.0 * 0.35 * 0.35, 0.02 * 2.0 * M_PI * M_PI * 0.35 * 0.35);
}

TEST(SparseContour, EveryAmbiguousConfigurationStitches)
{
  RandomField field;
  field.Cell = 0.5;
  ContourOptions options;
  options.CellSize = 0.5;
  std::vector<std::uint64_t> seeds;
  for (Index i = 1; i <= 13; ++i)
  {
    for (Index j = 1; j <= 13; ++j)
    {
      for (Index k = 1; k <= 13; ++k)
      {
        seeds.push_back(SparseContour::CellKey(i, j, k));
      }
    }
  }
  TriangleMesh mesh;
  ContourReport report;
  ASSERT_TRUE(SparseContour().Run(field, seeds, options, mesh, report));
  ASSERT_GT(mesh.NumberOfTriangles(), 1000);
  const MeshTopology topo = ComputeMeshTopology(mesh.Triangles, mesh.NumberOfPoints());
  EXPECT_EQ(topo.BoundaryEdges, 0);
  EXPECT_EQ(topo.NonManifoldEdges, 0);
  EXPECT_EQ(topo.InconsistentEdges, 0);
  // Each closed component encloses the negative values: total volume positive.
  EXPECT_GT(EnclosedVolume(mesh.Points, mesh.Triangles), 0.0);
}

TEST(SparseContour, UndefinedRegionsLeaveAnOpenBoundaryNotAWall)
{
  AnalyticField field;
  field.Reach = 0.03; // defined only in a thin shell: cells beyond it are skipped
  ContourOptions options;
  options.CellSize = 0.05;
  options.Origin[0] = options.Origin[1] = options.Origin[2] = -1.5;
  TriangleMesh mesh;
  ContourReport report;
  ASSERT_TRUE(SparseContour().Run(field, SeedsOnSphere(200, 1.0, options), options, mesh, report));
  EXPECT_GT(report.UndefinedCorners, 0);
  for (Index v = 0; v < mesh.NumberOfPoints(); ++v)
  {
    const double* p = &mesh.Points[3 * v];
    EXPECT_LT(std::fabs(std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1.0), 0.05);
  }
}

TEST(SparseContour, NothingToContour)
{
  AnalyticField field;
  ContourOptions options;
  options.CellSize = 0.1;
  TriangleMesh mesh;
  ContourReport report;
  EXPECT_TRUE(SparseContour().Run(field, {}, options, mesh, report));
  EXPECT_EQ(mesh.NumberOfTriangles(), 0);
  options.CellSize = 0.0;
  EXPECT_FALSE(SparseContour().Run(field, { SparseContour::CellKey(1, 1, 1) }, options, mesh, report));
}
