// SPDX-License-Identifier: BSD-3-Clause
// Common/MLSFastPath.h and Common/KernelShapes.h, the MESHFREE_HD code the CPU and the CUDA kernels share, checked on
// the CPU against references written here: the basis bit for bit against PolynomialBasis, the plain weights bit for
// bit against Kernel::ValueSquared, the equilibrated Cholesky solve against Eigen's LDLT of the same moment matrix,
// the pivot ratio against the exact condition number, polynomial reproduction (values and gradients) of every
// degree <= m to rounding, and the needs-robust-path answer on degenerate and near-collinear neighbourhoods.
#include "Common/KernelShapes.h"
#include "Common/Kernels.h"
#include "Common/MLSFastPath.h"
#include "Common/PolynomialBasis.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace
{
using namespace meshfree;

bool SameBits(double a, double b)
{
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}

/// A neighbourhood of n points in the unit ball (local coordinates, stride 3) with Wendland weights.
struct Cloud
{
  std::vector<double> Xi, W;
};

Cloud RandomCloud(int D, int n, unsigned seed, double squeeze = 1.0)
{
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.7, 0.7);
  Cloud c;
  for (int j = 0; j < n; ++j)
  {
    double x[3] = { u(rng), D > 1 ? squeeze * u(rng) : 0.0, D > 2 ? u(rng) : 0.0 };
    c.Xi.insert(c.Xi.end(), x, x + 3);
    const double q = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    c.W.push_back(WendlandShape(q));
  }
  return c;
}

template <int D, int M>
void Moment(const Cloud& c, double* moment)
{
  constexpr int Q = BasisSize(D, M);
  std::fill(moment, moment + Q * Q, 0.0);
  for (size_t j = 0; j < c.W.size(); ++j)
  {
    double p[Q];
    mls::EvaluateBasis<D, M>(&c.Xi[3 * j], p);
    mls::AccumulateMoment<Q>(p, c.W[j], moment);
  }
}

/// The reference: M built independently (Eigen outer products), solved by Eigen's LDLT for the identity.
template <int D, int M>
Eigen::MatrixXd ReferenceInverse(const Cloud& c)
{
  constexpr int Q = BasisSize(D, M);
  const RuntimeBasis basis(D, M);
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(Q, Q);
  for (size_t j = 0; j < c.W.size(); ++j)
  {
    Eigen::VectorXd p(Q);
    basis.Evaluate(&c.Xi[3 * j], p.data());
    m += c.W[j] * p * p.transpose();
  }
  return m.ldlt().solve(Eigen::MatrixXd::Identity(Q, Q));
}

