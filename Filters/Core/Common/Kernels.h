// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: the weight functions (smoothing kernels) of the thesis, VTK-free.
//
// Every kernel is written as W(r) = sigma_d / h^d * f(q), q = r / h, where h is the support radius (the ONLY
// length: W = 0 for r >= h) and sigma_d makes the integral over R^d equal to 1 (except InverseDistance, and
// Viscosity in 1D, see IsNormalized()). Shape functions f(q) on 0 <= q < 1, thesis equation numbers in [..]:
//
//   Gaussian        [2.8, 3.10] exp(-9 q^2) - exp(-9)              compact, continuous; width h/3 (see below)
//   Wendland        [3.11]      (1-q)^4 (4q+1)
//   InverseDistance [3.12]      1/(q^2+eps^2) - 1/(1+eps^2)        not normalised (prefactor 1)
//   Poly6  (= W1)   [4.16,5.27] (1-q^2)^3
//   W2              [4.17]      exp(-6.25 q^2) - exp(-6.25)        (r/(0.4h))^2 = 6.25 q^2, shifted (see below)
//   W3, W5, CubicSpline [4.18, 4.20] M4(2q): 1 - 6q^2 + 6q^3 (q<=1/2), 2(1-q)^3 (1/2<q<1)
//   W4, Lucy        [4.19, 2.7] (1+3q)(1-q)^3 = 1 - 6q^2 + 8q^3 - 3q^4
//   Spiky           [5.41]      (1-q)^3
//   Viscosity       [5.47]      -q^3/2 + q^2 + 1/(2q) - 1 = (1-q)^3 (1+q) / (2q)
//
// Coincidences: W4 [4.19] IS Lucy's kernel [2.7] (expand (1+3q)(1-q)^3). W3 [4.18] is 2/3 * M4(2q) and W5 [4.20]
// is the 1D-normalised M4 with support 2 in its own variable; once rescaled to support h and normalised, W3, W5
// and CubicSpline are the same function. They are kept as separate names because the thesis uses them.
//
// Deviations from the thesis, on purpose:
//  * Gaussian: the thesis' Gaussians exp(-R^2) [2.8] / exp(-d^2/h^2) [3.10] have unbounded support. Ours uses
//    the support radius h as its only length: width h/3 (truncated at three widths) and shifted down by exp(-9)
//    so it is continuous at h. Normalised exactly (closed form with erf, see Kernels.cxx).
//  * W2 [4.17]: the thesis cuts exp(-(r/0.4h)^2) at q = 1, leaving a jump of exp(-6.25) ~ 0.2% of the peak. We
//    shift it by that amount like the Gaussian, so it is continuous and vanishes at h, then normalise it.
//  * InverseDistance [3.12]: the thesis' 1/(d^2+eps^2) has unbounded support and a dimensional eps. Ours is in
//    q = r/h with a dimensionless eps (relative to h) and tapered by 1/(1+eps^2) so it is continuous and zero
//    at h. Not normalised; it is a weight for WLS/MLS/PU, singular (interpolating) as eps -> 0.
//  * Lucy 3D: alpha = 105/(16 pi h^3) (the thesis drops the pi). Poly6 gradient/Laplacian and Spiky gradient:
//    the signs are the correct ones (the thesis flips some, see DIGEST.md).
//  * Viscosity: singular at r = 0 (~1/(2q)). For q < kMinimumQ = 1e-6 the value and derivative are evaluated
//    at q = kMinimumQ (a large finite cap: W(0) ~ 5e5 sigma/h^d), and so is the singular (3-d)/(2q^3) part of
//    its Laplacian in 1D/2D (in 3D the Laplacian 6(1-q) is regular and exact). The gradient at r = 0 is 0.
//    Not integrable in 1D: there the prefactor is 1/h and IsNormalized() is false. Spiky's Laplacian has a
//    -3(d-1)(1-q)^2/q term in 2D/3D, capped the same way; its gradient at r = 0 is 0 too.
//
// Laplacian() is the true Laplacian in Dimension() dimensions, W'' + (d-1)/r W'. For Viscosity in 3D it equals
// Mueller's closed form 45/(pi h^6)(h - r) [5.49]; MuellerViscosityLaplacian() gives that form for any d.
#ifndef meshfree_Kernels_h
#define meshfree_Kernels_h

