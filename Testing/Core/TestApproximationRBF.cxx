// SPDX-License-Identifier: BSD-3-Clause
// Method RBF (issue #26): the polyharmonic spline reproduces its polynomial tail and interpolates the data
// (global and RBF-PU), at offsets of 1e6 and scales of 1e-6 and 1e6; RBF-PU converges on a smooth function;
// the thesis' 9-point example is interpolated; smoothing has SciPy's (scale-covariant) meaning and tends to
// the tail's least-squares fit; duplicates, collinear, coplanar and single-position clouds and NaN give a
// defined, finite result; the result does not depend on the points' order; Auto says what it chose.
#include "TestFunctions.h"
#include "Approximation/Approximation.h"
#include "Approximation/ApproximationRBF.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace
{
using meshfree::testing::Franke;
using meshfree::testing::Halton;
using namespace meshfree;

struct Result
{
  std::vector<double> Values, Gradients, Conditions;
  std::vector<unsigned char> Valid;
};

Result EvaluateAll(Approximator& approx, const std::vector<double>& eval, int components = 1)
{
  const Index m = static_cast<Index>(eval.size() / 3);
  Result r;
  r.Values.assign(static_cast<size_t>(m) * components, -7.0);
  r.Gradients.assign(3 * static_cast<size_t>(m) * components, -7.0);
  r.Conditions.assign(static_cast<size_t>(m), -7.0);
  r.Valid.assign(static_cast<size_t>(m), 7);
  ApproximationOutput o;
  o.Values = r.Values.data();
  o.Gradients = r.Gradients.data();
  o.Valid = r.Valid.data();
  o.Conditions = r.Conditions.data();
  approx.Evaluate(eval.data(), m, o);
  return r;
}

void ExpectFinite(const Result& r)
{
  for (double v : r.Values)
    ASSERT_TRUE(std::isfinite(v));
  for (double v : r.Gradients)
    ASSERT_TRUE(std::isfinite(v));
  for (double v : r.Conditions)
    ASSERT_TRUE(std::isfinite(v));
}

ApproximationOptions RBFOptions(Index globalLimit = 2000)
{
  ApproximationOptions opts;
  opts.Method = ApproximationMethod::RBF;
  opts.RBFGlobalLimit = globalLimit;
  opts.Diagnostics = true;
  return opts;
}

/// Halton points of the unit square (dim 2, z = 0) or cube (dim 3), mapped to offset + scale * u.
std::vector<double> Cloud(int n, int dim, double offset = 0.0, double scale = 1.0, int start = 1)
{
  std::vector<double> xyz(3 * static_cast<size_t>(n), offset);
  for (int i = 0; i < n; ++i)
  {
    xyz[3 * i] = offset + scale * Halton(i + start, 2);
    xyz[3 * i + 1] = offset + scale * Halton(i + start, 3);
    xyz[3 * i + 2] = dim == 3 ? offset + scale * Halton(i + start, 5) : 0.0;
  }
  return xyz;
}

// ---------------------------------------------------------------------------------------------- tail, data
struct Reproduction
{
  int Dim;
  int Tail;
  Index GlobalLimit; // 0: RBF-PU
  double Offset;
  double Scale;
  RBFKernelType Kernel = RBFKernelType::Polyharmonic;
};

class RBFReproduction : public ::testing::TestWithParam<Reproduction>
{
};

TEST_P(RBFReproduction, TailAndDataExactly)
{
  const Reproduction c = GetParam();
  const int n = c.GlobalLimit > 0 ? (c.Dim == 2 ? 300 : 400) : (c.Dim == 2 ? 2000 : 3000);
  const std::vector<double> xyz = Cloud(n, c.Dim, c.Offset, c.Scale);
  // Column 0: a polynomial of the tail's degree in the unit coordinates; column 1: Franke's function.
  auto poly = [&](const double* x, double* g) {
    const double u = (x[0] - c.Offset) / c.Scale, v = (x[1] - c.Offset) / c.Scale;
    const double w = c.Dim == 3 ? (x[2] - c.Offset) / c.Scale : 0.0;
    double value = 0.3 - 1.2 * u + 0.7 * v + 0.4 * w;
    double gu[3] = { -1.2, 0.7, c.Dim == 3 ? 0.4 : 0.0 };
    if (c.Tail >= 2)
    {
      value += 0.5 * u * u - 0.8 * u * v + 0.25 * v * v;
      gu[0] += u - 0.8 * v;
      gu[1] += -0.8 * u + 0.5 * v;
    }
    if (g)
      for (int a = 0; a < 3; ++a)
        g[a] = gu[a] / c.Scale;
    return value;
  };
  std::vector<double> values(2 * static_cast<size_t>(n));
  for (int i = 0; i < n; ++i)
  {
    values[2 * i] = poly(&xyz[3 * i], nullptr);
    values[2 * i + 1] = Franke((xyz[3 * i] - c.Offset) / c.Scale, (xyz[3 * i + 1] - c.Offset) / c.Scale);
  }
  ApproximationOptions opts = RBFOptions(c.GlobalLimit);
  opts.TailDegree = c.Tail;
  opts.RBFKernel = c.Kernel;
  Approximator approx;
  ASSERT_TRUE(approx.SetOptions(opts)) << approx.Error();
  ASSERT_TRUE(approx.SetCloud(xyz.data(), n, values.data(), 2));
  EXPECT_EQ(approx.CloudDimension(), c.Dim);
  EXPECT_EQ(approx.Report().MethodUsed, c.GlobalLimit > 0 ? "RBF (global)" : "RBF-PU");

  // Inside the cloud, and at the data points themselves.
  std::vector<double> eval = Cloud(150, c.Dim, c.Offset + 0.05 * c.Scale, 0.9 * c.Scale, 5000);
  eval.insert(eval.end(), xyz.begin(), xyz.begin() + 3 * 200);
  const Result r = EvaluateAll(approx, eval, 2);
  ExpectFinite(r);
  EXPECT_EQ(approx.Report().Masked, 0);
  EXPECT_EQ(approx.Report().Regularized, 0);
  EXPECT_EQ(approx.Report().MergedPoints, 0);
  const int m = static_cast<int>(eval.size() / 3);
  double tailError = 0.0, gradError = 0.0, dataError = 0.0, largest = 0.0, largestGrad = 0.0;
  for (int i = 0; i < m; ++i)
  {
    ASSERT_EQ(r.Valid[i], 1);
    EXPECT_GE(r.Conditions[i], 1.0 - 1e-12);
    double g[3];
    const double exact = poly(&eval[3 * i], g);
    largest = std::max(largest, std::fabs(exact));
    tailError = std::max(tailError, std::fabs(r.Values[2 * i] - exact));
    for (int a = 0; a < 3; ++a)
    {
      largestGrad = std::max(largestGrad, std::fabs(g[a]));
      gradError = std::max(gradError, std::fabs(r.Gradients[3 * (2 * i) + a] - g[a]));
    }
    if (i >= 150)
    {
      dataError = std::max(dataError, std::fabs(r.Values[2 * i + 1] - values[2 * (i - 150) + 1]));
    }
  }
  EXPECT_LE(tailError, 1e-10 * largest);
  EXPECT_LE(gradError, 1e-8 * largestGrad); // derivatives lose a few digits to the scaling
  EXPECT_LE(dataError, 1e-10 * 1.22);       // max |Franke| on the unit square < 1.22
}

INSTANTIATE_TEST_SUITE_P(Clouds, RBFReproduction,
  ::testing::Values(Reproduction{ 2, 1, 2000, 0.0, 1.0 }, Reproduction{ 2, 2, 2000, 0.0, 1.0 },
    Reproduction{ 2, 1, 2000, 1e6, 1.0 }, Reproduction{ 2, 1, 2000, 0.0, 1e-6 }, Reproduction{ 2, 1, 2000, 0.0, 1e6 },
    Reproduction{ 3, 1, 2000, 0.0, 1.0 }, Reproduction{ 3, 1, 2000, 1e6, 1.0 }, Reproduction{ 2, 1, 0, 0.0, 1.0 },
    Reproduction{ 2, 1, 0, 1e6, 1.0 }, Reproduction{ 2, 1, 0, 0.0, 1e-6 }, Reproduction{ 3, 1, 0, 0.0, 1.0 },
    // Wendland's C2 kernel: its linear tail and the data reproduced the same way.
    Reproduction{ 2, 1, 2000, 0.0, 1.0, RBFKernelType::WendlandC2 },
    Reproduction{ 2, 1, 2000, 1e6, 1.0, RBFKernelType::WendlandC2 },
    Reproduction{ 2, 1, 2000, 0.0, 1e-6, RBFKernelType::WendlandC2 },
    Reproduction{ 3, 1, 2000, 0.0, 1.0, RBFKernelType::WendlandC2 },
    Reproduction{ 2, 1, 0, 0.0, 1.0, RBFKernelType::WendlandC2 },
    Reproduction{ 3, 1, 0, 0.0, 1.0, RBFKernelType::WendlandC2 }));

TEST(RBF, WendlandKernelIsCompactlySupportedAndItsSlopeIsItsDerivative)
{
  EXPECT_EQ(PolyharmonicValue(kWendlandBeta, 0.0), 1.0);
  EXPECT_EQ(PolyharmonicValue(kWendlandBeta, 1.0), 0.0);
  EXPECT_EQ(PolyharmonicValue(kWendlandBeta, 4.0), 0.0);
  EXPECT_EQ(PolyharmonicSlope(kWendlandBeta, 1.5), 0.0);
  for (double r : { 0.1, 0.35, 0.6, 0.9 })
  {
    const double e = 1e-6;
    const double derivative =
      (PolyharmonicValue(kWendlandBeta, (r + e) * (r + e)) - PolyharmonicValue(kWendlandBeta, (r - e) * (r - e))) /
      (2 * e);
    EXPECT_NEAR(PolyharmonicSlope(kWendlandBeta, r * r) * r, derivative, 1e-8) << r;
    EXPECT_GT(PolyharmonicValue(kWendlandBeta, r * r), 0.0);
  }
  // A fixed SupportRadius is the kernel's support: a global fit with rho = 0.05 on 300 points (about 2 in each
  // support) and with rho = 0.5 both interpolate, and differ away from the data.
  const int n = 300;
  const std::vector<double> xyz = Cloud(n, 2);
  std::vector<double> values(n);
  for (int i = 0; i < n; ++i)
    values[i] = Franke(xyz[3 * i], xyz[3 * i + 1]);
  const std::vector<double> eval = Cloud(100, 2, 0.1, 0.8, 5000);
  std::vector<double> at[2];
  int k = 0;
  for (double rho : { 0.05, 0.5 })
  {
    ApproximationOptions opts = RBFOptions();
    opts.RBFKernel = RBFKernelType::WendlandC2;
    opts.SupportRadius = rho;
    Approximator approx;
    ASSERT_TRUE(approx.SetOptions(opts));
    ASSERT_TRUE(approx.SetCloud(xyz.data(), n, values.data(), 1));
    std::vector<double> both = eval;
    both.insert(both.end(), xyz.begin(), xyz.end());
    const Result r = EvaluateAll(approx, both);
    ExpectFinite(r);
    for (int i = 0; i < n; ++i)
      EXPECT_NEAR(r.Values[100 + i], values[i], 1e-10);
    at[k++].assign(r.Values.begin(), r.Values.begin() + 100);
  }
  double differ = 0.0;
  for (int i = 0; i < 100; ++i)
    differ = std::max(differ, std::fabs(at[0][i] - at[1][i]));
  EXPECT_GT(differ, 1e-4);
}

// ---------------------------------------------------------------------------------------------- convergence
double RBFPUError(int n)
{
  const std::vector<double> xyz = Cloud(n, 2);
  std::vector<double> values(n);
  for (int i = 0; i < n; ++i)
    values[i] = Franke(xyz[3 * i], xyz[3 * i + 1]);
  Approximator approx;
  approx.SetOptions(RBFOptions(0));
  approx.SetCloud(xyz.data(), n, values.data(), 1);
  EXPECT_EQ(approx.Report().MethodUsed, "RBF-PU");
  // A 41 x 41 grid of [0.1, 0.9]^2 (away from the boundary, where every method loses an order).
  std::vector<double> eval;
  for (int j = 0; j <= 40; ++j)
    for (int i = 0; i <= 40; ++i)
      eval.insert(eval.end(), { 0.1 + 0.02 * i, 0.1 + 0.02 * j, 0.0 });
  const Result r = EvaluateAll(approx, eval);
  double worst = 0.0;
  for (size_t i = 0; i < r.Values.size(); ++i)
  {
    EXPECT_EQ(r.Valid[i], 1);
    worst = std::max(worst, std::fabs(r.Values[i] - Franke(eval[3 * i], eval[3 * i + 1])));
  }
  return worst;
}

TEST(RBF, PartitionOfUnityConverges)
{
  // Quadrupling N halves the spacing h. Thin-plate splines approximate smooth functions like h^2 (Wendland
  // 2005, Thm. 11.17 with the native space's order: h^(beta/2 + 1) = h^2 in 2D), and the partition of unity
  // keeps the local fits' order (Wendland 2002): over the two quadruplings the error must fall at least like
  // h^1.8, and by at least h^1.5 at each.
  const double e1 = RBFPUError(1000), e2 = RBFPUError(4000), e3 = RBFPUError(16000);
  const double order1 = std::log2(e1 / e2), order2 = std::log2(e2 / e3);
  std::printf("RBF-PU max error on Franke: N = 1000 %.3g, 4000 %.3g, 16000 %.3g (orders %.2f, %.2f)\n", e1, e2, e3,
    order1, order2);
  EXPECT_GE(0.5 * (order1 + order2), 1.8);
  EXPECT_GE(order1, 1.5);
  EXPECT_GE(order2, 1.5);
}

// ---------------------------------------------------------------------------------------------- thesis
TEST(RBF, ThesisNinePoints)
{
  // Thesis sec. 3.4 (Data/thesis_9points.xyz: x, y, z = f, f).
  const double points[9][3] = { { 1, 1, 1 }, { 1, -1, -1 }, { -1, 1, 0 }, { -1, -1, 0 }, { 0, 0, 1 }, { 1, 0, 0 },
    { -1, 0, -1 }, { 0, 1, -1 }, { 0, -1, 1 } };
  std::vector<double> xyz, values;
  for (const auto& p : points)
  {
    xyz.insert(xyz.end(), { p[0], p[1], 0.0 });
    values.push_back(p[2]);
  }
  // The data file, when the source tree is where this file was compiled from, holds the same points.
  std::string source = __FILE__;
  std::ifstream file(source.substr(0, source.rfind("Testing")) + "Data/thesis_9points.xyz");
  if (file)
  {
    std::string line;
    int row = 0;
    while (std::getline(file, line))
    {
      std::istringstream in(line);
      double x, y, z, f;
      if (line.empty() || line[0] == '#' || !(in >> x >> y >> z >> f))
        continue;
      ASSERT_LT(row, 9);
      EXPECT_EQ(x, points[row][0]);
      EXPECT_EQ(y, points[row][1]);
      EXPECT_EQ(f, points[row][2]);
      ++row;
    }
    EXPECT_EQ(row, 9);
  }
  Approximator approx;
  ASSERT_TRUE(approx.SetOptions(RBFOptions()));
  ASSERT_TRUE(approx.SetCloud(xyz.data(), 9, values.data(), 1));
  EXPECT_EQ(approx.CloudDimension(), 2);
  std::vector<double> eval = xyz;
  eval.insert(eval.end(), { 0.5, 0.5, 0.0, -0.3, 0.7, 0.0 });
  const Result r = EvaluateAll(approx, eval);
  ExpectFinite(r);
  for (int i = 0; i < 9; ++i)
  {
    EXPECT_EQ(r.Valid[i], 1);
    EXPECT_NEAR(r.Values[i], values[i], 1e-12) << "point " << i;
  }
  // Between the points the spline stays within the data's range widened by its overshoot (not garbage).
  EXPECT_LT(std::fabs(r.Values[9]), 2.0);
  EXPECT_LT(std::fabs(r.Values[10]), 2.0);
}

// ---------------------------------------------------------------------------------------------- smoothing
TEST(RBF, SmoothingIsScaleCovariantAndTendsToTheTail)
{
  const int n = 200;
  std::vector<double> values(n);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.02);
  const std::vector<double> xyz = Cloud(n, 2);
  for (int i = 0; i < n; ++i)
    values[i] = Franke(xyz[3 * i], xyz[3 * i + 1]) + noise(rng);
  const std::vector<double> eval = Cloud(100, 2, 0.05, 0.9, 777);
  auto solve = [&](double scale, double smoothing, ApproximationMethod method = ApproximationMethod::RBF) {
    std::vector<double> x = xyz, e = eval;
    for (double& v : x)
      v *= scale;
    for (double& v : e)
      v *= scale;
    ApproximationOptions opts = RBFOptions();
    opts.Method = method;
    opts.Degree = 1;
    opts.Smoothing = smoothing;
    Approximator approx;
    EXPECT_TRUE(approx.SetOptions(opts));
    approx.SetCloud(x.data(), n, values.data(), 1);
    return EvaluateAll(approx, e).Values;
  };
  // SciPy's meaning: the kernel in data units, so scaling the coordinates by s scales lambda by s^2 (TPS).
  const std::vector<double> a = solve(1.0, 1e-3), b = solve(1000.0, 1e-3 * 1e6);
  double diff = 0.0, misfit = 0.0;
  for (int i = 0; i < 100; ++i)
    diff = std::max(diff, std::fabs(a[i] - b[i]));
  EXPECT_LE(diff, 1e-9);
  // Smoothing makes it an approximation: not through the noisy data any more.
  {
    ApproximationOptions opts = RBFOptions();
    opts.Smoothing = 1e-3;
    Approximator approx;
    approx.SetOptions(opts);
    approx.SetCloud(xyz.data(), n, values.data(), 1);
    const Result r = EvaluateAll(approx, xyz);
    for (int i = 0; i < n; ++i)
      misfit = std::max(misfit, std::fabs(r.Values[i] - values[i]));
  }
  EXPECT_GT(misfit, 1e-3);
  // Infinite smoothing leaves the tail's least-squares fit: LS of degree 1.
  const std::vector<double> c = solve(1.0, 1e12), d = solve(1.0, 0.0, ApproximationMethod::LS);
  double toLS = 0.0;
  for (int i = 0; i < 100; ++i)
    toLS = std::max(toLS, std::fabs(c[i] - d[i]));
  EXPECT_LE(toLS, 1e-6);
  ApproximationOptions bad = RBFOptions();
  bad.Smoothing = -1.0;
  Approximator approx;
  EXPECT_FALSE(approx.SetOptions(bad));
  bad.Smoothing = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(approx.SetOptions(bad));
}

