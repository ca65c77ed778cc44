// SPDX-License-Identifier: BSD-3-Clause
// Normals of surface clouds (Surface/CloudNormals.h): accuracy, a neighbourhood that follows the noise,
// consistent outward orientation, curvature, MLS projection, and the orientation modes; at the accuracy limit
// (issue 23): the torus, the sphere and a cube at PCPNet's noise levels beside PCA over 18, 112 and 450 nearest,
// sharp cube edges, and the noisy torus of the issue.
#include "Common/NeighborGrid.h"
#include "Surface/CloudNormals.h"
#include "Surface/NormalOrientation.h"
#include "Surface/SurfaceNormals.h"
#include "Surface/PointSetSurface.h"
#include "SurfaceSamples.h"
#include "VirtualScan.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
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

using samples::SampleCube;

/// n points uniform by area on a closed triangular prism along y (|y| <= 1): the cross-section an isosceles
/// triangle with its apex at z = 1 and its base at z = -1, apex angle `apex` (radians), so a ridge that sharp along
/// the top; Gaussian noise sigma per axis. Normals: the faces'.
samples::SurfaceCloud SamplePrism(std::int64_t n, double apex, double sigma, unsigned seed)
{
  samples::SurfaceCloud c;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double half = 2.0 * std::tan(0.5 * apex); // half the base
  const double slant = std::sqrt(4.0 + half * half);
  const double side = 2.0 * slant, base = 4.0 * half, end = 2.0 * half; // areas: a slanted face, the base, an end
  const double total = 2.0 * side + base + 2.0 * end;
  for (std::int64_t i = 0; i < n; ++i)
  {
    const double pick = u(rng) * total;
    double p[3], m[3] = { 0.0, 0.0, 0.0 };
    if (pick < 2.0 * side)
    {
      const double s = pick < side ? 1.0 : -1.0; // the +x or the -x face
      const double t = u(rng);                   // 0 at the apex, 1 at the base
      p[0] = s * half * t;
      p[1] = 2.0 * u(rng) - 1.0;
      p[2] = 1.0 - 2.0 * t;
      m[0] = s * 2.0 / slant;
      m[2] = half / slant;
    }
    else if (pick < 2.0 * side + base)
    {
      p[0] = half * (2.0 * u(rng) - 1.0);
      p[1] = 2.0 * u(rng) - 1.0;
      p[2] = -1.0;
      m[2] = -1.0;
    }
    else
    {
      // An end: uniform in its triangle, corners (0, 1), (-half, -1), (half, -1).
      double a = u(rng), b = u(rng);
      if (a + b > 1.0)
      {
        a = 1.0 - a;
        b = 1.0 - b;
      }
      const double e = pick < 2.0 * side + base + end ? 1.0 : -1.0;
      p[0] = half * (b - a);
      p[1] = e;
      p[2] = 1.0 - 2.0 * (a + b);
      m[1] = e;
    }
    for (int a = 0; a < 3; ++a)
    {
      c.Points.push_back(p[a] + sigma * g(rng));
      c.Normals.push_back(m[a]);
    }
  }
  return c;
}

/// Angles (degrees) between estimated normal lines and the true normals; 90 where a normal is missing.
std::vector<double> Angles(const std::vector<double>& normals, const std::vector<double>& truth)
{
  std::vector<double> out(truth.size() / 3, 90.0);
  for (size_t i = 0; i < out.size(); ++i)
  {
    const double* n = &normals[3 * i];
    const double* t = &truth[3 * i];
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0.0)
    {
      const double c = std::fabs(n[0] * t[0] + n[1] * t[1] + n[2] * t[2]) / len;
      out[i] = std::acos(std::min(1.0, c)) * 180.0 / M_PI;
    }
  }
  return out;
}

double Mean(const std::vector<double>& v)
{
  double sum = 0.0;
  for (double x : v)
  {
    sum += x;
  }
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

double Percentile(std::vector<double> v, double q)
{
  const size_t at = std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + at, v.end());
  return v[at];
}

