// SPDX-License-Identifier: BSD-3-Clause
// Normals of surface clouds (Surface/CloudNormals.h): accuracy, a neighbourhood that follows the noise,
// consistent outward orientation, curvature, MLS projection, and the orientation modes.
#include "Surface/CloudNormals.h"
#include "SurfaceSamples.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace meshfree;
namespace samples = meshfree::testing;

namespace
{
struct NormalScore
{
  double MeanAngle = 0.0; // degrees, unoriented (the normal line)
  double Outward = 0.0;   // share pointing outward
  Index Invalid = 0;
};

NormalScore Score(const samples::SurfaceCloud& cloud, const std::vector<double>& points, const std::vector<double>& normals)
{
  NormalScore s;
  Index outward = 0, counted = 0;
  for (Index i = 0; i < cloud.Count(); ++i)
  {
    const double* n = &normals[3 * i];
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(std::fabs(len - 1.0) < 1e-9))
    {
      ++s.Invalid;
      continue;
    }
    double t[3];
    samples::SurfaceNormal(&points[3 * i], cloud.Torus, t);
    const double c = n[0] * t[0] + n[1] * t[1] + n[2] * t[2];
    s.MeanAngle += std::acos(std::min(1.0, std::fabs(c))) * 180.0 / M_PI;
    outward += c > 0.0 ? 1 : 0;
    ++counted;
  }
  s.MeanAngle /= std::max<Index>(counted, 1);
  s.Outward = static_cast<double>(outward) / std::max<Index>(counted, 1);
  return s;
}

double Rms(const samples::SurfaceCloud& cloud, const std::vector<double>& points)
{
  double sum = 0.0;
  for (Index i = 0; i < cloud.Count(); ++i)
  {
    const double d = samples::SurfaceDistance(&points[3 * i], cloud.Torus);
    sum += d * d;
  }
  return std::sqrt(sum / cloud.Count());
}
} // namespace

TEST(SurfaceNormals, ExactCloudsAreOrientedOutwardEverywhere)
{
  for (bool torus : { false, true })
  {
    const samples::SurfaceCloud cloud = samples::SampleSurface(torus, 20000, 0.0);
    CloudNormalsResult r;
    ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, CloudNormalsOptions(), r));
    const NormalScore s = Score(cloud, cloud.Points, r.Normals);
    EXPECT_EQ(s.Invalid, 0);
    EXPECT_EQ(s.Outward, 1.0) << (torus ? "torus" : "sphere");
    // PCA's curvature bias: 0.16 (sphere) and 0.45 degrees (torus) at k = 20 (research §3).
    EXPECT_LT(s.MeanAngle, torus ? 1.0 : 0.5);
    EXPECT_EQ(r.Orientation.Components, 1);
    EXPECT_EQ(r.Orientation.Ambiguous, 0);
    // No noise: the density alone decides the neighbourhood.
    EXPECT_EQ(r.Scale.Radius, 0.0);
  }
}

TEST(SurfaceNormals, NeighbourhoodFollowsTheNoise)
{
  // At 200k points the spacing (0.0079) is below sigma = 0.01: a fixed k = 20 neighbourhood would tilt the
  // normals by tens of degrees (research §0.2); the noise-adapted radius keeps them within a few.
  const samples::SurfaceCloud cloud = samples::SampleSurface(true, 200000, 0.01);
  CloudNormalsResult adapted;
  ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, CloudNormalsOptions(), adapted));
  CloudNormalsOptions fixedK;
  fixedK.Neighborhood.AdaptToNoise = false;
  CloudNormalsResult fixed;
  ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, fixedK, fixed));
  const NormalScore a = Score(cloud, cloud.Points, adapted.Normals);
  const NormalScore f = Score(cloud, cloud.Points, fixed.Normals);
  EXPECT_NEAR(adapted.Scale.Noise, 0.01, 0.002); // the spread about the surface is sigma
  EXPECT_GT(adapted.Scale.Radius, 0.0);
  EXPECT_LT(a.MeanAngle, 7.0); // the 1M-point target
  EXPECT_GT(f.MeanAngle, 2.0 * a.MeanAngle);
  EXPECT_EQ(a.Outward, 1.0);
}