// ---------------------------------------------------------------------------------------------- hostile
TEST(RBF, DuplicatesAreMergedWithTheirMean)
{
  for (Index limit : { Index(2000), Index(0) })
  {
    SCOPED_TRACE(limit);
    const int n = 400;
    std::vector<double> xyz = Cloud(n, 2);
    std::vector<double> values(n);
    for (int i = 0; i < n; ++i)
      values[i] = Franke(xyz[3 * i], xyz[3 * i + 1]);
    // Point 10 twice more (one exactly, one 1e-13 away) with other values.
    xyz.insert(xyz.end(), { xyz[30], xyz[31], 0.0, xyz[30] + 1e-13, xyz[31], 0.0 });
    values.push_back(values[10] + 1.0);
    values.push_back(values[10] - 0.4);
    Approximator approx;
    approx.SetOptions(RBFOptions(limit));
    ASSERT_TRUE(approx.SetCloud(xyz.data(), n + 2, values.data(), 1));
    const std::vector<double> eval(xyz.begin() + 30, xyz.begin() + 33);
    const Result r = EvaluateAll(approx, eval);
    ExpectFinite(r);
    EXPECT_EQ(approx.Report().MergedPoints, 2);
    EXPECT_EQ(r.Valid[0], 1);
    EXPECT_NEAR(r.Values[0], values[10] + 0.2, 1e-10);
  }
}