/// Unoriented PCA normals over the k nearest (the point itself included), as the benchmark's peer computes them,
/// at every stride-th point (0 elsewhere).
std::vector<double> PCANormals(const std::vector<double>& points, int k, Index stride = 1)
{
  const Index n = static_cast<Index>(points.size() / 3);
  NeighborGrid grid;
  grid.Build(points.data(), n);
  std::vector<double> out(points.size(), 0.0);
  std::vector<Index> ids;
  std::vector<double> d2;
  for (Index i = 0; i < n; i += stride)
  {
    const int found = grid.FindKNearest(&points[3 * i], k, ids, d2);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int j = 0; j < found; ++j)
    {
      mean += Eigen::Vector3d(&points[3 * ids[j]]) - Eigen::Vector3d(&points[3 * i]);
    }
    mean /= found;
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (int j = 0; j < found; ++j)
    {
      const Eigen::Vector3d d = Eigen::Vector3d(&points[3 * ids[j]]) - Eigen::Vector3d(&points[3 * i]) - mean;
      C += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(C);
    for (int a = 0; a < 3; ++a)
    {
      out[3 * i + a] = eig.eigenvectors()(a, 0);
    }
  }
  return out;
}

std::vector<double> DefaultNormals(const samples::SurfaceCloud& cloud)
{
  CloudNormalsOptions options;
  options.ComputeCurvature = false;
  CloudNormalsResult r;
  EXPECT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, options, r));
  return r.Normals;
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

TEST(SurfaceNormals, CubesAreOrientedOutwardAcrossTheirSharpEdges)
{
  // Sharp normals meet at 90 degrees across a cube's edges: a block of the propagation that straddled an edge turned
  // one side by the sign of a single near-perpendicular pair, in patches along the edges. Measured here: 0.946 and
  // 0.979 outward before the fix, 0.9986 and 1.0000 with it.
  for (const double level : { 0.0, 0.00125 })
  {
    const samples::SurfaceCloud cloud = SampleCube(150000, level * 2.0 * std::sqrt(3.0), 3);
    CloudNormalsOptions options;
    options.ComputeCurvature = false;
    CloudNormalsResult r;
    ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, options, r));
    const NormalScore s = Score(cloud, cloud.Points, r.Normals);
    std::printf("cube, noise %g: outward %.4f\n", level, s.Outward);
    EXPECT_GT(s.Outward, 0.995) << "noise " << level;
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
  EXPECT_LT(a.MeanAngle, 7.0); // the issue's 1M-point target
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
  // The curvature jets are exact on spheres (measured: 1e-15 relative; the sphere fits before: 1e-5).
  for (Index i = 0; i < cloud.Count(); ++i)
  {
    ASSERT_NEAR(r.Curvature[i], 0.5, 1e-4);
  }
  // Torus: at the outer equator (v = 0) the principal curvatures are 1/r and 1/(R + r).
  const samples::SurfaceCloud torus = samples::SampleSurface(true, 20000, 0.0);
  ASSERT_TRUE(ComputeCloudNormals(torus.Points.data(), torus.Count(), nullptr, CloudNormalsOptions(), r));
  const double outer = 0.5 * (1.0 / samples::TubeRadius + 1.0 / (samples::RingRadius + samples::TubeRadius));
  // Random sampling scatters the estimate (the sphere fits before: up to 18 % at 20k points; the jets, averaged
  // over the graph, far less): the median is the check.
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

/// The exact mean curvature of the sample surface at the surface point nearest p (outward normals: positive on the
/// sphere; on the torus (R + 2 r cos v) / (2 r (R + r cos v)), v the angle around the tube).
static double ExactMeanCurvature(const double* p, bool torus)
{
  if (!torus)
  {
    return 1.0;
  }
  const double ring = std::hypot(p[0], p[1]) - samples::RingRadius;
  const double c = ring / std::hypot(ring, p[2]);
  const double R = samples::RingRadius, r = samples::TubeRadius;
  return (R + 2.0 * r * c) / (2.0 * r * (R + r * c));
}

/// Mean and 99th percentile of |k - exact| / |exact| over the cloud (an invalid point counts as error 1).
static std::pair<double, double> CurvatureError(
  const samples::SurfaceCloud& cloud, const std::vector<unsigned char>& valid, const std::vector<double>& k)
{
  std::vector<double> e;
  for (Index i = 0; i < cloud.Count(); ++i)
  {
    const double exact = ExactMeanCurvature(&cloud.Points[3 * i], cloud.Torus);
    e.push_back(valid[i] && std::isfinite(k[i]) ? std::fabs(k[i] - exact) / exact : 1.0);
  }
  double mean = 0.0;
  for (double x : e)
  {
    mean += x;
  }
  std::sort(e.begin(), e.end());
  return { mean / static_cast<double>(e.size()), e[e.size() * 99 / 100] };
}

