// SPDX-License-Identifier: BSD-3-Clause
// Hostile inputs (issue #3): empty cloud, one point, all points identical, duplicates, collinear and
// coplanar clouds in 2D and 3D, NaN coordinates or values, NeighborCount larger than the cloud, tiny
// SupportRadius, probe points far outside, multi-component data. Every method must give a defined output
// with no NaN/Inf, with masks and the report saying what happened.
#include "Approximation/Approximation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace
{
using namespace meshfree;
const double kNaN = std::numeric_limits<double>::quiet_NaN();
const ApproximationMethod kMethods[] = { ApproximationMethod::LS, ApproximationMethod::WLS,
  ApproximationMethod::MLS, ApproximationMethod::PUWLS, ApproximationMethod::SPH };

struct Result
{
  bool Ok;
  std::vector<double> Values;
  std::vector<double> Gradients;
  std::vector<unsigned char> Valid;
  ApproximationReport Report;
};

Result Approximate(ApproximationMethod method, const std::vector<double>& xyz, const std::vector<double>& values, int C,
  const std::vector<double>& eval, ApproximationOptions opts = ApproximationOptions())
{
  opts.Method = method;
  opts.ComputeGradients = true;
  opts.Diagnostics = true;
  opts.NullValue = -99.0;
  Approximator approx;
  EXPECT_TRUE(approx.SetOptions(opts));
  const Index n = static_cast<Index>(xyz.size() / 3);
  approx.SetCloud(xyz.data(), n, values.data(), C);
  const Index m = static_cast<Index>(eval.size() / 3);
  Result r;
  r.Values.assign(m * C, 12345.0);
  r.Gradients.assign(3 * m * C, 12345.0);
  r.Valid.assign(m, 7);
  std::vector<double> counts(m), conditions(m);
  ApproximationOutput o;
  o.Values = r.Values.data();
  o.Gradients = r.Gradients.data();
  o.Valid = r.Valid.data();
  o.NeighborCounts = counts.data();
  o.Conditions = conditions.data();
  r.Ok = approx.Evaluate(eval.data(), m, o);
  r.Report = approx.Report();
  for (Index i = 0; i < m; ++i)
  {
    EXPECT_TRUE(r.Valid[i] == 0 || r.Valid[i] == 1);
    for (int c = 0; c < C; ++c)
    {
      EXPECT_TRUE(std::isfinite(r.Values[i * C + c])) << ApproximationMethodName(method);
      if (!r.Valid[i])
      {
        EXPECT_EQ(r.Values[i * C + c], -99.0);
      }
    }
    for (int c = 0; c < 3 * C; ++c)
    {
      EXPECT_TRUE(std::isfinite(r.Gradients[3 * i * C + c])) << ApproximationMethodName(method);
    }
    EXPECT_TRUE(std::isfinite(counts[i]) && std::isfinite(conditions[i]));
  }
  return r;
}

std::vector<double> Grid2D(int n, double lo, double hi)
{
  std::vector<double> eval;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      eval.insert(eval.end(), { lo + (hi - lo) * i / (n - 1), lo + (hi - lo) * j / (n - 1), 0.0 });
  return eval;
}

std::vector<double> Random(int n, int dims, unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> xyz(3 * n, 0.0);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < dims; ++a)
      xyz[3 * i + a] = u(rng);
  return xyz;
}

TEST(ApproximationHostile, EmptyCloudMasksEverything)
{
  for (ApproximationMethod method : kMethods)
  {
    const Result r = Approximate(method, {}, {}, 1, Grid2D(5, 0, 1));
    EXPECT_FALSE(r.Ok);
    EXPECT_EQ(r.Report.Masked, 25);
  }
}

TEST(ApproximationHostile, OnePointAndIdenticalPointsGiveTheirValue)
{
  for (ApproximationMethod method : kMethods)
  {
    const Result one = Approximate(method, { 0.3, 0.4, 0.5 }, { 2.5 }, 1, { 0.3, 0.4, 0.5, 0.31, 0.4, 0.5 });
    EXPECT_TRUE(one.Ok) << ApproximationMethodName(method);
    EXPECT_EQ(one.Report.CloudDimension, 0);
    EXPECT_EQ(one.Valid[0], 1) << ApproximationMethodName(method);
    EXPECT_NEAR(one.Values[0], 2.5, 1e-12) << ApproximationMethodName(method);
    std::vector<double> xyz, values;
    for (int i = 0; i < 50; ++i)
    {
      xyz.insert(xyz.end(), { 1.0, 2.0, 3.0 });
      values.push_back(i % 2 ? 1.0 : 3.0);
    }
    const Result same = Approximate(method, xyz, values, 1, { 1.0, 2.0, 3.0 });
    EXPECT_EQ(same.Valid[0], 1) << ApproximationMethodName(method);
    EXPECT_NEAR(same.Values[0], 2.0, 1e-12) << ApproximationMethodName(method);
  }
}