TEST(RBF, DegenerateCloudsGiveADefinedFiniteResult)
{
  // Collinear in 3D space (intrinsic dimension 1: r^3 with a linear tail).
  {
    std::vector<double> xyz, values;
    for (int i = 0; i < 50; ++i)
    {
      const double t = Halton(i + 1, 2);
      xyz.insert(xyz.end(), { 1 + t, 2 - 2 * t, 3 + 0.5 * t });
      values.push_back(std::sin(6 * t));
    }
    Approximator approx;
    approx.SetOptions(RBFOptions());
    ASSERT_TRUE(approx.SetCloud(xyz.data(), 50, values.data(), 1));
    EXPECT_EQ(approx.CloudDimension(), 1);
    const Result r = EvaluateAll(approx, xyz);
    ExpectFinite(r);
    for (int i = 0; i < 50; ++i)
      EXPECT_NEAR(r.Values[i], values[i], 1e-10);
  }
  // Coplanar in 3D, on a tilted plane (intrinsic dimension 2: thin-plate spline in the plane).
  {
    std::vector<double> xyz, values;
    for (int i = 0; i < 200; ++i)
    {
      const double u = Halton(i + 1, 2), v = Halton(i + 1, 3);
      xyz.insert(xyz.end(), { 0.6 * u + 0.64 * v, 0.6 * v, -0.8 * u + 0.48 * v });
      values.push_back(Franke(u, v));
    }
    for (Index limit : { Index(2000), Index(0) })
    {
      ApproximationOptions opts = RBFOptions(limit);
      opts.PatchPoints = 30;
      Approximator approx;
      approx.SetOptions(opts);
      ASSERT_TRUE(approx.SetCloud(xyz.data(), 200, values.data(), 1));
      EXPECT_EQ(approx.CloudDimension(), 2);
      const Result r = EvaluateAll(approx, xyz);
      ExpectFinite(r);
      for (int i = 0; i < 200; ++i)
        EXPECT_NEAR(r.Values[i], values[i], 1e-9);
    }
  }
  // One position (intrinsic dimension 0): the mean of the values, everywhere.
  {
    const std::vector<double> xyz = { 1, 2, 3, 1, 2, 3, 1, 2, 3 };
    const std::vector<double> values = { 1, 2, 6 };
    Approximator approx;
    approx.SetOptions(RBFOptions());
    ASSERT_TRUE(approx.SetCloud(xyz.data(), 3, values.data(), 1));
    const Result r = EvaluateAll(approx, { 1, 2, 3, 5, 5, 5 });
    ExpectFinite(r);
    EXPECT_EQ(approx.Report().MergedPoints, 2);
    EXPECT_NEAR(r.Values[0], 3.0, 1e-14);
    EXPECT_NEAR(r.Values[1], 3.0, 1e-14);
  }
  // Two points, three points on a line in 2D, and an empty cloud.
  {
    const std::vector<double> xyz = { 0, 0, 0, 1, 0, 0, 2, 0, 0 };
    const std::vector<double> values = { 1, 3, 2 };
    for (int n : { 2, 3 })
    {
      Approximator approx;
      approx.SetOptions(RBFOptions());
      ASSERT_TRUE(approx.SetCloud(xyz.data(), n, values.data(), 1));
      const Result r = EvaluateAll(approx, xyz);
      ExpectFinite(r);
      for (int i = 0; i < n; ++i)
        EXPECT_NEAR(r.Values[i], values[i], 1e-12);
    }
    Approximator approx;
    approx.SetOptions(RBFOptions());
    EXPECT_FALSE(approx.SetCloud(nullptr, 0, nullptr, 1));
    const Result r = EvaluateAll(approx, { 0, 0, 0 });
    ExpectFinite(r);
    EXPECT_EQ(r.Valid[0], 0);
  }
}