/// Curvature as CloudNormals computed it before the jets gave it (issue 23): the mean curvature of the algebraic
/// sphere fitted at each point over the oriented normals r.Normals, with the default fit supports.
static std::vector<double> SphereFitCurvature(const samples::SurfaceCloud& cloud, const CloudNormalsResult& r)
{
  NeighborGrid grid;
  grid.Build(cloud.Points.data(), cloud.Count());
  NormalField field; // the same normals, unoriented; only their radii and outlier flags are used
  EstimateNormals(grid, NormalOptions(), field);
  const CloudNormalsOptions defaults;
  double median = 0.0;
  const std::vector<double> support = FitSupports(field, defaults.SupportScale, defaults.NoiseScale, false, median);
  PointSetSurface surface;
  surface.SetCloud(grid, r.Normals.data(), support.data());
  std::vector<double> k(static_cast<size_t>(cloud.Count()), 0.0);
  FieldScratch scratch;
  for (Index i = 0; i < cloud.Count(); ++i)
  {
    SphereFit fit;
    if (r.Valid[i] && surface.Fit(&cloud.Points[3 * i], fit, scratch))
    {
      k[i] = fit.Curvature;
    }
  }
  return k;
}

TEST(SurfaceNormals, NoisyCurvatureAndItsSign)
{
  // Noise of 0.1 % of the diagonal per axis (the benchmark's level): the jets' curvature, averaged over the graph.
  for (const bool torus : { false, true })
  {
    const samples::SurfaceCloud cloud = samples::SampleSurface(torus, 50000, torus ? 0.0039 : 0.0035);
    CloudNormalsResult r;
    ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, CloudNormalsOptions(), r));
    const std::pair<double, double> error = CurvatureError(cloud, r.Valid, r.Curvature);
    const std::pair<double, double> spheres = CurvatureError(cloud, r.Valid, SphereFitCurvature(cloud, r));
    std::printf("%s, noise 0.1 %% of the diagonal: Curvature's relative error mean %.4f, p99 %.4f; the sphere "
                "fits' %.4f, %.4f\n",
      torus ? "torus" : "sphere", error.first, error.second, spheres.first, spheres.second);
    // Not worse than the sphere fits it replaced, on average nor in the tail.
    EXPECT_LE(error.first, spheres.first);
    EXPECT_LE(error.second, spheres.second);
    // Normals turned inward (a viewpoint at the centre of the sphere; the torus's ring axis is no such point, so
    // the sphere only): the same curvature, negated, bit for bit.
    if (!torus)
    {
      CloudNormalsOptions inward;
      inward.Orientation = OrientationMode::Viewpoint;
      CloudNormalsResult in;
      ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, inward, in));
      for (Index i = 0; i < cloud.Count(); ++i)
      {
        ASSERT_EQ(in.Curvature[i], -r.Curvature[i]) << "point " << i;
      }
    }
  }
  // ProjectPoints: the curvature of the spheres fitted at the projected points (mean curvature 1 on the sphere).
  const samples::SurfaceCloud sphere = samples::SampleSurface(false, 20000, 0.0);
  CloudNormalsOptions projecting;
  projecting.ProjectPoints = true;
  CloudNormalsResult p;
  ASSERT_TRUE(ComputeCloudNormals(sphere.Points.data(), sphere.Count(), nullptr, projecting, p));
  for (Index i = 0; i < sphere.Count(); ++i)
  {
    ASSERT_NEAR(p.Curvature[i], 1.0, 2e-4); // as CurvatureIsTheMeanCurvature's 1e-4 at curvature 0.5
  }
  // ComputeCurvature off: no curvature at all.
  CloudNormalsOptions off;
  off.ComputeCurvature = false;
  CloudNormalsResult o;
  ASSERT_TRUE(ComputeCloudNormals(sphere.Points.data(), sphere.Count(), nullptr, off, o));
  EXPECT_EQ(*std::max_element(o.Curvature.begin(), o.Curvature.end()), 0.0);
  EXPECT_EQ(*std::min_element(o.Curvature.begin(), o.Curvature.end()), 0.0);
}

TEST(SurfaceNormals, ProjectionDenoises)
{
  const samples::SurfaceCloud cloud = samples::SampleSurface(false, 100000, 0.005);
  CloudNormalsOptions options;
  options.ProjectPoints = true;
  CloudNormalsResult r;
  ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, options, r));
  EXPECT_NEAR(Rms(cloud, cloud.Points), 0.005 * std::sqrt(3.0) / std::sqrt(3.0), 0.0005); // radial part of the noise
  // The issue's 100k smoothing target: rms <= 1.7e-3 (PCL MLS 1.9-2.0e-3, CGAL jet 1.7e-3).
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