TEST(SurfaceNormals, CurvatureIsTheMeanCurvature)
{
  // Sphere of radius 2: mean curvature 0.5 everywhere.
  samples::SurfaceCloud cloud = samples::SampleSurface(false, 20000, 0.0);
  for (double& x : cloud.Points)
  {
    x *= 2.0;
  }
  CloudNormalsResult r;
  ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, CloudNormalsOptions(), r));
  // The spheres are fitted to jet normals, which are exact to third order in the support: 1e-4.
  for (Index i = 0; i < cloud.Count(); ++i)
  {
    ASSERT_NEAR(r.Curvature[i], 0.5, 1e-4);
  }
  // Torus: at the outer equator (v = 0) the principal curvatures are 1/r and 1/(R + r).
  const samples::SurfaceCloud torus = samples::SampleSurface(true, 20000, 0.0);
  ASSERT_TRUE(ComputeCloudNormals(torus.Points.data(), torus.Count(), nullptr, CloudNormalsOptions(), r));
  const double outer = 0.5 * (1.0 / samples::TubeRadius + 1.0 / (samples::RingRadius + samples::TubeRadius));
  // A sphere fitted to an anisotropic patch gives its mean curvature when the support is sampled
  // symmetrically; random sampling scatters it (measured: up to 18 % at 20k points): the median is the check.
  std::vector<double> equator;
  for (Index i = 0; i < torus.Count(); ++i)
  {
    const double* p = &torus.Points[3 * i];
    if (std::hypot(p[0], p[1]) > 1.34 && std::fabs(p[2]) < 0.02)
    {
      equator.push_back(r.Curvature[i]);
      EXPECT_NEAR(r.Curvature[i], outer, 0.25 * outer);
    }
  }
  ASSERT_GT(equator.size(), 10u);
  std::nth_element(equator.begin(), equator.begin() + equator.size() / 2, equator.end());
  EXPECT_NEAR(equator[equator.size() / 2], outer, 0.03 * outer);
}

TEST(SurfaceNormals, ProjectionDenoises)
{
  const samples::SurfaceCloud cloud = samples::SampleSurface(false, 100000, 0.005);
  CloudNormalsOptions options;
  options.ProjectPoints = true;
  CloudNormalsResult r;
  ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, options, r));
  EXPECT_NEAR(Rms(cloud, cloud.Points), 0.005 * std::sqrt(3.0) / std::sqrt(3.0), 0.0005); // radial part of the noise
  // The 100k smoothing target: rms <= 1.7e-3 (PCL MLS 1.9-2.0e-3, CGAL jet 1.7e-3).
  EXPECT_LT(Rms(cloud, r.Points), 1.7e-3);
  EXPECT_GT(r.Projected, cloud.Count() * 99 / 100);
  EXPECT_EQ(Score(cloud, r.Points, r.Normals).Outward, 1.0);
}

TEST(SurfaceNormals, ViewpointAndReferenceModes)
{
  const samples::SurfaceCloud cloud = samples::SampleSurface(false, 20000, 0.0);
  // Viewpoint inside the sphere: every normal points to it (inward).
  CloudNormalsOptions inside;
  inside.Orientation = OrientationMode::Viewpoint;
  CloudNormalsResult r;
  ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, inside, r));
  EXPECT_EQ(Score(cloud, cloud.Points, r.Normals).Outward, 0.0);
  // Reference normals: inward ones are followed point by point, with their agreement as confidence.
  std::vector<double> inward(cloud.Normals);
  for (double& v : inward)
  {
    v = -3.0 * v; // length does not matter
  }
  CloudNormalsOptions reference;
  reference.Orientation = OrientationMode::Reference;
  ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), inward.data(), reference, r));
  EXPECT_EQ(Score(cloud, cloud.Points, r.Normals).Outward, 0.0);
  EXPECT_GT(*std::min_element(r.Confidence.begin(), r.Confidence.end()), 0.99);
}

TEST(SurfaceNormals, DegenerateNeighbourhoodsAreInvalidNotNaN)
{
  // Collinear points with a NaN point; then 30 copies of one point (one distinct point: no plane).
  std::vector<double> line;
  for (int i = 0; i < 50; ++i)
  {
    line.insert(line.end(), { 0.1 * i, 0.0, 0.0 });
  }
  line.insert(line.end(), { std::nan(""), 0.0, 0.0 });
  std::vector<double> copies;
  for (int i = 0; i < 30; ++i)
  {
    copies.insert(copies.end(), { 5.0, 5.0, 5.0 });
  }
  CloudNormalsResult r;
  for (const std::vector<double>* p : { &line, &copies })
  {
    const Index n = static_cast<Index>(p->size() / 3);
    ComputeCloudNormals(p->data(), n, nullptr, CloudNormalsOptions(), r);
    EXPECT_EQ(r.Invalid, n);
    for (Index i = 0; i < n; ++i)
    {
      EXPECT_EQ(r.Valid[i], 0);
      for (int a = 0; a < 3; ++a)
      {
        EXPECT_TRUE(std::isfinite(r.Normals[3 * i + a]) && std::isfinite(r.Curvature[i]));
      }
    }
  }
  EXPECT_EQ(r.Duplicates, 29);
  std::vector<double> p;
  // A flat disc has one normal line: consistent, +-z.
  for (int i = 0; i < 4000; ++i)
  {
    const double a = 2.399963 * i, r0 = std::sqrt(i / 4000.0);
    p.insert(p.end(), { r0 * std::cos(a), r0 * std::sin(a), 0.0 });
  }
  ASSERT_TRUE(ComputeCloudNormals(p.data(), 4000, nullptr, CloudNormalsOptions(), r));
  for (Index i = 0; i < 4000; ++i)
  {
    ASSERT_NEAR(std::fabs(r.Normals[3 * i + 2]), 1.0, 1e-9);
    ASSERT_EQ(r.Normals[3 * i + 2], r.Normals[2]);
  }
}