#include "Common/KernelShapes.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace meshfree
{

enum class KernelType
{
  Gaussian,
  Wendland,
  InverseDistance,
  Poly6,
  W2,
  W3,
  W4,
  W5,
  Lucy,
  Spiky,
  Viscosity,
  CubicSpline
};

/// Number of KernelType values (they are numbered 0 .. KernelTypeCount-1).
constexpr int KernelTypeCount = 12;

/// "Gaussian", "Wendland", "InverseDistance", "Poly6", "W2", "W3", "W4", "W5", "Lucy", "Spiky", "Viscosity",
/// "CubicSpline"; "Unknown" for a value outside the enum.
const char* KernelName(KernelType type);

/// Case-insensitive inverse of KernelName. Returns false (and leaves `out` untouched) for an unknown name.
bool KernelFromName(const std::string& name, KernelType& out);

/// Mueller et al. 2003 closed form of the viscosity kernel's Laplacian, 45/(pi h^6)(h - r) for r < h, 0 beyond
/// [5.49]. It is the true Laplacian only in 3D; SPH codes use it as is in every dimension.
double MuellerViscosityLaplacian(double r, double h);

/**
 * @class Kernel
 * One radial weight function with its value, radial derivative, gradient and Laplacian, for a given kernel
 * type, dimension (1, 2, 3) and support radius h. Cheap to copy; evaluation is a switch on the type with
 * everything precomputed by the constructor (no allocation, no virtual call), meant for hot loops.
 */
class Kernel
{
public:
  /// Wendland, 3D, h = 1.
  Kernel() = default;

  /// Throws std::invalid_argument for an unknown type, a dimension outside 1..3, a support radius that is not
  /// finite and > 0 or so extreme that sigma/h^d (or its /h, /h^2 versions) leaves double's range, or
  /// (InverseDistance only, ignored otherwise) an epsilon that is not finite and > 0. Epsilon below
  /// kMinimumEpsilon acts as kMinimumEpsilon.
  Kernel(KernelType type, int dimension, double supportRadius, double epsilon = 1e-3);

  KernelType Type() const { return this->Kind; }
  int Dimension() const { return this->SpaceDimension; }
  double SupportRadius() const { return this->Radius; }
  /// Epsilon of InverseDistance (dimensionless, relative to h); stored but unused by the other kernels.
  double Epsilon() const { return this->RelativeEpsilon; }
  /// True when the integral of W over R^Dimension() is 1.
  bool IsNormalized() const { return this->HasUnitIntegral; }
  /// The prefactor sigma_d / h^d in W(r) = sigma_d / h^d f(r/h), with f(0) the table above.
  double NormalizationFactor() const { return this->Normalization; }

  /// W(r), r >= 0 (a negative r is read as |r|). Zero for r >= h.
  double Value(double r) const;
  /// dW/dr. Zero for r >= h; at r = 0 the limit from the right (0 for smooth kernels, -3 sigma/h^(d+1) Spiky).
  double RadialDerivative(double r) const;
  /// grad_x W(|x - x_j|) with rvec = x - x_j. Only the first Dimension() components of rvec are read (the
  /// distance is taken in Dimension() dims); the others of grad are set to 0. Zero at rvec = 0.
  void Gradient(const double rvec[3], double grad[3]) const;
  /// True Laplacian in Dimension() dims: W'' + (d-1)/r W'. At r = 0 the limit (d f''(0) sigma/h^(d+2)).
  double Laplacian(double r) const;
  /// W from the squared distance; avoids the square root for Gaussian, W2, InverseDistance and Poly6.
  double ValueSquared(double r2) const;

  /// Below this q the singular kernels (Viscosity, Spiky's Laplacian) are evaluated at q = kMinimumQ.
  static constexpr double kMinimumQ = 1e-6;
  /// InverseDistance: a smaller epsilon acts as this one (1/eps^2 = 1e100 stays finite in sums and fits).
  static constexpr double kMinimumEpsilon = 1e-50;

private:
  double Shape(double q) const;           // f(q), 0 <= q < 1
  double ShapeDerivative(double q) const; // f'(q), 0 <= q < 1
  double ShapeLaplacian(double q) const;  // f''(q) + (d-1)/q f'(q), 0 <= q < 1

  KernelType Kind = KernelType::Wendland;
  int SpaceDimension = 3;
  double Radius = 1.0;
  double InverseRadius = 1.0;
  double InverseRadiusSquared = 1.0;
  double RelativeEpsilon = 1e-3;
  double EpsilonSquared = 1e-6;
  double GaussExponent = 0.0; // a in exp(-a q^2): 9 (Gaussian), 6.25 (W2)
  double TaperOffset = 0.0;   // taper making f(1) = 0: exp(-a) or 1/(1+eps^2)
  // sigma_d / h^d, and its /h and /h^2 versions; the defaults are Wendland 3D with h = 1: 21/(2 pi).
  double Normalization = 21.0 / (2.0 * 3.141592653589793238462643383279502884);
  double DerivativeNormalization = Normalization;
  double LaplacianNormalization = Normalization;
  bool HasUnitIntegral = true;
};

//------------------------------------------------------------------------------
// Inline evaluation (hot loops).
inline double Kernel::Shape(double q) const
{
  switch (this->Kind)
  {
    case KernelType::Gaussian:
    case KernelType::W2:
      return std::exp(-this->GaussExponent * q * q) - this->TaperOffset;
    case KernelType::Wendland:
      return WendlandShape(q);
    case KernelType::InverseDistance:
      return 1.0 / (q * q + this->EpsilonSquared) - this->TaperOffset;
    case KernelType::Poly6:
    {
      const double s = 1.0 - q * q;
      return s * s * s;
    }
    case KernelType::W3:
    case KernelType::W5:
    case KernelType::CubicSpline:
      return CubicSplineShape(q);
    case KernelType::W4:
    case KernelType::Lucy:
      return LucyShape(q);
    case KernelType::Spiky:
      return SpikyShape(q);
    case KernelType::Viscosity:
    {
      const double qc = std::max(q, kMinimumQ);
      const double uc = 1.0 - qc;
      return uc * uc * uc * (1.0 + qc) / (2.0 * qc);
    }
  }
  return 0.0;
}

inline double Kernel::ShapeDerivative(double q) const
{
  const double u = 1.0 - q;
  switch (this->Kind)
  {
    case KernelType::Gaussian:
    case KernelType::W2:
      return -2.0 * this->GaussExponent * q * std::exp(-this->GaussExponent * q * q);
    case KernelType::Wendland:
      return -20.0 * q * u * u * u;
    case KernelType::InverseDistance:
    {
      const double s = q * q + this->EpsilonSquared;
      return -2.0 * q / (s * s);
    }
    case KernelType::Poly6:
    {
      const double s = 1.0 - q * q;
      return -6.0 * q * s * s;
    }
    case KernelType::W3:
    case KernelType::W5:
    case KernelType::CubicSpline:
      return q <= 0.5 ? q * (18.0 * q - 12.0) : -6.0 * u * u;
    case KernelType::W4:
    case KernelType::Lucy:
      return -12.0 * q * u * u;
    case KernelType::Spiky:
      return -3.0 * u * u;
    case KernelType::Viscosity:
    {
      // -3q^2/2 + 2q - 1/(2q^2) = -(1-q)^2 (3q^2 + 2q + 1) / (2q^2)
      const double qc = std::max(q, kMinimumQ);
      const double uc = 1.0 - qc;
      return -uc * uc * (3.0 * qc * qc + 2.0 * qc + 1.0) / (2.0 * qc * qc);
    }
  }
  return 0.0;
}

inline double Kernel::Value(double r) const
{
  const double q = std::fabs(r) * this->InverseRadius;
  if (!(q < 1.0))
  {
    return 0.0;
  }
  return this->Normalization * this->Shape(q);
}

inline double Kernel::ValueSquared(double r2) const
{
  const double q2 = std::fabs(r2) * this->InverseRadiusSquared;
  if (!(q2 < 1.0))
  {
    return 0.0;
  }
  switch (this->Kind)
  {
    case KernelType::Gaussian:
    case KernelType::W2:
      return this->Normalization * (std::exp(-this->GaussExponent * q2) - this->TaperOffset);
    case KernelType::InverseDistance:
      return this->Normalization * (1.0 / (q2 + this->EpsilonSquared) - this->TaperOffset);
    case KernelType::Poly6:
      return Poly6ValueSquared(this->Normalization, q2);
    default:
      return this->Normalization * this->Shape(std::sqrt(q2));
  }
}

inline double Kernel::RadialDerivative(double r) const
{
  const double q = std::fabs(r) * this->InverseRadius;
  if (!(q < 1.0))
  {
    return 0.0;
  }
  return this->DerivativeNormalization * this->ShapeDerivative(q);
}

inline void Kernel::Gradient(const double rvec[3], double grad[3]) const
{
  double r2 = 0.0;
  for (int i = 0; i < this->SpaceDimension; ++i)
  {
    r2 += rvec[i] * rvec[i];
  }
  grad[0] = grad[1] = grad[2] = 0.0;
  const double r = std::sqrt(r2);
  if (!(r > 0.0) || !(r < this->Radius))
  {
    return;
  }
  // dW/dr * rvec/r, with the unit vector formed first so singular kernels stay finite for tiny r.
  const double dWdr = this->RadialDerivative(r);
  const double invR = 1.0 / r;
  for (int i = 0; i < this->SpaceDimension; ++i)
  {
    grad[i] = dWdr * (rvec[i] * invR);
  }
}

} // namespace meshfree

#endif