TEST(SurfaceNormals, NoFixedKPCABeatsTheDefaultAtAnyNoise)
{
  // Issue 23's targets at a test's size: the torus (R = 1, r = 0.35), the unit sphere and the cube [-1, 1]^3 at
  // noise 0, 0.125 %, 0.6 % and 1.2 % of the bounding box's diagonal (PCPNet's levels); PCA over the 18, 112
  // and 450 nearest is never better than the default by more than 10 % in mean angle. The cube at 1.2 % (noise
  // 0.042 above the spacing 0.035): 10.0 degrees against PCA k 112's 9.7; 12.0 before single jets were flagged
  // from 3.5 standard errors of their misfit (SharpFeatures).
  const std::int64_t n = 20000;
  for (int shape = 0; shape < 3; ++shape)
  {
    const double diagonal = shape == 0 ? std::sqrt(2.0 * 2.7 * 2.7 + 0.7 * 0.7) : 2.0 * std::sqrt(3.0);
    for (double level : { 0.0, 0.00125, 0.006, 0.012 })
    {
      const double sigma = level * diagonal;
      const samples::SurfaceCloud cloud =
        shape == 2 ? SampleCube(n, sigma, 7) : samples::SampleSurface(shape == 0, n, sigma, 7);
      const std::string what = std::string(shape == 0 ? "torus" : shape == 1 ? "sphere" : "cube") + ", noise " +
        std::to_string(100.0 * level) + " %";
      // Scored at every 8th point (PCA over 450 nearest at every point would take most of the test's time).
      const Index stride = 8;
      auto every = [&](const std::vector<double>& angles) {
        std::vector<double> kept;
        for (size_t i = 0; i < angles.size(); i += stride)
        {
          kept.push_back(angles[i]);
        }
        return Mean(kept);
      };
      const double ours = every(Angles(DefaultNormals(cloud), cloud.Normals));
      for (int k : { 18, 112, 450 })
      {
        const double pca = every(Angles(PCANormals(cloud.Points, k, stride), cloud.Normals));
        EXPECT_LE(ours, 1.1 * pca) << what << ": PCA k = " << k << " " << pca << " degrees, ours " << ours;
      }
    }
  }
}

TEST(SurfaceNormals, RangeScanNoiseIsNotTakenForCreases)
{
  // A range scan's noise grows with the square of the range and its part along the normal with the incidence, so
  // over one view it spans several times its median. The crease rules compared every jet's misfit with that
  // median: the noisier half of the view counted as creases, the radius shrank to the 20 nearest and the flagged
  // points took a neighbour's normal (the virtual scans of results/scans_normals.md: CGAL's jet over 112
  // neighbours 2-5 times better). Both now also ask a jet to misfit beyond its own local noise (the misfit over
  // half its radius, where a crease hardly shows): this view 0.55 degrees, 2.38 before (PCA k 18 2.01, k 112 1.69).
  const samples::ScanCloud scan =
    samples::Scan(true, { samples::Viewpoint(20.0, 40.0, 3.0) }, 180, 0.004, 11, true);
  ASSERT_GT(scan.Count(), 10000);
  samples::SurfaceCloud cloud;
  cloud.Points = scan.Points;
  cloud.Normals = scan.Normals;
  const double ours = Mean(Angles(DefaultNormals(cloud), cloud.Normals));
  for (int k : { 18, 112 })
  {
    const double pca = Mean(Angles(PCANormals(cloud.Points, k), cloud.Normals));
    EXPECT_LE(ours, 1.1 * pca) << "PCA k = " << k << " " << pca << " degrees, ours " << ours;
  }
}

