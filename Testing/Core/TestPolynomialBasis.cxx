// SPDX-License-Identifier: BSD-3-Clause
// PolynomialBasis.h: sizes, the ordering (1, linear terms, ...), exponents of every monomial against a
// brute-force enumeration, and derivatives against central differences.
#include "Common/PolynomialBasis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

namespace
{
using meshfree::BasisSize;
using meshfree::RuntimeBasis;

TEST(PolynomialBasis, Sizes)
{
  EXPECT_EQ(BasisSize(0, 3), 1);
  EXPECT_EQ(BasisSize(1, 3), 4);
  EXPECT_EQ(BasisSize(2, 2), 6);
  EXPECT_EQ(BasisSize(2, 3), 10);
  EXPECT_EQ(BasisSize(3, 2), 10);
  EXPECT_EQ(BasisSize(3, 3), 20);
  for (int d = 0; d <= 3; ++d)
  {
    for (int m = 0; m <= 3; ++m)
    {
      EXPECT_EQ(RuntimeBasis(d, m).Size(), BasisSize(d, m));
    }
  }
}

TEST(PolynomialBasis, MonomialsAreDistinctAndComplete)
{
  // Evaluate at xi = (2, 3, 5): every monomial x^a y^b z^c is a distinct integer 2^a 3^b 5^c, so the set of
  // values identifies the exponents.
  const double xi[3] = { 2.0, 3.0, 5.0 };
  for (int d = 1; d <= 3; ++d)
  {
    for (int m = 0; m <= 3; ++m)
    {
      RuntimeBasis basis(d, m);
      std::vector<double> p(basis.Size());
      basis.Evaluate(xi, p.data());
      std::set<long> got(p.begin(), p.end());
      std::set<long> expected;
      for (int a = 0; a <= m; ++a)
        for (int b = 0; b <= (d > 1 ? m - a : 0); ++b)
          for (int c = 0; c <= (d > 2 ? m - a - b : 0); ++c)
            expected.insert(std::lround(std::pow(2.0, a) * std::pow(3.0, b) * std::pow(5.0, c)));
      EXPECT_EQ(got, expected) << "d=" << d << " m=" << m;
      EXPECT_EQ(p[0], 1.0);
      for (int a = 0; a < d && m > 0; ++a)
      {
        EXPECT_EQ(p[1 + a], xi[a]) << "linear terms come right after the constant";
      }
    }
  }
}

TEST(PolynomialBasis, TemplateMatchesRuntimeAndDerivatives)
{
  const double xi[3] = { 0.3, -0.7, 0.45 };
  meshfree::PolynomialBasis<3, 3> t;
  (void)t;
  double p[20], dp[60];
  meshfree::PolynomialBasis<3, 3>::Derivatives(xi, p, dp);
  RuntimeBasis basis(3, 3);
  double q[20], dq[60];
  basis.Derivatives(xi, q, dq);
  for (int i = 0; i < 20; ++i)
  {
    EXPECT_DOUBLE_EQ(p[i], q[i]);
  }
  const double step = 1e-5;
  for (int a = 0; a < 3; ++a)
  {
    double plus[3] = { xi[0], xi[1], xi[2] }, minus[3] = { xi[0], xi[1], xi[2] };
    plus[a] += step;
    minus[a] -= step;
    double pp[20], pm[20];
    basis.Evaluate(plus, pp);
    basis.Evaluate(minus, pm);
    for (int i = 0; i < 20; ++i)
    {
      EXPECT_NEAR(dp[a * 20 + i], (pp[i] - pm[i]) / (2 * step), 1e-8) << "a=" << a << " i=" << i;
      EXPECT_DOUBLE_EQ(dp[a * 20 + i], dq[a * 20 + i]);
    }
  }
}
} // namespace
