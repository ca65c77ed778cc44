// SPDX-License-Identifier: BSD-3-Clause
// LocalFit.h: MLS shape functions reproduce the basis (sum to 1, first moments 0 at the centre), the fast
// path's pivot ratio is a lower bound of the exact condition number, degenerate neighbourhoods (collinear
// points for a 2D linear basis, too few points) are refused instead of solved, and fits with many
// right-hand sides (LS/WLS/PU-WLS) recover polynomial coefficients.
#include "Common/LocalFit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace
{
using namespace meshfree;

struct Neighbourhood
{
  std::vector<double> Xi, W, Rows, Phi, DPhi;
  int N;
};

Neighbourhood Random2D(int n, unsigned seed, bool collinear = false)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.9, 0.9);
  Neighbourhood h;
  h.N = n;
  for (int j = 0; j < n; ++j)
  {
    const double x = u(rng), y = collinear ? 0.5 * x : u(rng);
    h.Xi.insert(h.Xi.end(), { x, y, 0.0 });
    const double q = std::min(0.999, std::sqrt(x * x + y * y));
    h.W.push_back(std::pow(1 - q, 4) * (4 * q + 1));
  }
  h.Rows.resize(kMaxBasisSize * n);
  h.Phi.resize(n);
  h.DPhi.resize(3 * n);
  return h;
}

TEST(LocalFit, ShapeFunctionsReproduceTheBasis)
{
  Neighbourhood h = Random2D(20, 1);
  for (int degree = 0; degree <= 3; ++degree)
  {
    double fast = 0.0, exact = 0.0;
    ASSERT_TRUE(ComputeMLSShapeFunctions(2, degree, h.Xi.data(), h.W.data(), nullptr, h.N, degree > 0, false,
      h.Rows.data(), h.Phi.data(), h.DPhi.data(), fast));
    // Every monomial of degree <= m is reproduced at xi = 0: sum phi_j b(xi_j) = b(0) = e_1.
    RuntimeBasis basis(2, degree);
    std::vector<double> p(basis.Size()), sum(basis.Size(), 0.0), dsum(2 * basis.Size(), 0.0);
    for (int j = 0; j < h.N; ++j)
    {
      basis.Evaluate(&h.Xi[3 * j], p.data());
      for (int a = 0; a < basis.Size(); ++a)
      {
        sum[a] += h.Phi[j] * p[a];
        if (degree > 0)
        {
          dsum[a] += h.DPhi[j] * p[a];
          dsum[basis.Size() + a] += h.DPhi[h.N + j] * p[a];
        }
      }
    }
    for (int a = 0; a < basis.Size(); ++a)
    {
      EXPECT_NEAR(sum[a], a == 0 ? 1.0 : 0.0, 1e-12) << "degree " << degree << " monomial " << a;
      if (degree > 0)
      {
        // Diffuse derivatives: d/dxi of b at 0 is e_2 (x) and e_3 (y).
        EXPECT_NEAR(dsum[a], a == 1 ? 1.0 : 0.0, 1e-11);
        EXPECT_NEAR(dsum[basis.Size() + a], a == 2 ? 1.0 : 0.0, 1e-11);
      }
    }
    std::vector<double> phi2(h.N);
    ASSERT_TRUE(ComputeMLSShapeFunctions(2, degree, h.Xi.data(), h.W.data(), nullptr, h.N, false, true,
      h.Rows.data(), phi2.data(), h.DPhi.data(), exact));
    EXPECT_LE(fast, exact * (1 + 1e-9)) << "the pivot ratio is a lower bound";
    EXPECT_GE(exact, 1.0);
    for (int j = 0; j < h.N; ++j)
    {
      EXPECT_NEAR(phi2[j], h.Phi[j], 1e-12);
    }
  }
}

TEST(LocalFit, DegenerateFitsAreRefused)
{
  Neighbourhood line = Random2D(30, 2, true);
  double condition = 0.0;
  EXPECT_FALSE(ComputeMLSShapeFunctions(2, 1, line.Xi.data(), line.W.data(), nullptr, line.N, false, false,
    line.Rows.data(), line.Phi.data(), line.DPhi.data(), condition));
  EXPECT_TRUE(condition > kMaxCondition || std::isinf(condition));
  // The same points fit fine in 1D (their own dimension) or at degree 0.
  EXPECT_TRUE(ComputeMLSShapeFunctions(2, 0, line.Xi.data(), line.W.data(), nullptr, line.N, false, false,
    line.Rows.data(), line.Phi.data(), line.DPhi.data(), condition));
  // Fewer points than basis functions.
  Neighbourhood few = Random2D(5, 3);
  EXPECT_FALSE(ComputeMLSShapeFunctions(2, 2, few.Xi.data(), few.W.data(), nullptr, few.N, false, false,
    few.Rows.data(), few.Phi.data(), few.DPhi.data(), condition));
}

TEST(LocalFit, CoefficientsOfAWeightedFit)
{
  Neighbourhood h = Random2D(40, 4);
  // Two components: f = 1 + 2x - y + 0.5 xy and g = -3 + y^2.
  std::vector<double> values;
  for (int j = 0; j < h.N; ++j)
  {
    const double x = h.Xi[3 * j], y = h.Xi[3 * j + 1];
    values.push_back(1 + 2 * x - y + 0.5 * x * y);
    values.push_back(-3 + y * y);
  }
  std::vector<double> k(6 * 2);
  double condition = 0.0;
  ASSERT_TRUE(ComputeFitCoefficients(2, 2, h.Xi.data(), h.W.data(), h.N, nullptr, values.data(), 2, true,
    k.data(), condition));
  // Basis order [1, x, y, x^2, xy, y^2].
  const double f[6] = { 1, 2, -1, 0, 0.5, 0 }, g[6] = { -3, 0, 0, 0, 0, 1 };
  for (int a = 0; a < 6; ++a)
  {
    EXPECT_NEAR(k[2 * a], f[a], 1e-11);
    EXPECT_NEAR(k[2 * a + 1], g[a], 1e-11);
  }
  const double xi[2] = { 0.3, -0.2 };
  double out[2], grad[4];
  EvaluateFit(2, 2, xi, k.data(), 2, out, grad);
  EXPECT_NEAR(out[0], 1 + 0.6 + 0.2 - 0.03, 1e-12);
  EXPECT_NEAR(grad[0], 2 + 0.5 * -0.2, 1e-12); // df/dx
  EXPECT_NEAR(grad[2], -1 + 0.5 * 0.3, 1e-12); // df/dy
  EXPECT_NEAR(grad[3], -0.4, 1e-12);           // dg/dy
}
} // namespace