TEST(RBF, NaNNeverLeaves)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> xyz = Cloud(300, 2);
  std::vector<double> values(300);
  for (int i = 0; i < 300; ++i)
    values[i] = Franke(xyz[3 * i], xyz[3 * i + 1]);
  xyz[3 * 5] = nan;
  xyz[3 * 6 + 1] = inf;
  values[7] = nan;
  values[8] = -inf;
  for (Index limit : { Index(2000), Index(0) })
  {
    ApproximationOptions opts = RBFOptions(limit);
    opts.NullValue = -5.0;
    Approximator approx;
    approx.SetOptions(opts);
    ASSERT_TRUE(approx.SetCloud(xyz.data(), 300, values.data(), 1));
    EXPECT_EQ(approx.Report().ExcludedPoints, 4);
    std::vector<double> eval = Cloud(50, 2, 0.0, 1.0, 999);
    eval.insert(eval.end(), { nan, 0.5, 0.0, 0.5, inf, 0.0, 1e300, 1e300, 0.0 });
    const Result r = EvaluateAll(approx, eval);
    ExpectFinite(r);
    for (int i = 0; i < 50; ++i)
      EXPECT_EQ(r.Valid[i], 1);
    EXPECT_EQ(r.Valid[50], 0);
    EXPECT_EQ(r.Values[50], -5.0);
    EXPECT_EQ(r.Valid[51], 0);
    // Far away (1e300): extrapolation overflows, the point is masked rather than infinite.
    EXPECT_TRUE(r.Valid[52] == 0 || std::isfinite(r.Values[52]));
  }
}