TEST(ApproximationHostile, DuplicatesCollinearAndCoplanar)
{
  // Duplicated points: a 2D cloud whose every point appears three times.
  std::vector<double> base = Random(200, 2, 3), xyz, values;
  for (int i = 0; i < 200; ++i)
    for (int copy = 0; copy < 3; ++copy)
    {
      xyz.insert(xyz.end(), { base[3 * i], base[3 * i + 1], 0.0 });
      values.push_back(1.0 + 2.0 * base[3 * i] - base[3 * i + 1]);
    }
  for (ApproximationMethod method : kMethods)
  {
    const Result r = Approximate(method, xyz, values, 1, Grid2D(7, 0.2, 0.8));
    EXPECT_EQ(r.Report.Masked, 0) << ApproximationMethodName(method);
    if (method != ApproximationMethod::SPH)
    {
      for (size_t i = 0; i < r.Values.size(); ++i)
      {
        const double x = 0.2 + 0.6 * (i % 7) / 6.0, y = 0.2 + 0.6 * (i / 7) / 6.0;
        EXPECT_NEAR(r.Values[i], 1.0 + 2.0 * x - y, 1e-9) << ApproximationMethodName(method);
      }
    }
  }
  // Collinear in 3D (a tilted line) and in 2D (the x axis): 1D basis, linear data reproduced on the line.
  for (int tilted = 0; tilted < 2; ++tilted)
  {
    std::vector<double> line, f, eval;
    for (int i = 0; i < 100; ++i)
    {
      const double t = i / 99.0;
      line.insert(line.end(), { t, tilted ? 2 * t : 0.0, tilted ? -t : 0.0 });
      f.push_back(3.0 * t * t - t);
    }
    eval = { 0.5, tilted ? 1.0 : 0.0, tilted ? -0.5 : 0.0 };
    for (ApproximationMethod method : kMethods)
    {
      const Result r = Approximate(method, line, f, 1, eval);
      EXPECT_EQ(r.Report.CloudDimension, 1);
      EXPECT_EQ(r.Valid[0], 1) << ApproximationMethodName(method);
      if (method != ApproximationMethod::SPH)
      {
        EXPECT_NEAR(r.Values[0], 0.25, 1e-9) << ApproximationMethodName(method);
      }
    }
  }
  // Points on a plane, probed off the plane: defined values, 2D basis.
  std::vector<double> plane = Random(300, 2, 9), f;
  for (int i = 0; i < 300; ++i)
  {
    plane[3 * i + 2] = 0.5 * plane[3 * i] + 0.25 * plane[3 * i + 1];
    f.push_back(plane[3 * i]);
  }
  for (ApproximationMethod method : kMethods)
  {
    const Result r = Approximate(method, plane, f, 1, { 0.5, 0.5, 2.0 });
    EXPECT_EQ(r.Report.CloudDimension, 2);
  }
}

TEST(ApproximationHostile, NaNCoordinatesAndValuesAreExcluded)
{
  std::vector<double> xyz = Random(400, 2, 4), values(2 * 400);
  for (int i = 0; i < 400; ++i)
  {
    values[2 * i] = xyz[3 * i];
    values[2 * i + 1] = -xyz[3 * i + 1];
  }
  for (int i = 0; i < 400; i += 37)
    xyz[3 * i + 1] = kNaN;
  for (int i = 5; i < 400; i += 41)
    values[2 * i + 1] = std::numeric_limits<double>::infinity();
  for (ApproximationMethod method : kMethods)
  {
    std::vector<double> eval = Grid2D(6, 0.2, 0.8);
    eval[4] = kNaN; // one evaluation point with a NaN coordinate
    const Result r = Approximate(method, xyz, values, 2, eval);
    // 11 NaN coordinates, 10 infinite values, point 333 has both.
    EXPECT_EQ(r.Report.ExcludedPoints, 11 + 10 - 1);
    EXPECT_EQ(r.Valid[1], 0);
    EXPECT_EQ(r.Report.Masked, 1) << ApproximationMethodName(method);
  }
}

