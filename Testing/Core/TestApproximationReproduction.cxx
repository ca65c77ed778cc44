// SPDX-License-Identifier: BSD-3-Clause
// Polynomial reproduction (issue #3): degree-m LS, WLS (near the centre), MLS and PU-WLS fits reproduce
// polynomials of degree <= m to 1e-9 relative, for clouds at the origin, offset by 1e6, and scaled by 1e-6
// and 1e6, in 2D (flat in z), in 3D and on a tilted plane; gradients of the fits reproduce the
// polynomials' gradients.
#include "TestFunctions.h"
#include "Approximation/Approximation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace
{
using meshfree::testing::Halton;
using namespace meshfree;

// A random polynomial of total degree m in the unit coordinates u = (x - offset) / scale (3 variables).
struct Polynomial
{
  int Degree;
  std::vector<double> Coefficients; // over all (a, b, c) with a + b + c <= Degree
  double Value(const double u[3]) const
  {
    double v = 0.0;
    int n = 0;
    for (int a = 0; a <= Degree; ++a)
      for (int b = 0; a + b <= Degree; ++b)
        for (int c = 0; a + b + c <= Degree; ++c)
          v += Coefficients[n++] * std::pow(u[0], a) * std::pow(u[1], b) * std::pow(u[2], c);
    return v;
  }
  void Gradient(const double u[3], double g[3]) const
  {
    g[0] = g[1] = g[2] = 0.0;
    int n = 0;
    for (int a = 0; a <= Degree; ++a)
      for (int b = 0; a + b <= Degree; ++b)
        for (int c = 0; a + b + c <= Degree; ++c)
        {
          const double k = Coefficients[n++];
          if (a > 0)
            g[0] += k * a * std::pow(u[0], a - 1) * std::pow(u[1], b) * std::pow(u[2], c);
          if (b > 0)
            g[1] += k * b * std::pow(u[0], a) * std::pow(u[1], b - 1) * std::pow(u[2], c);
          if (c > 0)
            g[2] += k * c * std::pow(u[0], a) * std::pow(u[1], b) * std::pow(u[2], c - 1);
        }
  }
};

Polynomial RandomPolynomial(int degree, unsigned seed)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Polynomial p{ degree, {} };
  for (int a = 0; a <= degree; ++a)
    for (int b = 0; a + b <= degree; ++b)
      for (int c = 0; a + b + c <= degree; ++c)
        p.Coefficients.push_back(u(rng));
  return p;
}

enum class Shape
{
  Flat,   // unit square, z = 0
  Volume, // unit cube
  Tilted  // unit square rotated out of every coordinate plane
};

void UnitToWorld(Shape shape, const double u[3], double offset, double scale, double x[3])
{
  double v[3] = { u[0], u[1], shape == Shape::Volume ? u[2] : 0.0 };
  if (shape == Shape::Tilted)
  {
    // Orthonormal rows: a rotation taking the x-y plane to a tilted plane.
    const double r[3][3] = { { 0.6, 0.0, -0.8 }, { 0.64, 0.6, 0.48 }, { 0.48, -0.8, 0.36 } };
    const double w[3] = { v[0], v[1], v[2] };
    for (int i = 0; i < 3; ++i)
      v[i] = r[0][i] * w[0] + r[1][i] * w[1] + r[2][i] * w[2];
  }
  for (int i = 0; i < 3; ++i)
    x[i] = offset + scale * v[i];
}

struct Case
{
  ApproximationMethod Method;
  int Degree;
  Shape Geometry;
  double Offset;
  double Scale;
};

std::string Name(const Case& c)
{
  return std::string(ApproximationMethodName(c.Method)) + " degree " + std::to_string(c.Degree) + " shape " +
    std::to_string(static_cast<int>(c.Geometry)) + " offset " + std::to_string(c.Offset) + " scale " +
    std::to_string(c.Scale);
}

