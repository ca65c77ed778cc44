// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: weight functions. Formulas and thesis equation numbers: see Kernels.h.
#include "Common/Kernels.h"

#include <cctype>
#include <cstdio>
#include <stdexcept>

namespace meshfree
{

namespace
{
constexpr double kPi = 3.141592653589793238462643383279502884;

// Exponents a of the truncated Gaussians exp(-a q^2) - exp(-a).
constexpr double kGaussianExponent = 9.0; // width h/3: exp(-(3q)^2)           [2.8, 3.10]
constexpr double kW2Exponent = 6.25;      // exp(-(r/(0.4h))^2) = exp(-6.25 q^2) [4.17]

const char* const kNames[KernelTypeCount] = { "Gaussian", "Wendland", "InverseDistance", "Poly6", "W2", "W3",
  "W4", "W5", "Lucy", "Spiky", "Viscosity", "CubicSpline" };

// Measure of the unit sphere S^{d-1}: |S^0| = 2, |S^1| = 2 pi, |S^2| = 4 pi.
double SphereMeasure(int d)
{
  return d == 1 ? 2.0 : (d == 2 ? 2.0 * kPi : 4.0 * kPi);
}

// Radial moment M_d(a) = int_0^1 (exp(-a q^2) - exp(-a)) q^(d-1) dq in closed form:
//   d = 1: sqrt(pi)/(2 sqrt(a)) erf(sqrt(a)) - e^-a
//   d = 2: (1 - e^-a)/(2a) - e^-a/2
//   d = 3: sqrt(pi)/(4 a^(3/2)) erf(sqrt(a)) - e^-a/(2a) - e^-a/3   (by parts: int q^2 e^-aq^2 = ...)
double TruncatedGaussianMoment(double a, int d)
{
  const double ea = std::exp(-a);
  const double sa = std::sqrt(a);
  switch (d)
  {
    case 1:
      return std::sqrt(kPi) / (2.0 * sa) * std::erf(sa) - ea;
    case 2:
      return (1.0 - ea) / (2.0 * a) - ea / 2.0;
    default:
      return std::sqrt(kPi) / (4.0 * a * sa) * std::erf(sa) - ea / (2.0 * a) - ea / 3.0;
  }
}

// sigma_d such that sigma_d / h^d f(r/h) integrates to 1 over R^d, i.e. sigma_d = 1 / (|S^{d-1}| M_d) with
// M_d = int_0^1 f(q) q^(d-1) dq. The rational moments were integrated by hand (substituting u = 1 - q) and
// are checked numerically by TestKernels (radial Gauss-Legendre quadrature). Returns 0 where f is not
// integrable (Viscosity in 1D) and for InverseDistance (not normalised).
double Sigma(KernelType type, int d)
{
  switch (type)
  {
    case KernelType::Gaussian:
      return 1.0 / (SphereMeasure(d) * TruncatedGaussianMoment(kGaussianExponent, d));
    case KernelType::W2:
      return 1.0 / (SphereMeasure(d) * TruncatedGaussianMoment(kW2Exponent, d));
    case KernelType::Wendland: // M_d = 1/3, 1/14, 1/42                         [3.11]
    {
      const double s[3] = { 3.0 / 2.0, 7.0 / kPi, 21.0 / (2.0 * kPi) };
      return s[d - 1];
    }
    case KernelType::Poly6: // M_d = 16/35, 1/8, 16/315                          [4.16, 5.27]
    {
      const double s[3] = { 35.0 / 32.0, 4.0 / kPi, 315.0 / (64.0 * kPi) };
      return s[d - 1];
    }
    case KernelType::W3:
    case KernelType::W5:
    case KernelType::CubicSpline: // M4(2q): M_d = 3/8, 7/80, 1/32               [4.18, 4.20]
    {
      // = the usual 2/3, 10/(7 pi), 1/pi of M4 with smoothing length h/2.
      const double s[3] = { 4.0 / 3.0, 40.0 / (7.0 * kPi), 8.0 / kPi };
      return s[d - 1];
    }
    case KernelType::W4:
    case KernelType::Lucy: // M_d = 2/5, 1/10, 4/105                             [2.7, 4.19]
    {
      const double s[3] = { 5.0 / 4.0, 5.0 / kPi, 105.0 / (16.0 * kPi) };
      return s[d - 1];
    }
    case KernelType::Spiky: // M_d = 1/4, 1/20, 1/60                             [5.41]
    {
      const double s[3] = { 2.0, 10.0 / kPi, 15.0 / kPi };
      return s[d - 1];
    }
    case KernelType::Viscosity: // M_d = inf, 3/20, 1/30                          [5.47]
    {
      const double s[3] = { 0.0, 10.0 / (3.0 * kPi), 15.0 / (2.0 * kPi) };
      return s[d - 1];
    }
    case KernelType::InverseDistance:
      return 0.0;
  }
  return 0.0;
}

std::string Lower(const std::string& s)
{
  std::string out(s);
  for (char& c : out)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}
} // namespace

//------------------------------------------------------------------------------
const char* KernelName(KernelType type)
{
  const int i = static_cast<int>(type);
  return (i >= 0 && i < KernelTypeCount) ? kNames[i] : "Unknown";
}

bool KernelFromName(const std::string& name, KernelType& out)
{
  const std::string lower = Lower(name);
  for (int i = 0; i < KernelTypeCount; ++i)
  {
    if (lower == Lower(kNames[i]))
    {
      out = static_cast<KernelType>(i);
      return true;
    }
  }
  return false;
}

double MuellerViscosityLaplacian(double r, double h)
{
  r = std::fabs(r);
  if (!(h > 0.0) || !(r < h))
  {
    return 0.0;
  }
  const double h2 = h * h;
  return 45.0 / (kPi * h2 * h2 * h2) * (h - r); // [5.49]
}

//------------------------------------------------------------------------------
Kernel::Kernel(KernelType type, int dimension, double supportRadius, double epsilon)
{
  const int t = static_cast<int>(type);
  if (t < 0 || t >= KernelTypeCount)
  {
    throw std::invalid_argument("meshfree::Kernel: unknown kernel type " + std::to_string(t));
  }
  if (dimension < 1 || dimension > 3)
  {
    throw std::invalid_argument(
      "meshfree::Kernel: dimension must be 1, 2 or 3, got " + std::to_string(dimension));
  }
  if (!std::isfinite(supportRadius) || !(supportRadius > 0.0))
  {
    throw std::invalid_argument(
      "meshfree::Kernel: support radius must be finite and > 0, got " + std::to_string(supportRadius));
  }
  if (type == KernelType::InverseDistance && (!std::isfinite(epsilon) || !(epsilon > 0.0)))
  {
    throw std::invalid_argument(
      "meshfree::Kernel: InverseDistance epsilon must be finite and > 0, got " + std::to_string(epsilon));
  }

  this->Kind = type;
  this->SpaceDimension = dimension;
  this->Radius = supportRadius;
  this->InverseRadius = 1.0 / supportRadius;
  this->InverseRadiusSquared = this->InverseRadius * this->InverseRadius;
  this->RelativeEpsilon = epsilon;
  // InverseDistance: W(0) = 1/eps^2 must stay finite, with room for sums of many weights and for the
  // moment matrices built from them: eps below kMinimumEpsilon acts as kMinimumEpsilon (then W(0) = 1e100,
  // the fit interpolates the data to ~1e-100 relative, as eps -> 0 should).
  this->EpsilonSquared = std::max(epsilon, kMinimumEpsilon) * std::max(epsilon, kMinimumEpsilon);
  this->GaussExponent = 0.0;
  this->TaperOffset = 0.0;
  if (type == KernelType::Gaussian || type == KernelType::W2)
  {
    this->GaussExponent = type == KernelType::Gaussian ? kGaussianExponent : kW2Exponent;
    this->TaperOffset = std::exp(-this->GaussExponent);
  }
  else if (type == KernelType::InverseDistance)
  {
    this->TaperOffset = 1.0 / (1.0 + this->EpsilonSquared);
  }

  // sigma_d / h^d, with 1/h^d as a product of 1/h.
  double invHd = 1.0;
  for (int i = 0; i < dimension; ++i)
  {
    invHd *= this->InverseRadius;
  }
  const double sigma = Sigma(type, dimension);
  this->HasUnitIntegral = sigma > 0.0;
  if (type == KernelType::InverseDistance)
  {
    this->Normalization = 1.0; // a dimensionless weight, W(0) = 1/eps^2 - 1/(1+eps^2)
  }
  else if (!this->HasUnitIntegral)
  {
    this->Normalization = this->InverseRadius; // Viscosity 1D: not integrable; prefactor 1/h keeps units of a 1D density
  }
  else
  {
    this->Normalization = sigma * invHd;
  }
  this->DerivativeNormalization = this->Normalization * this->InverseRadius;
  this->LaplacianNormalization = this->Normalization * this->InverseRadiusSquared;
  // sigma/h^d and its /h, /h^2 versions must be representable: a support of 1e-300 in 3D overflows them (and
  // 0 * inf would give NaN), one of 1e300 underflows sigma/h^d to 0 (a kernel that is zero everywhere).
  if (!std::isfinite(this->Normalization) || !std::isfinite(this->DerivativeNormalization) ||
    !std::isfinite(this->LaplacianNormalization) || !std::isfinite(this->InverseRadiusSquared) ||
    !(this->Normalization > 0.0))
  {
    char text[160];
    std::snprintf(text, sizeof text,
      "meshfree::Kernel: support radius %g is out of range in dimension %d (the normalisation sigma/h^d or "
      "its derivatives over- or underflow)",
      supportRadius, dimension);
    throw std::invalid_argument(text);
  }
}

//------------------------------------------------------------------------------
// f''(q) + (d-1)/q f'(q), simplified by hand per kernel so there is no 0/0 at q = 0 and no cancellation at q = 1.
double Kernel::ShapeLaplacian(double q) const
{
  const double d = this->SpaceDimension;
  const double u = 1.0 - q;
  switch (this->Kind)
  {
    case KernelType::Gaussian:
    case KernelType::W2:
    {
      // f' = -2a q e^(-aq^2), f'' = (4a^2 q^2 - 2a) e^(-aq^2)
      const double a = this->GaussExponent;
      return (4.0 * a * a * q * q - 2.0 * a * d) * std::exp(-a * q * q);
    }
    case KernelType::Wendland:
      // f' = -20 q u^3, f'' = -20 u^2 (1 - 4q)
      return -20.0 * u * u * (d - (d + 3.0) * q);
    case KernelType::InverseDistance:
    {
      // f' = -2q/s^2, f'' = -2/s^2 + 8q^2/s^3, s = q^2 + eps^2
      const double s = q * q + this->EpsilonSquared;
      return (8.0 * q * q / s - 2.0 * d) / (s * s);
    }
    case KernelType::Poly6:
    {
      // f' = -6q s^2, f'' = -6 s (1 - 5q^2), s = 1 - q^2. 3D: 945/(32 pi h^9)(h^2-r^2)(7r^2-3h^2) [5.27+]
      const double s = 1.0 - q * q;
      return -6.0 * s * (d - (d + 4.0) * q * q);
    }
    case KernelType::W3:
    case KernelType::W5:
    case KernelType::CubicSpline:
      // q <= 1/2: f' = -12q + 18q^2, f'' = -12 + 36q;  q > 1/2: f' = -6u^2, f'' = 12u
      return q <= 0.5 ? -12.0 * d + 18.0 * (d + 1.0) * q : 12.0 * u - 6.0 * (d - 1.0) * u * u / q;
    case KernelType::W4:
    case KernelType::Lucy:
      // f' = -12 q u^2, f'' = -12 u (1 - 3q)
      return -12.0 * u * (d - (d + 2.0) * q);
    case KernelType::Spiky:
    {
      // f' = -3u^2, f'' = 6u; the (d-1)/q f' term is singular at q = 0 (capped)
      const double qc = std::max(q, kMinimumQ);
      return 6.0 * u - 3.0 * (d - 1.0) * u * u / qc;
    }
    case KernelType::Viscosity:
    {
      // f'' = -3q + 2 + 1/q^3; f'' + (d-1)/q f' = -3(d+1)/2 q + 2d + (3-d)/(2q^3)
      //     = (1-q) [3(d+1)/2 q^3 + (3-d)/2 (q^2 + q + 1)] / q^3   (3D: 6(1-q), i.e. 45/(pi h^6)(h-r) [5.49])
      // Only the (3-d)/q^3 part is singular (not in 3D); it alone is capped.
      const double qc = std::max(q, kMinimumQ);
      return u * (1.5 * (d + 1.0) + 0.5 * (3.0 - d) * (qc * qc + qc + 1.0) / (qc * qc * qc));
    }
  }
  return 0.0;
}

double Kernel::Laplacian(double r) const
{
  const double q = std::fabs(r) * this->InverseRadius;
  if (!(q < 1.0))
  {
    return 0.0;
  }
  return this->LaplacianNormalization * this->ShapeLaplacian(q);
}

} // namespace meshfree

// KernelShapes.h numbers the plain-arithmetic weights like KernelType (device code cannot see the enum class).
static_assert(meshfree::kPlainWendland == static_cast<int>(meshfree::KernelType::Wendland) &&
    meshfree::kPlainPoly6 == static_cast<int>(meshfree::KernelType::Poly6) &&
    meshfree::kPlainW3 == static_cast<int>(meshfree::KernelType::W3) &&
    meshfree::kPlainW4 == static_cast<int>(meshfree::KernelType::W4) &&
    meshfree::kPlainW5 == static_cast<int>(meshfree::KernelType::W5) &&
    meshfree::kPlainLucy == static_cast<int>(meshfree::KernelType::Lucy) &&
    meshfree::kPlainSpiky == static_cast<int>(meshfree::KernelType::Spiky) &&
    meshfree::kPlainCubicSpline == static_cast<int>(meshfree::KernelType::CubicSpline),
  "KernelShapes.h's PlainWeight must follow KernelType");
