// SPDX-License-Identifier: BSD-3-Clause
// Private to the Approximator: radial basis function interpolation (Method RBF), global or as a partition of
// unity of local fits (RBF-PU).
//
// Each fit is a polyharmonic spline with a polynomial tail (Wendland 2005, ch. 8; Fasshauer 2007, ch. 6-8),
//   s(x) = sum_j w_j phi(|xi - xi_j|) + sum_k c_k b_k(xi),   phi(r) = r^2 log r (2D), r^3 (1D, 3D),
// in local coordinates xi = A (x - x_c) / L shifted to the fit's centre, rotated onto the cloud's intrinsic
// axes and scaled by the fit's radius L (|xi| <= 1; the polyharmonic splines are scale invariant, so this
// changes the conditioning, not the interpolant). The interpolation conditions with smoothing lambda,
//   (K + lambda' I) w + P c = f,   P^T w = 0,
// are solved in the null space of P^T: P = Q [R; 0] (Householder), w = Q2 z with
//   (Q2^T K Q2 + lambda' I) z = Q2^T f,   R c = Q1^T (f - K w - lambda' w),
// whose matrix is symmetric positive definite for distinct points, both kernels being conditionally positive
// definite of order 2 (degree-1 tail or higher). Cholesky (LLT) solves it; its 1-norm condition estimate
// (Eigen's rcond) is the fit's condition number. Fallback chain: the tail's degree is lowered while P is
// rank-deficient (too few points, or points on a line or a plane of a lower-dimensional set) -> when the
// Cholesky fails or the estimate exceeds kRBFMaxCondition, a symmetric eigen-decomposition solves it as a least-
// squares problem, dropping eigenvalues below 1e-13 of the largest (the fit is counted in Report().Regularized)
// -> a fit that is still not finite is dropped (a global fit: every point masked; a PU patch: not blended).
// Smoothing has SciPy's meaning (RBFInterpolator's `smoothing`, the kernel in data units): lambda' = lambda /
// L^beta in the scaled coordinates (beta = 2 for r^2 log r, 3 for r^3), so that each fit is exactly SciPy's.
//
// Duplicates: points closer than 1e-10 of the cloud's diameter are merged into the first of them (in the
// order given), with the mean of their values (Report().MergedPoints): an interpolant cannot take two values
// at one place, and the system would be singular.
//
// RBF-PU (Wendland 2002; Cavoretto & De Rossi 2019): local fits at the nodes of the PU-WLS lattice, each over
// the points within max(SupportFactor R, SupportFactor d_k) of its node (R: the cover radius, d_k: the distance
// to the k-th nearest point, k = the patch size), blended by phi_c(x) = theta_c(x) / sum theta (theta: the
// weight function at |x - x_c| / R). Every patch interpolates the points its blending weight reaches, so RBF-PU
// interpolates (smoothing 0) like the global fit. A patch holds at most kRBFPatchCap x k points (the nearest).
#ifndef meshfree_ApproximationRBF_h
#define meshfree_ApproximationRBF_h