// ---------------------------------------------------------------------------------------------- order, Auto
TEST(RBF, IndependentOfThePointsOrder)
{
  for (Index limit : { Index(2000), Index(0) })
  {
    const int n = 800;
    const std::vector<double> xyz = Cloud(n, 2);
    std::vector<double> values(n);
    for (int i = 0; i < n; ++i)
      values[i] = Franke(xyz[3 * i], xyz[3 * i + 1]);
    std::vector<int> perm(n);
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), std::mt19937(11));
    std::vector<double> xyz2(3 * n), values2(n);
    for (int i = 0; i < n; ++i)
    {
      std::copy_n(&xyz[3 * perm[i]], 3, &xyz2[3 * i]);
      values2[i] = values[perm[i]];
    }
    const std::vector<double> eval = Cloud(200, 2, 0.0, 1.0, 3000);
    Approximator a, b;
    a.SetOptions(RBFOptions(limit));
    b.SetOptions(RBFOptions(limit));
    a.SetCloud(xyz.data(), n, values.data(), 1);
    b.SetCloud(xyz2.data(), n, values2.data(), 1);
    const Result ra = EvaluateAll(a, eval), rb = EvaluateAll(b, eval);
    for (int i = 0; i < 200; ++i)
      EXPECT_NEAR(ra.Values[i], rb.Values[i], 1e-11);
  }
}