void CheckReproduction(const Case& c)
{
  SCOPED_TRACE(Name(c));
  const int n = c.Geometry == Shape::Volume ? 1500 : 400;
  const Polynomial poly = RandomPolynomial(c.Degree, 17 + c.Degree);
  std::vector<double> xyz(3 * n), values(n);
  std::vector<double> units(3 * n);
  for (int i = 0; i < n; ++i)
  {
    const double u[3] = { Halton(i + 1, 2), Halton(i + 1, 3), Halton(i + 1, 5) };
    UnitToWorld(c.Geometry, u, c.Offset, c.Scale, &xyz[3 * i]);
  }
  // The data are the polynomial at the stored coordinates, in the unit coordinates of the cloud
  // (recovered exactly: x - offset is exact for |x - offset| << offset by Sterbenz' lemma... up to scale).
  auto unitOf = [&](const double x[3], double u[3]) {
    double v[3];
    for (int i = 0; i < 3; ++i)
      v[i] = (x[i] - c.Offset) / c.Scale;
    if (c.Geometry == Shape::Tilted)
    {
      const double r[3][3] = { { 0.6, 0.0, -0.8 }, { 0.64, 0.6, 0.48 }, { 0.48, -0.8, 0.36 } };
      for (int i = 0; i < 3; ++i)
        u[i] = r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2];
    }
    else
    {
      std::copy(v, v + 3, u);
    }
  };
  double largest = 0.0;
  for (int i = 0; i < n; ++i)
  {
    double u[3];
    unitOf(&xyz[3 * i], u);
    values[i] = poly.Value(u);
    largest = std::max(largest, std::fabs(values[i]));
  }
  ApproximationOptions opts;
  opts.Method = c.Method;
  opts.Degree = c.Degree;
  opts.NeighborCount = c.Geometry == Shape::Volume ? 40 : 20;
  opts.ComputeGradients = true;
  opts.Diagnostics = true;
  const double centerUnit[3] = { 0.5, 0.5, 0.5 };
  UnitToWorld(c.Geometry, centerUnit, c.Offset, c.Scale, opts.Center);
  opts.CenterSet = true;
  Approximator approx;
  ASSERT_TRUE(approx.SetOptions(opts)) << approx.Error();
  ASSERT_TRUE(approx.SetCloud(xyz.data(), n, values.data(), 1));
  EXPECT_EQ(approx.CloudDimension(), c.Geometry == Shape::Volume ? 3 : 2);

  // Evaluation points inside the cloud (WLS: near its centre, within 0.1 of the unit size).
  const int m = 200;
  std::vector<double> eval(3 * m);
  std::mt19937 rng(5);
  const bool nearCenter = c.Method == ApproximationMethod::WLS;
  std::uniform_real_distribution<double> ud(nearCenter ? 0.45 : 0.05, nearCenter ? 0.55 : 0.95);
  for (int i = 0; i < m; ++i)
  {
    const double u[3] = { ud(rng), ud(rng), ud(rng) };
    UnitToWorld(c.Geometry, u, c.Offset, c.Scale, &eval[3 * i]);
  }
  std::vector<double> out(m, -1.0), grad(3 * m), counts(m), conditions(m);
  std::vector<unsigned char> valid(m, 7);
  ApproximationOutput o;
  o.Values = out.data();
  o.Gradients = grad.data();
  o.Valid = valid.data();
  o.NeighborCounts = counts.data();
  o.Conditions = conditions.data();
  ASSERT_TRUE(approx.Evaluate(eval.data(), m, o)) << approx.Error();
  EXPECT_EQ(approx.Report().Masked, 0);
  double worst = 0.0, worstGrad = 0.0, largestGrad = 1e-300;
  for (int i = 0; i < m; ++i)
  {
    ASSERT_EQ(valid[i], 1);
    double u[3];
    unitOf(&eval[3 * i], u);
    worst = std::max(worst, std::fabs(out[i] - poly.Value(u)));
    EXPECT_GE(counts[i], 1.0);
    if (c.Method == ApproximationMethod::MLS && approx.Report().Widened == 0)
    {
      // h = 1.1 x the distance to the k-th nearest point: exactly k points carry weight.
      EXPECT_EQ(counts[i], opts.NeighborCount);
    }
    EXPECT_GE(conditions[i], 1.0 - 1e-12);
    // Gradient in world units: d f / d x = (d f / d u) (d u / d x), d u / d x = R / scale.
    double gu[3];
    poly.Gradient(u, gu);
    if (c.Geometry != Shape::Volume)
      gu[2] = 0.0; // the data only know the plane
    double gx[3];
    if (c.Geometry == Shape::Tilted)
    {
      const double r[3][3] = { { 0.6, 0.0, -0.8 }, { 0.64, 0.6, 0.48 }, { 0.48, -0.8, 0.36 } };
      for (int k = 0; k < 3; ++k)
        gx[k] = (r[0][k] * gu[0] + r[1][k] * gu[1] + r[2][k] * gu[2]) / c.Scale;
    }
    else
    {
      for (int k = 0; k < 3; ++k)
        gx[k] = gu[k] / c.Scale;
    }
    for (int k = 0; k < 3; ++k)
    {
      worstGrad = std::max(worstGrad, std::fabs(grad[3 * i + k] - gx[k]));
      largestGrad = std::max(largestGrad, std::fabs(gx[k]));
    }
  }
  EXPECT_LE(worst, 1e-9 * largest) << "max |error| " << worst << " max |f| " << largest;
  if (c.Degree > 0 || c.Method == ApproximationMethod::LS || c.Method == ApproximationMethod::WLS)
  {
    // Degree 0 MLS/PU differentiates Shepard's formula, which is exact for constants (gradient 0).
    EXPECT_LE(worstGrad, 1e-7 * largestGrad) << "max |gradient error| " << worstGrad;
  }
}