TEST(SurfaceNormals, ALargePartIsNotTurnedByAStripOfBadNormals)
{
  // Issue 23 (the dragon scan): one side of a limb hung on the rest by a chain of small nodes, and one wrong vote
  // there turned all of it inward. Here two caps of the unit sphere (|z| > 0.1, 30,000 points each) are tied only by
  // a narrow strip along a meridian whose normals are garbage (random directions, as at a scanner's grazing
  // border): each cap is an anchor turned outward by its own flux, whatever the strip votes. Measured here: with the
  // rule every cap of every seed outward; before it (c3581f2's parent: every link joined, strongest first) a whole
  // cap inward for seeds 2 (the lower) and 7 (the upper).
  int wrong = 0;
  for (unsigned seed = 1; seed <= 8; ++seed)
  {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g;
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> points;
    std::vector<unsigned char> strip;
    const double spacing = std::sqrt(4.0 * M_PI * 0.9 / 60000.0);
    while (points.size() < 3 * 60000)
    {
      double p[3] = { g(rng), g(rng), g(rng) };
      const double r = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      for (double& x : p)
      {
        x /= r;
      }
      const bool inStrip = std::fabs(p[2]) <= 0.1 && p[0] > 0.0 && std::fabs(p[1]) < 1.5 * spacing;
      if (std::fabs(p[2]) > 0.1 || inStrip)
      {
        points.insert(points.end(), p, p + 3);
        strip.push_back(inStrip ? 1 : 0);
      }
    }
    const Index n = static_cast<Index>(points.size() / 3);
    NeighborGrid grid;
    grid.Build(points.data(), n);
    NormalField field;
    ASSERT_TRUE(EstimateNormals(grid, NormalOptions(), field));
    for (Index i = 0; i < n; ++i)
    {
      if (strip[i])
      {
        double m[3] = { u(rng), u(rng), u(rng) };
        const double len = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        for (int a = 0; a < 3; ++a)
        {
          field.Normals[3 * i + a] = m[a] / len;
        }
      }
    }
    std::vector<double> confidence;
    OrientNormals(grid, field, OrientationOptions(), confidence);
    Index inward[2] = { 0, 0 }, count[2] = { 0, 0 };
    for (Index i = 0; i < n; ++i)
    {
      if (!strip[i] && field.Valid[i])
      {
        const double* p = &points[3 * i];
        const double* m = &field.Normals[3 * i];
        const int cap = p[2] > 0.0 ? 0 : 1;
        ++count[cap];
        inward[cap] += p[0] * m[0] + p[1] * m[1] + p[2] * m[2] < 0.0 ? 1 : 0;
      }
    }
    std::printf("seed %u: inward %lld of %lld (upper cap), %lld of %lld (lower cap)\n", seed,
      static_cast<long long>(inward[0]), static_cast<long long>(count[0]), static_cast<long long>(inward[1]),
      static_cast<long long>(count[1]));
    for (int cap = 0; cap < 2; ++cap)
    {
      wrong += inward[cap] > count[cap] / 100 ? 1 : 0;
    }
  }
  EXPECT_EQ(wrong, 0);
}

TEST(SurfaceNormals, SharpRidgesAreOrientedOutward)
{
  // Prisms whose edges are sharper than a cube's: apex 40 and 80 degrees, the faces' normals 140 and 100 degrees
  // apart along the ridge, 110 and 130 at the base's edges. The propagation inside a block followed edges within
  // 60 degrees up to sign, and took such a pair for "nearly opposite: turn one face". Measured here: 0.9957 and
  // 0.9678 outward with 60 degrees, 0.9960 and 0.9961 with 45. With noise (0.125 % of the diagonal) the points
  // near a ridge take a neighbour's normal (SharpFeatures), often the other face's, and propagating over those
  // tied the faces wrongly: 0.63 / 0.78 outward; since the jets' own normals are oriented and the donors' follow
  // them, 0.950 / 0.970.
  for (const double level : { 0.0, 0.00125 })
  for (const double apex : { 40.0, 80.0 })
  {
    const samples::SurfaceCloud cloud = SamplePrism(150000, apex * M_PI / 180.0, level * 2.0 * std::sqrt(3.0), 7);
    CloudNormalsOptions options;
    options.ComputeCurvature = false;
    CloudNormalsResult r;
    ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, options, r));
    Index outward = 0;
    for (Index i = 0; i < cloud.Count(); ++i)
    {
      const double* n = &r.Normals[3 * i];
      const double* t = &cloud.Normals[3 * i];
      outward += n[0] * t[0] + n[1] * t[1] + n[2] * t[2] > 0.0 ? 1 : 0;
    }
    const double share = static_cast<double>(outward) / static_cast<double>(cloud.Count());
    std::printf("prism, apex %g degrees, noise %g: outward %.4f\n", apex, level, share);
    EXPECT_GT(share, level > 0.0 ? 0.93 : 0.99) << "apex " << apex << ", noise " << level;
  }
}