TEST(RBF, AutoSaysWhatItChoseAndWhy)
{
  // 2D: PU-WLS of degree 3 above kAutoRBFPoints2D (150), below it the spline or PU-WLS by their leave-one-out
  // errors (on Franke's function at 100 points: the spline, 0.033 vs 0.044 of the values' spread); 3D (Franke's
  // function of x and y): r^3 by the sampled leave-one-out estimate, global up to RBFGlobalLimit, RBF-PU above.
  const struct
  {
    int N, Dim;
    const char* Expected;
  } cases[] = { { 100, 2, "RBF (global)" }, { 3000, 2, "PU-WLS degree 3" }, { 300, 3, "RBF (global)" },
    { 1500, 3, "RBF-PU" } };
  for (const auto& c : cases)
  {
    const int n = c.N;
    const std::vector<double> xyz = Cloud(n, c.Dim);
    std::vector<double> values(n);
    for (int i = 0; i < n; ++i)
      values[i] = Franke(xyz[3 * i], xyz[3 * i + 1]);
    ApproximationOptions opts;
    opts.Method = ApproximationMethod::Auto;
    Approximator approx;
    ASSERT_TRUE(approx.SetOptions(opts));
    ASSERT_TRUE(approx.SetCloud(xyz.data(), n, values.data(), 1));
    EXPECT_EQ(approx.Report().MethodUsed, c.Expected) << approx.Report().MethodReason;
    EXPECT_NE(approx.Report().MethodReason.find(std::to_string(n)), std::string::npos);
    const Result r = EvaluateAll(approx, Cloud(100, c.Dim, 0.1, 0.8, 4000));
    ExpectFinite(r);
    for (int i = 0; i < 100; ++i)
      EXPECT_EQ(r.Valid[i], 1);
  }
  ApproximationMethod m;
  ASSERT_TRUE(ApproximationMethodFromName("rbf", m));
  EXPECT_EQ(m, ApproximationMethod::RBF);
  ASSERT_TRUE(ApproximationMethodFromName("Auto", m));
  EXPECT_EQ(m, ApproximationMethod::Auto);
}

TEST(RBF, LeaveOneOutResidualsAreThoseOfTheRefits)
{
  // Rippa's formula (SolvePolyharmonic's leaveOneOut) against solving the system again without each centre:
  // f_j - s_(j)(x_j), 2D thin-plate and 3D r^3, two components.
  for (int dim : { 2, 3 })
  {
    const int n = 40, C = 2;
    const std::vector<double> xyz = Cloud(n, dim);
    std::vector<double> f(static_cast<size_t>(n) * C);
    for (int i = 0; i < n; ++i)
    {
      f[C * i] = Franke(xyz[3 * i], xyz[3 * i + 1]) + (dim == 3 ? xyz[3 * i + 2] * xyz[3 * i + 2] : 0.0);
      f[C * i + 1] = std::sin(4.0 * xyz[3 * i]) * std::cos(3.0 * xyz[3 * i + 1]);
    }
    const int beta = dim == 2 ? 2 : 3;
    std::vector<double> w(static_cast<size_t>(n) * C), tail(static_cast<size_t>(kMaxBasisSize) * C),
      loo(static_cast<size_t>(n) * C);
    PolyharmonicFit fit;
    ASSERT_TRUE(SolvePolyharmonic(dim, beta, 1, 0.0, xyz.data(), n, f.data(), C, w.data(), tail.data(), fit, loo.data()));
    double largest = 0.0;
    for (int j = 0; j < n; ++j)
    {
      std::vector<double> x2, f2;
      for (int i = 0; i < n; ++i)
      {
        if (i != j)
        {
          x2.insert(x2.end(), &xyz[3 * i], &xyz[3 * i] + 3);
          f2.insert(f2.end(), &f[C * i], &f[C * i] + C);
        }
      }
      std::vector<double> w2(static_cast<size_t>(n - 1) * C), tail2(tail.size());
      PolyharmonicFit fit2;
      ASSERT_TRUE(SolvePolyharmonic(dim, beta, 1, 0.0, x2.data(), n - 1, f2.data(), C, w2.data(), tail2.data(), fit2));
      fit2.Offset = 0;
      fit2.Count = n - 1;
      double out[2];
      EvaluatePolyharmonic(dim, beta, fit2, x2.data(), w2.data(), tail2.data(), &xyz[3 * j], C, out, nullptr);
      for (int c = 0; c < C; ++c)
      {
        const double refit = f[C * j + c] - out[c];
        EXPECT_NEAR(loo[C * j + c], refit, 1e-8 * (1.0 + std::fabs(refit))) << "dim " << dim << " point " << j;
        largest = std::max(largest, std::fabs(refit));
      }
    }
    EXPECT_GT(largest, 1e-4); // the residuals are not trivially zero
    // With smoothing the formula does not hold: no residuals (NaN), the fit itself still succeeds.
    ASSERT_TRUE(SolvePolyharmonic(dim, beta, 1, 1e-3, xyz.data(), n, f.data(), C, w.data(), tail.data(), fit, loo.data()));
    for (double v : loo)
      EXPECT_TRUE(std::isnan(v));
  }
}