#include "Approximation/Approximation.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace meshfree
{
/// Points per RBF-PU patch by the cloud's intrinsic dimension (PatchPoints = 0).
constexpr int kRBFPatchPoints[4] = { 1, 12, 40, 160 };
/// A patch keeps at most this many times the patch size (its nearest points).
constexpr int kRBFPatchCap = 8;
/// Auto, 2D clouds without smoothing: PU-WLS of degree 3 above this many valid points; up to it, the global
/// thin-plate spline or PU-WLS of degree 3 by their leave-one-out errors (measured: at N = 100 the spline is the
/// most accurate on 8 of Renka & Brown's 10 functions, PU-WLS on 2; from N = 300 on PU-WLS is within 2x of the
/// best error at a fraction of the time; the estimate's cost, a dense system of this many rows, stays a fraction
/// of PU-WLS's time below it).
constexpr Index kAutoRBFPoints2D = 150;
/// Auto, small 2D clouds: the spline is chosen when its leave-one-out error is below PU-WLS's by more than this
/// factor (it costs several times PU-WLS's time to evaluate: about 4x at 100 points and 10^4 evaluation points).
constexpr double kAutoRBFMargin = 1.25;
/// Auto, 3D clouds without smoothing: the polyharmonic spline r^3 (global, RBF-PU above RBFGlobalLimit) or
/// PU-WLS of degree 3 over max(NeighborCount, kAutoPUPoints3D) neighbours (twice the 20 terms of the cubic
/// basis), by their leave-one-out errors at about kAutoSamples sampled neighbourhoods (AutoSampledLeaveOneOut);
/// PU-WLS is taken when its estimate is not above the spline's.
constexpr int kAutoPUPoints3D = 40;
constexpr double kAutoSamples = 32.0;
constexpr double kAutoMinimumSamples = 4.0;
/// Above this 1-norm condition estimate the Cholesky solution is not trusted (eigen-decomposition instead).
constexpr double kRBFMaxCondition = 1e14;

/// One polyharmonic fit: its local frame (origin, 1 / L) and where its centres sit in RBFData.
struct PolyharmonicFit
{
  double Origin[3] = { 0, 0, 0 };
  double InvScale = 1.0;
  int Degree = 0;       // degree of the tail used (after the fallback)
  Index Offset = 0;     // first centre in RBFData::X / W
  Index Count = 0;      // centres
  double Condition = 0.0;
  bool Regularized = false;
};

struct Approximator::RBFData
{
  bool Global = true;
  int Beta = 2;                     // 2: r^2 log r, 3: r^3, kWendlandBeta: Wendland's C2
  std::vector<double> X;            // 3 per centre: its local coordinates in its fit's frame
  std::vector<double> W;            // C per centre
  std::vector<double> Tail;         // kMaxBasisSize * C per fit (row-major, PolynomialBasis order)
  std::vector<PolyharmonicFit> Fits;
  // RBF-PU: the fits' nodes (3 per fit) and the cover radius R.
  double CoverRadius = 0.0;
  std::vector<double> Centers;
  NeighborGrid CenterGrid;
  // Duplicates: whether each point (by original id) is kept, and the values the fits use (merged means).
  std::vector<unsigned char> Kept;
  std::vector<double> Values;
  // Approximator::RBFLeaveOneOut: the global fit's leave-one-out residuals by point id (n x C; NaN for merged
  // points or when not defined).
  std::vector<double> LeaveOneOut;
};

/**
 * log(x) for positive, finite, normal x, to a few units in the last place, without branches or calls (so that
 * the evaluation loops vectorise; std::log is a call per kernel value): x = 2^e m with m in [sqrt(1/2),
 * sqrt(2)), log m = 2 atanh(s) = 2 (s + s^3/3 + s^5/5 + ...), s = (m - 1) / (m + 1), |s| < 0.172, the series
 * summed to s^23 (the next term is below 1e-18 of the sum). Zero gives a finite value (-745...), which the
 * callers multiply by r^2 = 0.
 */
inline double KernelLog(double x)
{
  std::uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  // The exponent as a double without an integer conversion: 2^52 + e_biased, minus 2^52 + 1023.
  std::uint64_t exponentBits = 0x4330000000000000ULL | (bits >> 52);
  double e;
  std::memcpy(&e, &exponentBits, sizeof e);
  e -= 4503599627370496.0 + 1023.0;
  std::uint64_t mantissaBits = (bits & 0x000FFFFFFFFFFFFFULL) | 0x3FF0000000000000ULL;
  double m;
  std::memcpy(&m, &mantissaBits, sizeof m);
  const bool high = m > 1.4142135623730951;
  m = high ? 0.5 * m : m;
  e = high ? e + 1.0 : e;
  const double s = (m - 1.0) / (m + 1.0);
  const double z = s * s;
  double p = 1.0 / 23.0;
  p = p * z + 1.0 / 21.0;
  p = p * z + 1.0 / 19.0;
  p = p * z + 1.0 / 17.0;
  p = p * z + 1.0 / 15.0;
  p = p * z + 1.0 / 13.0;
  p = p * z + 1.0 / 11.0;
  p = p * z + 1.0 / 9.0;
  p = p * z + 1.0 / 7.0;
  p = p * z + 1.0 / 5.0;
  p = p * z + 1.0 / 3.0;
  p = p * z + 1.0;
  return e * 0.69314718055994530942 + 2.0 * s * p;
}

/// RBFData::Beta of Wendland's C2 kernel (RBFKernelType::WendlandC2): phi(r) = (1 - r)^4 (4 r + 1) for r < 1,
/// 0 beyond, in coordinates scaled by the support radius (the fit's InvScale is 1 / rho). Being positive
/// definite, its systems need no scaling of the smoothing (beta 0: lambda' = lambda).
constexpr int kWendlandBeta = 0;

/// phi(r) from r^2 for beta = 2 (r^2 log r = r^2 log(r^2) / 2), 3 (r^3) and kWendlandBeta; r^2 log r and r^3
/// are 0 at r = 0.
inline double PolyharmonicValue(int beta, double r2)
{
  if (beta == kWendlandBeta)
  {
    const double r = std::sqrt(r2);
    const double t = r < 1.0 ? 1.0 - r : 0.0;
    return t * t * t * t * (4.0 * r + 1.0);
  }
  const double r2safe = r2 > 1e-300 ? r2 : 1.0; // log(1) = 0: phi(0) = 0 (and subnormal r^2 counts as 0)
  return beta == 2 ? 0.5 * r2 * KernelLog(r2safe) : r2 * std::sqrt(r2);
}

/// phi'(r) / r (the gradient is this times xi - xi_j): log(r^2) + 1 for beta = 2, 3 r for beta = 3,
/// -20 (1 - r)^3 for Wendland's C2 (0 beyond r = 1); 0 at r = 0 for the polyharmonic kernels (where
/// xi - xi_j = 0).
inline double PolyharmonicSlope(int beta, double r2)
{
  if (beta == kWendlandBeta)
  {
    const double r = std::sqrt(r2);
    const double t = r < 1.0 ? 1.0 - r : 0.0;
    return -20.0 * t * t * t;
  }
  if (!(r2 > 1e-300))
  {
    return 0.0;
  }
  return beta == 2 ? KernelLog(r2) + 1.0 : 3.0 * std::sqrt(r2);
}

/**
 * Solves one polyharmonic fit (see the file comment) over n centres with local coordinates xi (stride 3,
 * the first `dimension` used) and values f (n x C, row-major), for a tail of degree <= `degree` and smoothing
 * lambda (in the local coordinates). Writes w (n x C, row-major) and the tail (kMaxBasisSize x C, row-major;
 * the basis of the degree used) and fit.Degree, Condition, Regularized. False when no finite fit exists.
 * With leaveOneOut (n x C, row-major), lambda = 0 and a Cholesky solve, also the leave-one-out residuals
 * f_j - s_(j)(xi_j), s_(j) the fit without centre j (same tail degree), by Rippa's formula (Adv. Comput. Math.
 * 11, 1999): w_j / (A^-1)_jj, A the interpolation system [K P; P^T 0], whose top-left block of the inverse is
 * Q2 (Q2^T K Q2)^-1 Q2^T in the null-space form above. Otherwise leaveOneOut is filled with NaN.
 */
bool SolvePolyharmonic(int dimension, int beta, int degree, double lambda, const double* xi, Index n, const double* f,
  int components, double* w, double* tail, PolyharmonicFit& fit, double* leaveOneOut = nullptr);

/**
 * Evaluates one fit at the local coordinates xi: out[C] and, when gradient is not null, gradient[a * C + c]
 * (per unit xi, a < dimension).
 */
void EvaluatePolyharmonic(int dimension, int beta, const PolyharmonicFit& fit, const double* centers,
  const double* weights, const double* tail, const double* xi, int components, double* out, double* gradient);

} // namespace meshfree

#endif
