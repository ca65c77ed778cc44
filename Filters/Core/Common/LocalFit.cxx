// SPDX-License-Identifier: BSD-3-Clause
// Run-time dispatch of the templated local fits (LocalFit.h) on (dimension, degree), and the fits with many
// right-hand sides used by LS, WLS and PU-WLS.
#include "Common/LocalFit.h"

#include <vector>

namespace meshfree
{
namespace
{
// Calls F::template Run<D, M>(args...) for dimension 0..3 and degree 0..3 (dimension 0 only has degree 0:
// a cloud of one position carries constants only).
template <class F, class... Args>
bool Dispatch(int dimension, int degree, Args&&... args)
{
  if (dimension <= 0)
  {
    return F::template Run<0, 0>(args...);
  }
#define MESHFREE_DEGREES(D)                                                                              \
  switch (degree)                                                                                        \
  {                                                                                                      \
    case 0:                                                                                              \
      return F::template Run<D, 0>(args...);                                                            \
    case 1:                                                                                              \
      return F::template Run<D, 1>(args...);                                                            \
    case 2:                                                                                              \
      return F::template Run<D, 2>(args...);                                                            \
    default:                                                                                             \
      return F::template Run<D, 3>(args...);                                                            \
  }
  switch (dimension)
  {
    case 1:
      MESHFREE_DEGREES(1)
    case 2:
      MESHFREE_DEGREES(2)
    default:
      MESHFREE_DEGREES(3)
  }
#undef MESHFREE_DEGREES
}

struct MLSRun
{
  template <int D, int M>
  static bool Run(const double* xi, const double* w, const double* dw, int n, bool gradient,
    bool exactCondition, double* rows, double* phi, double* dphi, double& condition)
  {
    return MLSShapeFunctions<D, M>(xi, w, dw, n, gradient, exactCondition, rows, phi, dphi, condition);
  }
};

template <int D, int M>
void AccumulateT(const double* xi, const double* w, int n, const Index* ids, const double* values,
  int components, double* moment, double* rhs)
{
  using Basis = PolynomialBasis<D, M>;
  constexpr int Q = Basis::Size;
  double p[Q];
  for (int j = 0; j < n; ++j)
  {
    const double wj = w ? w[j] : 1.0;
    if (!(wj > 0.0))
    {
      continue;
    }
    Basis::Evaluate(xi + 3 * j, p);
    for (int a = 0; a < Q; ++a)
    {
      const double wp = wj * p[a];
      for (int b = a; b < Q; ++b)
      {
        moment[a * Q + b] += wp * p[b];
      }
      const double* f = values + static_cast<size_t>(ids ? ids[j] : j) * components;
      double* r = rhs + static_cast<size_t>(a) * components;
      for (int c = 0; c < components; ++c)
      {
        r[c] += wp * f[c];
      }
    }
  }
}

struct AccumulateRun
{
  template <int D, int M>
  static bool Run(const double* xi, const double* w, int n, const Index* ids, const double* values,
    int components, double* moment, double* rhs)
  {
    AccumulateT<D, M>(xi, w, n, ids, values, components, moment, rhs);
    return true;
  }
};

struct SolveRun
{
  template <int D, int M>
  static bool Run(double* moment, const double* rhs, int components, bool exactCondition,
    double* coefficients, double& condition)
  {
    constexpr int Q = BasisSize(D, M);
    Eigen::Matrix<double, Q, Q> m;
    for (int a = 0; a < Q; ++a)
    {
      for (int b = 0; b < Q; ++b)
      {
        m(a, b) = a <= b ? moment[a * Q + b] : moment[b * Q + a];
      }
    }
    using RowMajor = Eigen::Matrix<double, Q, Eigen::Dynamic, Eigen::RowMajor>;
    const Eigen::Map<const RowMajor> b(rhs, Q, components);
    RowMajor y(Q, components);
    if (!SolveMoment<Q>(m, b, y, exactCondition, condition))
    {
      return false;
    }
    Eigen::Map<RowMajor>(coefficients, Q, components) = y;
    return true;
  }
};

struct EvaluateRun
{
  template <int D, int M>
  static bool Run(const double* xi, const double* coefficients, int components, double* out, double* gradient)
  {
    using Basis = PolynomialBasis<D, M>;
    constexpr int Q = Basis::Size;
    double p[Q];
    double dp[(D > 0 ? D : 1) * Q];
    if (gradient)
    {
      Basis::Derivatives(xi, p, dp);
    }
    else
    {
      Basis::Evaluate(xi, p);
    }
    for (int c = 0; c < components; ++c)
    {
      double v = 0.0;
      for (int a = 0; a < Q; ++a)
      {
        v += p[a] * coefficients[a * components + c];
      }
      out[c] = v;
      if (gradient)
      {
        for (int d = 0; d < D; ++d)
        {
          double g = 0.0;
          for (int a = 0; a < Q; ++a)
          {
            g += dp[d * Q + a] * coefficients[a * components + c];
          }
          gradient[d * components + c] = g;
        }
      }
    }
    return true;
  }
};
} // namespace

bool ComputeMLSShapeFunctions(int dimension, int degree, const double* xi, const double* w,
  const double* dw, int n, bool gradient, bool exactCondition, double* rows, double* phi, double* dphi,
  double& condition)
{
  return Dispatch<MLSRun>(
    dimension, degree, xi, w, dw, n, gradient, exactCondition, rows, phi, dphi, condition);
}

void AccumulateFit(int dimension, int degree, const double* xi, const double* w, int n, const Index* ids,
  const double* values, int components, double* moment, double* rhs)
{
  Dispatch<AccumulateRun>(dimension, degree, xi, w, n, ids, values, components, moment, rhs);
}

bool SolveAccumulatedFit(int dimension, int degree, double* moment, const double* rhs, int components,
  bool exactCondition, double* coefficients, double& condition)
{
  return Dispatch<SolveRun>(dimension, degree, moment, rhs, components, exactCondition, coefficients, condition);
}

bool ComputeFitCoefficients(int dimension, int degree, const double* xi, const double* w, int n,
  const Index* ids, const double* values, int components, bool exactCondition, double* coefficients,
  double& condition)
{
  const int q = BasisSize(dimension <= 0 ? 0 : std::min(dimension, 3), dimension <= 0 ? 0 : degree);
  int valid = 0;
  for (int j = 0; j < n; ++j)
  {
    valid += (w ? w[j] > 0.0 : true) ? 1 : 0;
  }
  if (valid < q)
  {
    condition = std::numeric_limits<double>::infinity();
    return false;
  }
  std::vector<double> moment(static_cast<size_t>(q) * q, 0.0);
  std::vector<double> rhs(static_cast<size_t>(q) * std::max(components, 0), 0.0);
  AccumulateFit(dimension, degree, xi, w, n, ids, values, components, moment.data(), rhs.data());
  return SolveAccumulatedFit(
    dimension, degree, moment.data(), rhs.data(), components, exactCondition, coefficients, condition);
}

void EvaluateFit(int dimension, int degree, const double* xi, const double* coefficients, int components,
  double* out, double* gradient)
{
  Dispatch<EvaluateRun>(dimension, degree, xi, coefficients, components, out, gradient);
}

} // namespace meshfree
