// SPDX-License-Identifier: BSD-3-Clause
// Accuracy (issue #3): Franke's F1 (the original formula, research/mls.md §3.1 - not Fasshauer's variant)
// on Halton points in [0,1]^2, evaluated on the 101 x 101 grid: MLS degree 2 rms <= 5e-4 at N = 1,000 and
// <= 2e-5 at N = 10,000; observed convergence order ~ m + 1 for degree m = 0..3 over N = 250 ... 16,000;
// Renka-Brown's other test functions converge too; the thesis' 9-point example (§3.4).
#include "TestFunctions.h"
#include "Approximation/Approximation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace
{
using meshfree::testing::Franke;
using meshfree::testing::Halton;
using namespace meshfree;
using Function = std::function<double(double, double)>;

struct Errors
{
  double Rms;
  double Max;
  long Masked;
};

Errors Measure(const Function& f, int n, ApproximationOptions opts, int grid = 101)
{
  std::vector<double> xyz(3 * n), values(n);
  for (int i = 0; i < n; ++i)
  {
    xyz[3 * i] = Halton(i + 1, 2);
    xyz[3 * i + 1] = Halton(i + 1, 3);
    xyz[3 * i + 2] = 0.0;
    values[i] = f(xyz[3 * i], xyz[3 * i + 1]);
  }
  const int m = grid * grid;
  std::vector<double> eval(3 * m), out(m);
  std::vector<unsigned char> valid(m);
  for (int j = 0; j < grid; ++j)
    for (int i = 0; i < grid; ++i)
    {
      double* x = &eval[3 * (j * grid + i)];
      x[0] = i / double(grid - 1);
      x[1] = j / double(grid - 1);
      x[2] = 0.0;
    }
  Approximator approx;
  EXPECT_TRUE(approx.SetOptions(opts));
  EXPECT_TRUE(approx.SetCloud(xyz.data(), n, values.data(), 1));
  ApproximationOutput o;
  o.Values = out.data();
  o.Valid = valid.data();
  EXPECT_TRUE(approx.Evaluate(eval.data(), m, o));
  Errors e{ 0.0, 0.0, 0 };
  for (int i = 0; i < m; ++i)
  {
    const double d = out[i] - f(eval[3 * i], eval[3 * i + 1]);
    e.Rms += d * d;
    e.Max = std::max(e.Max, std::fabs(d));
    e.Masked += valid[i] ? 0 : 1;
  }
  e.Rms = std::sqrt(e.Rms / m);
  return e;
}

ApproximationOptions MLS(int degree, int k = 20)
{
  ApproximationOptions opts;
  opts.Method = ApproximationMethod::MLS;
  opts.Degree = degree;
  opts.NeighborCount = k;
  return opts;
}

TEST(ApproximationAccuracy, FrankeMLSDegree2)
{
  const Errors e1000 = Measure(Franke, 1000, MLS(2));
  const Errors e10000 = Measure(Franke, 10000, MLS(2));
  std::printf("Franke F1, MLS degree 2, 20 neighbours: N=1000 rms %.3g max %.3g; N=10000 rms %.3g max %.3g\n",
    e1000.Rms, e1000.Max, e10000.Rms, e10000.Max);
  EXPECT_EQ(e1000.Masked, 0);
  EXPECT_EQ(e10000.Masked, 0);
  EXPECT_LE(e1000.Rms, 5e-4);
  EXPECT_LE(e10000.Rms, 2e-5);
}

// Least-squares slope of log(rms) against log(h), h ~ N^(-1/2) in 2D.
double ObservedOrder(const Function& f, const ApproximationOptions& opts, const std::vector<int>& sizes)
{
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int n : sizes)
  {
    const double x = std::log(1.0 / std::sqrt(static_cast<double>(n)));
    const double y = std::log(Measure(f, n, opts, 51).Rms);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double k = static_cast<double>(sizes.size());
  return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

TEST(ApproximationAccuracy, FrankeConvergenceOrder)
{
  const std::vector<int> sizes = { 250, 1000, 4000, 16000 };
  const int neighbours[] = { 10, 12, 20, 30 };
  for (int m = 0; m <= 3; ++m)
  {
    const double order = ObservedOrder(Franke, MLS(m, neighbours[m]), sizes);
    std::printf("Franke F1, MLS degree %d (%d neighbours): observed order %.2f\n", m, neighbours[m], order);
    EXPECT_NEAR(order, m + 1.0, 0.6) << "degree " << m;
  }
}

TEST(ApproximationAccuracy, RenkaBrownFunctionsConverge)
{
  // Renka & Brown (ACM TOMS 792) test functions 2-8 and 10 (TSTFN1).
  const std::vector<std::pair<const char*, Function>> functions = {
    { "cliff", [](double x, double y) { return (std::tanh(9 * y - 9 * x) + 1) / 9; } },
    { "saddle",
      [](double x, double y) { return (1.25 + std::cos(5.4 * y)) / (6 + 6 * (3 * x - 1) * (3 * x - 1)); } },
    { "gentle",
      [](double x, double y) {
        return std::exp(-81.0 / 16 * ((x - .5) * (x - .5) + (y - .5) * (y - .5))) / 3;
      } },
    { "steep",
      [](double x, double y) {
        return std::exp(-81.0 / 4 * ((x - .5) * (x - .5) + (y - .5) * (y - .5))) / 3;
      } },
    { "sphere",
      [](double x, double y) {
        return std::sqrt(64 - 81 * ((x - .5) * (x - .5) + (y - .5) * (y - .5))) / 9 - .5;
      } },
    { "trig",
      [](double x, double y) { return 2 * std::cos(10 * x) * std::sin(10 * y) + std::sin(10 * x * y); } },
    { "gaussian",
      [](double x, double y) {
        const double a = std::exp(-(5 - 10 * x) * (5 - 10 * x) / 2);
        const double b = std::exp(-(5 - 10 * y) * (5 - 10 * y) / 2);
        return a + 0.75 * b + 0.75 * a * b;
      } },
    { "cosine peak",
      [](double x, double y) {
        const double r = std::sqrt((80 * x - 40) * (80 * x - 40) + (90 * y - 45) * (90 * y - 45));
        return std::exp(-0.04 * r) * std::cos(0.15 * r);
      } },
  };
  for (const auto& entry : functions)
  {
    const Errors shepard = Measure(entry.second, 4000, MLS(0, 10), 51);
    const Errors coarse = Measure(entry.second, 1000, MLS(2), 51);
    const Errors fine = Measure(entry.second, 4000, MLS(2), 51);
    std::printf("%-12s MLS2 rms N=1000 %.3g, N=4000 %.3g (Shepard N=4000 %.3g)\n", entry.first, coarse.Rms,
      fine.Rms, shepard.Rms);
    // Quadrupling N halves h: a third-order method gains a factor 8 on smooth functions; ask for 3. The
    // cosine peak has a kink at its centre (exp(-0.04 r)), which limits it to about first order: ask for 2.
    const bool kink = std::string(entry.first) == "cosine peak";
    EXPECT_LT(fine.Rms, coarse.Rms / (kink ? 2 : 3)) << entry.first;
    EXPECT_LT(fine.Rms, shepard.Rms) << entry.first;
  }
}

TEST(ApproximationAccuracy, ThesisNinePointExample)
{
  // Thesis §3.4: 9 points, basis [1, x, y, x^2, xy, y^2].
  const double px[9][2] = { { 1, 1 }, { 1, -1 }, { -1, 1 }, { -1, -1 }, { 0, 0 }, { 1, 0 }, { -1, 0 }, { 0, 1 },
    { 0, -1 } };
  const double f[9] = { 1, -1, 0, 0, 1, 0, -1, -1, 1 };
  std::vector<double> xyz;
  for (const auto& p : px)
  {
    xyz.insert(xyz.end(), { p[0], p[1], 0.0 });
  }
  const ApproximationMethod methods[] = { ApproximationMethod::LS, ApproximationMethod::WLS,
    ApproximationMethod::MLS, ApproximationMethod::SPH, ApproximationMethod::PUWLS };
  double residual[5] = { 0, 0, 0, 0, 0 };
  for (int k = 0; k < 5; ++k)
  {
    const ApproximationMethod method = methods[k];
    ApproximationOptions opts;
    opts.Method = method;
    opts.CenterSet = true; // x-bar = origin
    Approximator approx;
    ASSERT_TRUE(approx.SetOptions(opts));
    ASSERT_TRUE(approx.SetCloud(xyz.data(), 9, f, 1));
    // A 21 x 21 grid over [-1, 1]^2 (the thesis uses 101 x 101), then the 9 points themselves.
    std::vector<double> eval;
    for (int j = 0; j <= 20; ++j)
      for (int i = 0; i <= 20; ++i)
        eval.insert(eval.end(), { -1 + i * 0.1, -1 + j * 0.1, 0.0 });
    eval.insert(eval.end(), xyz.begin(), xyz.end());
    const int m = static_cast<int>(eval.size() / 3);
    std::vector<double> out(m);
    std::vector<unsigned char> valid(m);
    ApproximationOutput o;
    o.Values = out.data();
    o.Valid = valid.data();
    ASSERT_TRUE(approx.Evaluate(eval.data(), m, o)) << ApproximationMethodName(method) << approx.Error();
    for (int i = 0; i < m; ++i)
    {
      EXPECT_EQ(valid[i], 1) << ApproximationMethodName(method);
      EXPECT_TRUE(std::isfinite(out[i]));
      if (method == ApproximationMethod::SPH)
      {
        // Shepard-normalised SPH is a convex combination of the data.
        EXPECT_LE(std::fabs(out[i]), 1.0 + 1e-12);
      }
    }
    for (int i = 0; i < 9; ++i)
    {
      const double d = out[m - 9 + i] - f[i];
      residual[k] += d * d / 9;
    }
    std::printf("9-point example, %-6s rms residual at the data %.4f\n", ApproximationMethodName(method),
      std::sqrt(residual[k]));
  }
  // Figures 3.1-3.4: the moving fit follows the data better than the global one.
  EXPECT_LT(residual[2], residual[0]);
  // MLS with inverse-distance weights and a tiny epsilon interpolates the 9 values (thesis 3.12).
  ApproximationOptions opts;
  opts.Weight = KernelType::InverseDistance;
  opts.Epsilon = 1e-8;
  Approximator approx;
  ASSERT_TRUE(approx.SetOptions(opts));
  ASSERT_TRUE(approx.SetCloud(xyz.data(), 9, f, 1));
  std::vector<double> out(9);
  ApproximationOutput o;
  o.Values = out.data();
  ASSERT_TRUE(approx.Evaluate(xyz.data(), 9, o));
  for (int i = 0; i < 9; ++i)
  {
    EXPECT_NEAR(out[i], f[i], 1e-9) << "point " << i;
  }
  // ... and the least-squares fit of degree 2 does not (9 values, 6 coefficients): the test can fail.
  ApproximationOptions ls;
  ls.Method = ApproximationMethod::LS;
  ASSERT_TRUE(approx.SetOptions(ls));
  ASSERT_TRUE(approx.Evaluate(xyz.data(), 9, o));
  double lsResidual = 0.0;
  for (int i = 0; i < 9; ++i)
  {
    lsResidual = std::max(lsResidual, std::fabs(out[i] - f[i]));
  }
  EXPECT_GT(lsResidual, 0.1);
}
} // namespace