template <int D, int M>
void CheckSolveAgainstEigen(unsigned seed)
{
  constexpr int Q = BasisSize(D, M);
  constexpr int R = Q;
  const Cloud c = RandomCloud(D, 3 * Q, seed);
  double moment[Q * Q], s[Q], y[Q * R];
  Moment<D, M>(c, moment);
  ASSERT_TRUE(mls::EquilibrateMoment<Q>(moment, s));
  // The equilibrated matrix has a unit diagonal and is symmetric.
  for (int i = 0; i < Q; ++i)
  {
    EXPECT_NEAR(moment[i * Q + i], 1.0, 1e-14);
    for (int j = 0; j < Q; ++j)
    {
      EXPECT_EQ(moment[i * Q + j], moment[j * Q + i]);
    }
  }
  double condition = 0.0;
  ASSERT_TRUE((mls::CholeskyIdentitySolve<Q, R>(moment, s, Q, y, condition)));
  const Eigen::MatrixXd inverse = ReferenceInverse<D, M>(c);
  const double scale = inverse.cwiseAbs().maxCoeff();
  for (int col = 0; col < Q; ++col)
  {
    for (int i = 0; i < Q; ++i)
    {
      EXPECT_NEAR(y[col * Q + i], inverse(i, col), 1e-9 * scale)
        << "D " << D << " M " << M << " (" << i << ", " << col << ")";
    }
  }
  // The pivot ratio is a lower bound of the exact condition number of the equilibrated matrix.
  Eigen::MatrixXd e(Q, Q);
  for (int i = 0; i < Q; ++i)
  {
    for (int j = 0; j < Q; ++j)
    {
      e(i, j) = moment[i * Q + j];
    }
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(e);
  const double kappa = eig.eigenvalues()(Q - 1) / eig.eigenvalues()(0);
  EXPECT_GE(condition, 1.0);
  EXPECT_LE(condition, kappa * (1.0 + 1e-10));
}

/// Polynomial reproduction: with phi_j = w_j b_j^T y_0 and dphi_aj = w_j b_j^T y_{1+a}, sum phi_j f(xi_j) = f(0) and
/// sum dphi_aj f(xi_j) = df/dxi_a(0) for every polynomial f of degree <= M.
template <int D, int M>
void CheckReproduction(unsigned seed)
{
  constexpr int Q = BasisSize(D, M);
  constexpr int R = mls::MLSColumns<D, M>::Value;
  const Cloud c = RandomCloud(D, 2 * Q + 3, seed);
  double moment[Q * Q], s[Q], y[Q * R];
  Moment<D, M>(c, moment);
  ASSERT_TRUE(mls::EquilibrateMoment<Q>(moment, s));
  double condition = 0.0;
  ASSERT_TRUE((mls::CholeskyIdentitySolve<Q, R>(moment, s, R, y, condition)));
  std::mt19937 rng(seed + 1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const RuntimeBasis basis(D, M);
  for (int trial = 0; trial < 5; ++trial)
  {
    // f = sum_k a_k b_k(xi): any polynomial of degree <= M; f(0) = a_0, df/dxi_a(0) = a_{1+a}.
    std::vector<double> coefficients(Q);
    for (double& a : coefficients)
    {
      a = u(rng);
    }
    double value = 0.0, gradient[3] = { 0.0, 0.0, 0.0 }, scale = 0.0;
    for (size_t j = 0; j < c.W.size(); ++j)
    {
      double p[Q], b[Q];
      mls::EvaluateBasis<D, M>(&c.Xi[3 * j], p);
      basis.Evaluate(&c.Xi[3 * j], b);
      double f = 0.0;
      for (int k = 0; k < Q; ++k)
      {
        f += coefficients[k] * b[k];
      }
      const double phi = c.W[j] * mls::ShapeDot<Q>(p, y);
      value += phi * f;
      scale += std::fabs(phi * f);
      for (int a = 0; a < D && M > 0; ++a)
      {
        gradient[a] += c.W[j] * mls::ShapeDot<Q>(p, y + (1 + a) * Q) * f;
      }
    }
    EXPECT_NEAR(value, coefficients[0], 1e-12 * std::max(1.0, scale)) << "D " << D << " M " << M;
    for (int a = 0; a < D && M > 0; ++a)
    {
      EXPECT_NEAR(gradient[a], coefficients[1 + a], 1e-10) << "D " << D << " M " << M << " axis " << a;
    }
  }
}

template <int D, int M>
void CheckBasisBits()
{
  constexpr int Q = BasisSize(D, M);
  std::mt19937 rng(D * 10 + M);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial)
  {
    const double xi[3] = { u(rng), u(rng), u(rng) };
    double p[Q], b[Q];
    mls::EvaluateBasis<D, M>(xi, p);
    PolynomialBasis<D, M>::Evaluate(xi, b);
    for (int i = 0; i < Q; ++i)
    {
      EXPECT_TRUE(SameBits(p[i], b[i])) << "D " << D << " M " << M << " monomial " << i;
    }
  }
}
} // namespace

TEST(MLSFastPath, BasisIsPolynomialBasisBitForBit)
{
  CheckBasisBits<1, 3>();
  CheckBasisBits<2, 1>();
  CheckBasisBits<2, 2>();
  CheckBasisBits<2, 3>();
  CheckBasisBits<3, 1>();
  CheckBasisBits<3, 2>();
  CheckBasisBits<3, 3>();
}

TEST(MLSFastPath, SolveMatchesEigenLDLT)
{
  for (unsigned seed = 1; seed <= 5; ++seed)
  {
    CheckSolveAgainstEigen<2, 1>(seed);
    CheckSolveAgainstEigen<2, 2>(seed);
    CheckSolveAgainstEigen<2, 3>(seed);
    CheckSolveAgainstEigen<3, 1>(seed);
    CheckSolveAgainstEigen<3, 2>(seed);
  }
}

TEST(MLSFastPath, ReproducesPolynomials)
{
  for (unsigned seed = 11; seed <= 15; ++seed)
  {
    CheckReproduction<2, 1>(seed);
    CheckReproduction<2, 2>(seed);
    CheckReproduction<2, 3>(seed);
    CheckReproduction<3, 1>(seed);
    CheckReproduction<3, 2>(seed);
  }
}