TEST(RBF, AutoLeaveOneOutPicksTheMoreAccurate)
{
  // Small 2D clouds: a cubic polynomial, which PU-WLS of degree 3 reproduces (its leave-one-out error vanishes)
  // and the thin-plate spline does not -> PU-WLS; a thin-plate spline with four of the data points as centres
  // (weights orthogonal to the linear polynomials) plus a plane, which the spline reproduces whenever those
  // points are kept (only their own four residuals are not zero) and PU-WLS does not (the kernel's second
  // derivatives are singular at the centres) -> the spline. Both with the estimate's figures in the reason; a
  // second, constant component changes nothing (it is left out of the estimate).
  const int n = 120;
  const std::vector<double> xyz = Cloud(n, 2);
  const int centres[4] = { 17, 37, 58, 91 };
  double weights[4];
  for (int k = 0; k < 4; ++k)
  {
    // The null vector of [1; x; y] over the four centres: w_k = (-1)^k det(the 3 x 3 minor without column k).
    double m[3][3];
    for (int c = 0, col = 0; c < 4; ++c)
    {
      if (c == k)
        continue;
      m[0][col] = 1.0;
      m[1][col] = xyz[3 * centres[c]];
      m[2][col] = xyz[3 * centres[c] + 1];
      ++col;
    }
    const double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
      m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    weights[k] = (k % 2 == 0 ? 1.0 : -1.0) * det;
  }
  for (int which = 0; which < 2; ++which)
  {
    std::vector<double> values(2 * static_cast<size_t>(n));
    for (int i = 0; i < n; ++i)
    {
      const double x = xyz[3 * i], y = xyz[3 * i + 1];
      double spline = 0.3 * x - 0.2 * y;
      for (int k = 0; k < 4; ++k)
      {
        const double* p = &xyz[3 * centres[k]];
        const double r2 = (x - p[0]) * (x - p[0]) + (y - p[1]) * (y - p[1]);
        spline += weights[k] * (r2 > 0.0 ? 0.5 * r2 * std::log(r2) : 0.0);
      }
      values[2 * i] = which == 0 ? 0.2 + x - 0.5 * y + 0.8 * x * x * y - 0.3 * y * y * y + 0.4 * x * y : spline;
      values[2 * i + 1] = 2.5;
    }
    ApproximationOptions opts;
    opts.Method = ApproximationMethod::Auto;
    Approximator approx;
    ASSERT_TRUE(approx.SetOptions(opts));
    ASSERT_TRUE(approx.SetCloud(xyz.data(), n, values.data(), 2));
    const std::string& reason = approx.Report().MethodReason;
    std::printf("Auto, %s: %s\n", which == 0 ? "cubic" : "thin-plate spline", reason.c_str());
    EXPECT_EQ(approx.Report().MethodUsed, which == 0 ? "PU-WLS degree 3" : "RBF (global)") << reason;
    EXPECT_NE(reason.find("leave-one-out"), std::string::npos) << reason;
    const Result r = EvaluateAll(approx, Cloud(50, 2, 0.1, 0.8, 4000), 2);
    ExpectFinite(r);
    for (int i = 0; i < 50; ++i)
    {
      EXPECT_EQ(r.Valid[i], 1);
      EXPECT_NEAR(r.Values[2 * i + 1], 2.5, 1e-12);
    }
  }
  // Without values there is nothing to estimate: the spline, and the reason says why.
  ApproximationOptions opts;
  opts.Method = ApproximationMethod::Auto;
  Approximator approx;
  ASSERT_TRUE(approx.SetOptions(opts));
  ASSERT_TRUE(approx.SetCloud(xyz.data(), n, nullptr, 0));
  EXPECT_EQ(approx.Report().MethodUsed, "RBF (global)");
  EXPECT_NE(approx.Report().MethodReason.find("no values"), std::string::npos) << approx.Report().MethodReason;
}