TEST(ApproximationHostile, NeighborCountLargerThanCloudAndTinyRadius)
{
  std::vector<double> xyz = Random(30, 2, 5), f(30);
  for (int i = 0; i < 30; ++i)
    f[i] = xyz[3 * i] + xyz[3 * i + 1];
  ApproximationOptions many;
  many.NeighborCount = 1000;
  for (ApproximationMethod method : kMethods)
  {
    const Result r = Approximate(method, xyz, f, 1, Grid2D(5, 0.3, 0.7), many);
    EXPECT_EQ(r.Report.Masked, 0) << ApproximationMethodName(method);
  }
  ApproximationOptions tiny;
  tiny.SupportRadius = 1e-9;
  for (ApproximationMethod method : { ApproximationMethod::MLS, ApproximationMethod::SPH })
  {
    const Result r = Approximate(method, xyz, f, 1, Grid2D(5, 0.3, 0.7), tiny);
    EXPECT_EQ(r.Report.Masked, 25) << "no point carries weight";
  }
}

TEST(ApproximationHostile, FarProbesMultiComponentAndLocallyDegenerate)
{
  // Far outside: defined results (MLS falls back as the neighbours cluster in a corner of the support).
  std::vector<double> xyz = Random(500, 2, 6), values(3 * 500);
  for (int i = 0; i < 500; ++i)
    for (int c = 0; c < 3; ++c)
      values[3 * i + c] = (c + 1) * xyz[3 * i] - c * xyz[3 * i + 1];
  for (ApproximationMethod method : kMethods)
  {
    const Result r = Approximate(method, xyz, values, 3, { 1e6, 1e6, 0.0, -1e3, 5.0, 1e3, 0.5, 0.5, 0.0 });
    EXPECT_EQ(r.Valid[2], 1);
    if (method != ApproximationMethod::SPH)
    {
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(r.Values[6 + c], (c + 1) * 0.5 - c * 0.5, 1e-9);
    }
  }
  // A 2D cloud made of two parallel lines 1 apart: between them the neighbours come from both lines and
  // linear data are reproduced by degree 1 (y^2 is constant on two lines, so degree 2 is degenerate at any
  // support); on a line, the neighbours are collinear even with twice as many, so the
  // fallback chain lowers the degree to Shepard (error of order h |grad f| h, small but not exact).
  std::vector<double> lines, f;
  for (int i = 0; i < 200; ++i)
  {
    const double x = i / 199.0;
    lines.insert(lines.end(), { x, 0.0, 0.0, x, 1.0, 0.0 });
    f.push_back(2 * x);
    f.push_back(2 * x + 1);
  }
  ApproximationOptions opts;
  opts.NeighborCount = 8;
  const Result r = Approximate(ApproximationMethod::MLS, lines, f, 1, { 0.5, 0.5, 0.0, 0.25, 0.0, 0.0 }, opts);
  EXPECT_EQ(r.Report.Masked, 0);
  EXPECT_EQ(r.Report.DegreeLowered, 2);
  EXPECT_NEAR(r.Values[0], 1.5, 1e-9);
  EXPECT_NEAR(r.Values[1], 0.5, 1e-3);
}

TEST(ApproximationHostile, AbortMasksTheRest)
{
  std::vector<double> xyz = Random(1000, 2, 8), f(1000, 1.0);
  ApproximationOptions opts;
  Approximator approx;
  ASSERT_TRUE(approx.SetOptions(opts));
  ASSERT_TRUE(approx.SetCloud(xyz.data(), 1000, f.data(), 1));
  std::vector<double> eval = Grid2D(200, 0, 1), out(40000);
  std::vector<unsigned char> valid(40000);
  ApproximationOutput o;
  o.Values = out.data();
  o.Valid = valid.data();
  int calls = 0;
  EXPECT_FALSE(approx.Evaluate(eval.data(), 40000, o, [&](double) { return ++calls < 2; }));
  EXPECT_TRUE(approx.Report().Aborted);
  EXPECT_EQ(valid[0], 1);
  EXPECT_EQ(valid[39999], 0);
}
} // namespace