TEST(SurfaceNormals, CubeEdgesAreNotSmeared)
{
  // Near an edge (farther than the noise's reach, nearer than 0.1, about the normals' radius) a neighbourhood
  // that reaches across it tilts the normal by tens of degrees; the sharp-feature pass gives such points the
  // normal of the neighbourhood on their own side.
  const double sigma = 0.00125 * 2.0 * std::sqrt(3.0);
  const samples::SurfaceCloud cloud = SampleCube(20000, sigma, 5);
  CloudNormalsOptions options;
  options.ComputeCurvature = false;
  CloudNormalsResult r;
  ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), cloud.Count(), nullptr, options, r));
  const std::vector<double> ours = Angles(r.Normals, cloud.Normals);
  const std::vector<double> pca = Angles(PCANormals(cloud.Points, 112), cloud.Normals);
  std::vector<double> nearOurs, nearPCA;
  for (Index i = 0; i < cloud.Count(); ++i)
  {
    // Distance to the nearest edge of the point's face: 1 - the largest in-face coordinate.
    const double* p = &cloud.Points[3 * i];
    const double* m = &cloud.Normals[3 * i];
    double edge = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      edge = m[a] == 0.0 ? std::max(edge, std::fabs(p[a])) : edge;
    }
    const double distance = 1.0 - edge;
    if (distance > 4.0 * sigma && distance < 0.1)
    {
      nearOurs.push_back(ours[i]);
      nearPCA.push_back(pca[i]);
    }
  }
  ASSERT_GT(nearOurs.size(), 1000u);
  std::printf("cube edges: ours mean %.2f p75 %.2f p95 %.2f, PCA k 112 mean %.2f p75 %.2f\n", Mean(nearOurs),
    Percentile(nearOurs, 0.75), Percentile(nearOurs, 0.95), Mean(nearPCA), Percentile(nearPCA, 0.75));
  // Measured at this size: mean 4.6, p75 3.3 (p95 21: points whose neighbourhood all reaches across), PCA
  // over the 112 nearest 27 and 33.
  EXPECT_LT(Percentile(nearOurs, 0.75), 5.0);
  EXPECT_LT(Mean(nearOurs), 0.25 * Mean(nearPCA));
}

TEST(SurfaceNormals, NoisyTorusOfTheIssue)
{
  // Issue 23: torus R = 1, r = 0.35, 150,000 points, sigma = 0.002: mean <= 1 degree, p99 <= 3 degrees (PCA
  // over the 80 nearest: 0.76 / 1.9).
  const samples::SurfaceCloud cloud = samples::SampleSurface(true, 150000, 0.002, 11);
  const std::vector<double> angles = Angles(DefaultNormals(cloud), cloud.Normals);
  EXPECT_LE(Mean(angles), 1.0);
  EXPECT_LE(Percentile(angles, 0.99), 3.0);
}

TEST(SurfaceNormals, PortableKernelsGiveTheSameBits)
{
  // The fits' sums (jets, frames) and the grid's distance filter have vector variants; the portable code must give
  // the same bits in every output, with the curvature's jets too, on a noisy cloud and on an exact one.
  if (!SetNormalKernelsVectorized(true))
  {
    GTEST_SKIP() << "no vector kernels on this CPU";
  }
  struct Restore
  {
    ~Restore()
    {
      SetNormalKernelsVectorized(true);
      NeighborGrid::SetVectorized(true);
    }
  } restore;
  for (const double sigma : { 0.004, 0.0 })
  {
    const samples::SurfaceCloud cloud = samples::SampleSurface(true, 20000, sigma, 5);
    const Index n = static_cast<Index>(cloud.Points.size() / 3);
    CloudNormalsResult r[2];
    for (int vector = 0; vector < 2; ++vector)
    {
      SetNormalKernelsVectorized(vector == 1);
      NeighborGrid::SetVectorized(vector == 1);
      ASSERT_TRUE(ComputeCloudNormals(cloud.Points.data(), n, nullptr, CloudNormalsOptions(), r[vector]));
    }
    EXPECT_EQ(r[0].Normals, r[1].Normals);
    EXPECT_EQ(r[0].Curvature, r[1].Curvature);
    EXPECT_EQ(r[0].SurfaceVariation, r[1].SurfaceVariation);
    EXPECT_EQ(r[0].Confidence, r[1].Confidence);
    EXPECT_EQ(r[0].Radius, r[1].Radius);
    EXPECT_EQ(r[0].Valid, r[1].Valid);
    EXPECT_EQ(r[0].Outliers, r[1].Outliers);
    EXPECT_GT(r[0].Curvature.size(), 0u);
  }
}