TEST(MLSFastPath, DegenerateNeighbourhoodsAreRefused)
{
  // Exactly on the line y = 0: the y monomial vanishes on every neighbour, the equilibration refuses.
  {
    Cloud c = RandomCloud(2, 20, 3, 0.0);
    double moment[36], s[6];
    Moment<2, 2>(c, moment);
    EXPECT_FALSE(mls::EquilibrateMoment<6>(moment, s));
  }
  // Collinear but not along an axis (y = 0.5 x): the equilibration passes, the Cholesky must ask for the robust path.
  {
    Cloud c = RandomCloud(2, 20, 4);
    for (size_t j = 0; j < c.W.size(); ++j)
    {
      c.Xi[3 * j + 1] = 0.5 * c.Xi[3 * j];
    }
    double moment[9], s[3], y[9], condition = -1.0;
    Moment<2, 1>(c, moment);
    ASSERT_TRUE(mls::EquilibrateMoment<3>(moment, s));
    EXPECT_FALSE((mls::CholeskyIdentitySolve<3, 3>(moment, s, 3, y, condition)));
    EXPECT_EQ(condition, -1.0); // untouched
  }
  // Nearly collinear, across the axes (y = 0.5 x + 1e-5 v: the equilibration cannot undo it as it would an
  // axis-aligned squeeze): kappa far above kFastPathRatio, flagged; the same cloud unsqueezed is not.
  {
    const Cloud fat = RandomCloud(2, 20, 5, 1.0);
    Cloud thin = fat;
    for (size_t j = 0; j < thin.W.size(); ++j)
    {
      thin.Xi[3 * j + 1] = 0.5 * thin.Xi[3 * j] + 1e-5 * thin.Xi[3 * j + 1];
    }
    double moment[36], s[6], y[18], condition = 0.0;
    Moment<2, 2>(thin, moment);
    ASSERT_TRUE(mls::EquilibrateMoment<6>(moment, s));
    EXPECT_FALSE((mls::CholeskyIdentitySolve<6, 3>(moment, s, 3, y, condition)));
    Moment<2, 2>(fat, moment);
    ASSERT_TRUE(mls::EquilibrateMoment<6>(moment, s));
    EXPECT_TRUE((mls::CholeskyIdentitySolve<6, 3>(moment, s, 3, y, condition)));
    EXPECT_LT(condition, kFastPathRatio);
  }
  // Too few points for a 3D quadratic (9 < 10): singular, flagged.
  {
    const Cloud c = RandomCloud(3, 9, 6);
    double moment[100], s[10], y[40], condition = 0.0;
    Moment<3, 2>(c, moment);
    if (mls::EquilibrateMoment<10>(moment, s))
    {
      EXPECT_FALSE((mls::CholeskyIdentitySolve<10, 4>(moment, s, 4, y, condition)));
    }
  }
  // A non-finite or non-positive M_00 is refused.
  {
    double moment[9] = { 0.0, 0, 0, 0, 1, 0, 0, 0, 1 }, s[3];
    EXPECT_FALSE(mls::EquilibrateMoment<3>(moment, s));
    moment[0] = std::numeric_limits<double>::infinity();
    EXPECT_FALSE(mls::EquilibrateMoment<3>(moment, s));
    moment[0] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(mls::EquilibrateMoment<3>(moment, s));
  }
}

TEST(KernelShapes, PlainWeightsAreKernelValueSquaredBitForBit)
{
  const KernelType plain[] = { KernelType::Wendland, KernelType::Poly6, KernelType::W3, KernelType::W4, KernelType::W5,
    KernelType::Lucy, KernelType::Spiky, KernelType::CubicSpline };
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.2);
  for (KernelType type : plain)
  {
    EXPECT_TRUE(IsPlainWeight(static_cast<int>(type))) << KernelName(type);
    for (int d = 1; d <= 3; ++d)
    {
      const Kernel kernel(type, d, 1.0);
      for (int trial = 0; trial < 200; ++trial)
      {
        const double q2 = trial == 0 ? 0.0 : (trial == 1 ? 1.0 : u(rng));
        const double expected = kernel.ValueSquared(q2);
        const double got = PlainWeightSquared(static_cast<int>(type), kernel.NormalizationFactor(), q2);
        EXPECT_TRUE(SameBits(expected, got)) << KernelName(type) << " d " << d << " q2 " << q2;
      }
    }
  }
  EXPECT_FALSE(IsPlainWeight(static_cast<int>(KernelType::Gaussian)));
  EXPECT_FALSE(IsPlainWeight(static_cast<int>(KernelType::InverseDistance)));
  EXPECT_FALSE(IsPlainWeight(static_cast<int>(KernelType::Viscosity)));
}