TEST(RBF, AutoIn3DPicksTheMoreAccurateBySampledLeaveOneOut)
{
  // 3D clouds: r^3 or PU-WLS of degree 3 over 40 neighbours, by leave-one-out errors at sampled neighbourhoods.
  // Fields of the benchmark (trivariate (F(x, y) + F(y, z) + F(z, x)) / 3 of Renka & Brown's F5, a Gaussian
  // that r^3 fits 3-4x better, and F6, a sphere's cap that PU-WLS fits 2-9x better) and a cubic polynomial,
  // which PU-WLS reproduces; on either side of RBFGlobalLimit. Auto's choice must be the more accurate of the
  // two on points it did not see, and the reason must carry the estimate.
  auto f5 = [](double x, double y) { return std::exp(-81.0 / 4.0 * ((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5))) / 3.0; };
  auto f6 = [](double x, double y) {
    return std::sqrt(std::max(64.0 - 81.0 * ((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5)), 0.0)) / 9.0 - 0.5;
  };
  auto field = [&](int which, const double* p) {
    const double x = p[0], y = p[1], z = p[2];
    if (which == 0)
      return (f5(x, y) + f5(y, z) + f5(z, x)) / 3.0;
    if (which == 1)
      return (f6(x, y) + f6(y, z) + f6(z, x)) / 3.0;
    return 0.3 + x - 0.5 * y + 0.7 * z * x * y - 0.4 * z * z * z + 0.2 * x * x * y;
  };
  const char* names[3] = { "F5 (trivariate)", "F6 (trivariate)", "cubic" };
  const std::vector<double> eval = Cloud(2000, 3, 0.1, 0.8, 5000);
  for (int n : { 600, 2000 })
  {
    const std::vector<double> xyz = Cloud(n, 3);
    for (int which = 0; which < 3; ++which)
    {
      std::vector<double> values(n);
      for (int i = 0; i < n; ++i)
        values[i] = field(which, &xyz[3 * i]);
      ApproximationOptions opts;
      opts.Method = ApproximationMethod::Auto;
      Approximator approx;
      ASSERT_TRUE(approx.SetOptions(opts));
      ASSERT_TRUE(approx.SetCloud(xyz.data(), n, values.data(), 1));
      const std::string used = approx.Report().MethodUsed, reason = approx.Report().MethodReason;
      std::printf("Auto, 3D, %d points, %s: %s (%s)\n", n, names[which], used.c_str(), reason.c_str());
      EXPECT_NE(reason.find("leave-one-out"), std::string::npos) << reason;
      const Result automatic = EvaluateAll(approx, eval);
      ExpectFinite(automatic);
      // The two candidates, forced.
      double rms[3] = { 0, 0, 0 };
      for (int candidate = 0; candidate < 2; ++candidate)
      {
        ApproximationOptions forced;
        forced.Method = candidate == 0 ? ApproximationMethod::RBF : ApproximationMethod::PUWLS;
        forced.Degree = 3;
        forced.NeighborCount = 40;
        Approximator other;
        ASSERT_TRUE(other.SetOptions(forced));
        ASSERT_TRUE(other.SetCloud(xyz.data(), n, values.data(), 1));
        const Result r = EvaluateAll(other, eval);
        for (size_t i = 0; i < r.Values.size(); ++i)
        {
          ASSERT_EQ(r.Valid[i], 1);
          const double e = r.Values[i] - field(which, &eval[3 * i]);
          rms[candidate] += e * e;
        }
      }
      for (size_t i = 0; i < automatic.Values.size(); ++i)
      {
        ASSERT_EQ(automatic.Valid[i], 1);
        const double e = automatic.Values[i] - field(which, &eval[3 * i]);
        rms[2] += e * e;
      }
      std::printf("  rms on unseen points: r^3 %.3g, PU-WLS %.3g, Auto %.3g\n", std::sqrt(rms[0] / eval.size() * 3),
        std::sqrt(rms[1] / eval.size() * 3), std::sqrt(rms[2] / eval.size() * 3));
      const bool puBetter = rms[1] < rms[0];
      EXPECT_EQ(used.rfind("PU-WLS", 0) == 0, puBetter) << reason;
      EXPECT_LE(rms[2], std::min(rms[0], rms[1]) * (1.0 + 1e-9)) << reason;
    }
  }
}

TEST(RBF, AutoIn3DIsIndependentOfThePointsOrder)
{
  // The sampled estimate sorts every neighbourhood by distance and position: a permuted cloud gets the same
  // choice, the same reason (the estimate's figures) and the same values, bit for bit.
  const int n = 1500;
  const std::vector<double> xyz = Cloud(n, 3);
  std::vector<double> values(n);
  for (int i = 0; i < n; ++i)
    values[i] = Franke(xyz[3 * i], xyz[3 * i + 1]) + 0.3 * xyz[3 * i + 2];
  std::vector<int> perm(n);
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(5));
  std::vector<double> xyz2(3 * n), values2(n);
  for (int i = 0; i < n; ++i)
  {
    std::copy_n(&xyz[3 * perm[i]], 3, &xyz2[3 * i]);
    values2[i] = values[perm[i]];
  }
  ApproximationOptions opts;
  opts.Method = ApproximationMethod::Auto;
  Approximator a, b;
  ASSERT_TRUE(a.SetOptions(opts));
  ASSERT_TRUE(b.SetOptions(opts));
  ASSERT_TRUE(a.SetCloud(xyz.data(), n, values.data(), 1));
  ASSERT_TRUE(b.SetCloud(xyz2.data(), n, values2.data(), 1));
  EXPECT_EQ(a.Report().MethodUsed, b.Report().MethodUsed);
  EXPECT_EQ(a.Report().MethodReason, b.Report().MethodReason);
  EXPECT_NE(a.Report().MethodReason.find("leave-one-out"), std::string::npos) << a.Report().MethodReason;
  const std::vector<double> eval = Cloud(300, 3, 0.05, 0.9, 7000);
  const Result ra = EvaluateAll(a, eval), rb = EvaluateAll(b, eval);
  for (int i = 0; i < 300; ++i)
    EXPECT_EQ(ra.Values[i], rb.Values[i]);
}

} // namespace