class ApproximationReproduction : public ::testing::TestWithParam<ApproximationMethod>
{
};

TEST_P(ApproximationReproduction, EveryDegreeShapeOffsetAndScale)
{
  const Shape shapes[] = { Shape::Flat, Shape::Volume, Shape::Tilted };
  const double placements[][2] = { { 0.0, 1.0 }, { 1e6, 1.0 }, { 0.0, 1e-6 }, { 0.0, 1e6 } };
  for (int degree = 0; degree <= 3; ++degree)
    for (Shape shape : shapes)
      for (const auto& p : placements)
        CheckReproduction(Case{ GetParam(), degree, shape, p[0], p[1] });
}

INSTANTIATE_TEST_SUITE_P(Methods, ApproximationReproduction,
  ::testing::Values(ApproximationMethod::LS, ApproximationMethod::WLS, ApproximationMethod::MLS,
    ApproximationMethod::PUWLS),
  [](const ::testing::TestParamInfo<ApproximationMethod>& info) {
    std::string name = ApproximationMethodName(info.param);
    return name == "PU-WLS" ? std::string("PUWLS") : name;
  });

TEST(ApproximationReproduction, SPHShepardReproducesConstants)
{
  const int n = 500;
  std::vector<double> xyz(3 * n), values(2 * n);
  for (int i = 0; i < n; ++i)
  {
    xyz[3 * i] = 1e6 + Halton(i + 1, 2);
    xyz[3 * i + 1] = Halton(i + 1, 3);
    xyz[3 * i + 2] = 0.0;
    values[2 * i] = 3.25;
    values[2 * i + 1] = -7.0;
  }
  ApproximationOptions opts;
  opts.Method = ApproximationMethod::SPH;
  Approximator approx;
  ASSERT_TRUE(approx.SetOptions(opts));
  ASSERT_TRUE(approx.SetCloud(xyz.data(), n, values.data(), 2));
  std::vector<double> eval = { 1e6 + 0.5, 0.5, 0.0, 1e6 + 0.1, 0.9, 0.0 };
  std::vector<double> out(4);
  ApproximationOutput o;
  o.Values = out.data();
  ASSERT_TRUE(approx.Evaluate(eval.data(), 2, o));
  for (int i = 0; i < 2; ++i)
  {
    EXPECT_NEAR(out[2 * i], 3.25, 1e-12);
    EXPECT_NEAR(out[2 * i + 1], -7.0, 1e-12);
  }
}
} // namespace
