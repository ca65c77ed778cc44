// SPDX-License-Identifier: BSD-3-Clause
// Weight functions (Filters/Core/Kernels.h): normalisation by independent radial quadrature and against the
// published constants, derivatives against fourth-order Cartesian finite differences, compact support, scale
// invariance, symmetry, monotonicity, finiteness at r = 0, invalid arguments and names.
#include "Common/Kernels.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace
{
using meshfree::Kernel;
using meshfree::KernelType;

constexpr double kPi = 3.141592653589793238462643383279502884;

static_assert(std::is_trivially_copyable<Kernel>::value, "Kernel must stay a cheap value type for hot loops");

std::vector<KernelType> AllTypes()
{
  std::vector<KernelType> types;
  for (int i = 0; i < meshfree::KernelTypeCount; ++i)
    types.push_back(static_cast<KernelType>(i));
  return types;
}

// Calls f(type, dimension) for every kernel type in 1D, 2D and 3D.
void ForEachTypeAndDimension(const std::function<void(KernelType, int)>& f)
{
  for (KernelType t : AllTypes())
    for (int d = 1; d <= 3; ++d)
      f(t, d);
}

bool IsCubicSpline(KernelType t)
{
  return t == KernelType::W3 || t == KernelType::W5 || t == KernelType::CubicSpline;
}

bool ExpectNormalized(KernelType t, int d)
{
  return t != KernelType::InverseDistance && !(t == KernelType::Viscosity && d == 1);
}

std::string Describe(const Kernel& k)
{
  return std::string(meshfree::KernelName(k.Type())) + " d=" + std::to_string(k.Dimension()) +
    " h=" + std::to_string(k.SupportRadius()) + " eps=" + std::to_string(k.Epsilon());
}

// Gauss-Legendre nodes and weights on [-1, 1] (Newton on P_n).
struct GaussLegendre
{
  std::vector<double> x, w;
  explicit GaussLegendre(int n)
  {
    for (int i = 0; i < n; ++i)
    {
      double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1.0;
      for (int it = 0; it < 100; ++it)
      {
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= n; ++k)
        {
          const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (z * p1 - p0) / (z * z - 1.0);
        const double dz = p1 / dp;
        z -= dz;
        if (std::fabs(dz) < 1e-16)
          break;
      }
      x.push_back(z);
      w.push_back(2.0 / ((1.0 - z * z) * dp * dp));
    }
  }
};

// Integral of W over R^d: |S^{d-1}| int_0^h W(r) r^(d-1) dr by 20-point Gauss-Legendre on 64 equal panels; the
// panel edges include the only kink inside the support (q = 1/2 of the cubic spline). Exact for the polynomial
// kernels, ~1e-15 for the Gaussians.
double IntegralOverSpace(const Kernel& k)
{
  static const GaussLegendre gl(20);
  const int d = k.Dimension(), panels = 64;
  const double h = k.SupportRadius();
  double sum = 0.0;
  for (int p = 0; p < panels; ++p)
  {
    const double mid = h * (p + 0.5) / panels, half = 0.5 * h / panels;
    for (size_t i = 0; i < gl.x.size(); ++i)
    {
      const double r = mid + half * gl.x[i];
      sum += half * gl.w[i] * k.Value(r) * std::pow(r, d - 1);
    }
  }
  return (d == 1 ? 2.0 : (d == 2 ? 2.0 * kPi : 4.0 * kPi)) * sum;
}

// Sample q in [qMin, 0.97], off round numbers, at least `margin` away from the cubic spline's kink at 1/2.
std::vector<double> SampleQ(KernelType t, double margin, double qMin = 0.03)
{
  std::vector<double> qs;
  for (double q = qMin + 0.00123; q <= 0.97; q += 0.01)
    if (!(IsCubicSpline(t) && std::fabs(q - 0.5) < margin))
      qs.push_back(q);
  return qs;
}

// W at x shifted by `shift` along `axis`, the distance taken in Dimension() dims.
double ValueAt(const Kernel& k, const double x[3], int axis = 0, double shift = 0.0)
{
  double y[3] = { x[0], x[1], x[2] }, r2 = 0.0;
  y[axis] += shift;
  for (int i = 0; i < k.Dimension(); ++i)
    r2 += y[i] * y[i];
  return k.Value(std::sqrt(r2));
}

// Fourth-order central differences (error O(delta^4)), so that the tolerances can be tight.
double FirstDifference(const std::function<double(double)>& f, double delta)
{
  return (f(-2 * delta) - 8.0 * f(-delta) + 8.0 * f(delta) - f(2 * delta)) / (12.0 * delta);
}
double SecondDifference(const std::function<double(double)>& f, double delta)
{
  return (-f(-2 * delta) + 16.0 * f(-delta) - 30.0 * f(0.0) + 16.0 * f(delta) - f(2 * delta)) /
    (12.0 * delta * delta);
}

// A random point at distance r in the first d dimensions (components beyond d are 0).
void RandomPoint(std::mt19937& rng, int d, double r, double x[3])
{
  std::normal_distribution<double> n(0.0, 1.0);
  double norm2 = 0.0;
  while (norm2 < 1e-6)
  {
    x[0] = n(rng), x[1] = d > 1 ? n(rng) : 0.0, x[2] = d > 2 ? n(rng) : 0.0;
    norm2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
  }
  for (int i = 0; i < 3; ++i)
    x[i] *= r / std::sqrt(norm2);
}

// Every type and dimension for two support radii; InverseDistance also with a large epsilon.
std::vector<Kernel> DerivativeTestKernels()
{
  std::vector<Kernel> ks;
  ForEachTypeAndDimension([&](KernelType t, int d) {
    for (double h : { 0.7, 2.3 })
    {
      ks.emplace_back(t, d, h);
      if (t == KernelType::InverseDistance)
        ks.emplace_back(t, d, h, 0.1);
    }
  });
  return ks;
}
} // namespace

//------------------------------------------------------------------------------
TEST(KernelNames, RoundTripAndCaseInsensitive)
{
  const char* expected[] = { "Gaussian", "Wendland", "InverseDistance", "Poly6", "W2", "W3", "W4", "W5", "Lucy",
    "Spiky", "Viscosity", "CubicSpline" };
  for (KernelType t : AllTypes())
  {
    const std::string name = meshfree::KernelName(t);
    EXPECT_EQ(name, expected[static_cast<int>(t)]);
    std::string upper = name, lower = name;
    std::transform(name.begin(), name.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
    std::transform(name.begin(), name.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    for (const std::string& s : { name, upper, lower })
    {
      KernelType back = t == KernelType::Spiky ? KernelType::Lucy : KernelType::Spiky;
      EXPECT_TRUE(meshfree::KernelFromName(s, back)) << s;
      EXPECT_EQ(back, t) << s;
    }
  }
  KernelType out = KernelType::Spiky;
  for (const char* bad : { "", "Wendland ", "W6", "Gauss", "poly 6" })
    EXPECT_FALSE(meshfree::KernelFromName(bad, out)) << bad;
  EXPECT_EQ(out, KernelType::Spiky); // untouched on failure
  EXPECT_STREQ(meshfree::KernelName(static_cast<KernelType>(99)), "Unknown");
}

TEST(KernelConstruction, DefaultIsWendland3DUnitSupport)
{
  const Kernel k, ref(KernelType::Wendland, 3, 1.0);
  EXPECT_EQ(k.Type(), KernelType::Wendland);
  EXPECT_EQ(k.Dimension(), 3);
  EXPECT_EQ(k.SupportRadius(), 1.0);
  EXPECT_TRUE(k.IsNormalized());
  for (double r : { 0.0, 0.1, 0.5, 0.99, 1.0 })
  {
    EXPECT_DOUBLE_EQ(k.Value(r), ref.Value(r));
    EXPECT_DOUBLE_EQ(k.RadialDerivative(r), ref.RadialDerivative(r));
    EXPECT_DOUBLE_EQ(k.Laplacian(r), ref.Laplacian(r));
  }
}

TEST(KernelConstruction, InvalidArgumentsThrow)
{
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  ForEachTypeAndDimension([&](KernelType t, int d) {
    for (double h : { 0.0, -0.0, -1.0, inf, -inf, nan })
      EXPECT_THROW(Kernel(t, d, h), std::invalid_argument) << meshfree::KernelName(t) << " h=" << h;
    EXPECT_NO_THROW(Kernel(t, d, 1.0));
  });
  for (KernelType t : AllTypes())
    for (int d : { -1, 0, 4, 100 })
      EXPECT_THROW(Kernel(t, d, 1.0), std::invalid_argument) << meshfree::KernelName(t) << " d=" << d;
  for (double eps : { 0.0, -1e-3, inf, nan })
  {
    EXPECT_THROW(Kernel(KernelType::InverseDistance, 2, 1.0, eps), std::invalid_argument) << eps;
    EXPECT_NO_THROW(Kernel(KernelType::Wendland, 2, 1.0, eps)); // epsilon is read by InverseDistance only
  }
  EXPECT_THROW(Kernel(static_cast<KernelType>(-1), 3, 1.0), std::invalid_argument);
  EXPECT_THROW(Kernel(static_cast<KernelType>(meshfree::KernelTypeCount), 3, 1.0), std::invalid_argument);
  std::string message;
  try
  {
    Kernel(KernelType::Poly6, 3, -2.0);
  }
  catch (const std::invalid_argument& e)
  {
    message = e.what();
  }
  EXPECT_NE(message.find("support radius"), std::string::npos) << message; // a clear message
}

//------------------------------------------------------------------------------
TEST(KernelNormalization, IntegralIsOneInEveryDimensionAndScale)
{
  ForEachTypeAndDimension([](KernelType t, int d) {
    for (double h : { 1e-6, 0.37, 1.0, 4.2, 1e6 })
    {
      const Kernel k(t, d, h);
      EXPECT_EQ(k.IsNormalized(), ExpectNormalized(t, d)) << Describe(k);
      if (ExpectNormalized(t, d))
      {
        EXPECT_NEAR(IntegralOverSpace(k), 1.0, 1e-6) << Describe(k);
      }
    }
  });
  // The quadrature can fail: kernels that are not normalised do not integrate to 1 (Viscosity 1D: the capped
  // 1/(2q) integrates to ~ log(1/kMinimumQ)).
  EXPECT_GT(std::fabs(IntegralOverSpace(Kernel(KernelType::InverseDistance, 2, 1.0)) - 1.0), 0.1);
  EXPECT_GT(std::fabs(IntegralOverSpace(Kernel(KernelType::Viscosity, 1, 1.0)) - 1.0), 0.1);
}

TEST(KernelNormalization, PublishedConstants)
{
  // sigma_d of the brief / thesis, W(0) = sigma_d / h^d (Lucy 3D with the pi the thesis drops).
  struct Case
  {
    KernelType type;
    double sigma[3];
  };
  const Case cases[] = {
    { KernelType::Wendland, { 3.0 / 2.0, 7.0 / kPi, 21.0 / (2.0 * kPi) } },
    { KernelType::Poly6, { 35.0 / 32.0, 4.0 / kPi, 315.0 / (64.0 * kPi) } },
    { KernelType::Lucy, { 5.0 / 4.0, 5.0 / kPi, 105.0 / (16.0 * kPi) } },
    { KernelType::W4, { 5.0 / 4.0, 5.0 / kPi, 105.0 / (16.0 * kPi) } },
    { KernelType::Spiky, { 2.0, 10.0 / kPi, 15.0 / kPi } },
    { KernelType::CubicSpline, { 4.0 / 3.0, 40.0 / (7.0 * kPi), 8.0 / kPi } },
    { KernelType::W3, { 4.0 / 3.0, 40.0 / (7.0 * kPi), 8.0 / kPi } },
    { KernelType::W5, { 4.0 / 3.0, 40.0 / (7.0 * kPi), 8.0 / kPi } },
  };
  for (const Case& c : cases)
    for (int d = 1; d <= 3; ++d)
    {
      const Kernel k(c.type, d, 1.7);
      EXPECT_NEAR(k.Value(0.0) * std::pow(1.7, d), c.sigma[d - 1], 1e-13) << Describe(k);
      EXPECT_NEAR(k.NormalizationFactor() * std::pow(1.7, d), c.sigma[d - 1], 1e-13) << Describe(k);
    }
  // Viscosity [5.47]: 15/(2 pi h^3) (-q^3/2 + q^2 + 1/(2q) - 1) in 3D, 10/(3 pi h^2) (...) in 2D.
  const double h = 0.8;
  for (double q : { 0.1, 0.25, 0.5, 0.9 })
  {
    const double f = -q * q * q / 2.0 + q * q + 1.0 / (2.0 * q) - 1.0;
    EXPECT_NEAR(Kernel(KernelType::Viscosity, 3, h).Value(q * h), 15.0 / (2.0 * kPi * h * h * h) * f, 1e-12);
    EXPECT_NEAR(Kernel(KernelType::Viscosity, 2, h).Value(q * h), 10.0 / (3.0 * kPi * h * h) * f, 1e-12);
  }
}

TEST(KernelFormulas, MuellerClosedForms)
{
  const double h = 1.3, h2 = h * h, h6 = h2 * h2 * h2, h9 = h6 * h2 * h;
  const Kernel poly6(KernelType::Poly6, 3, h), spiky(KernelType::Spiky, 3, h), visc(KernelType::Viscosity, 3, h);
  for (double q : { 0.0, 0.05, 0.3, 0.5, 0.77, 0.99 })
  {
    const double r = q * h, s = h2 - r * r;
    EXPECT_NEAR(poly6.Value(r), 315.0 / (64.0 * kPi * h9) * s * s * s, 1e-12);                    // [5.27]
    EXPECT_NEAR(poly6.RadialDerivative(r), -945.0 / (32.0 * kPi * h9) * r * s * s, 1e-12);        // sign fixed
    EXPECT_NEAR(poly6.Laplacian(r), 945.0 / (32.0 * kPi * h9) * s * (7 * r * r - 3 * h2), 1e-12); // sign fixed
    EXPECT_NEAR(spiky.Value(r), 15.0 / (kPi * h6) * std::pow(h - r, 3), 1e-12);                  // [5.41]
    EXPECT_NEAR(spiky.RadialDerivative(r), -45.0 / (kPi * h6) * (h - r) * (h - r), 1e-12);
    EXPECT_NEAR(visc.Laplacian(r), 45.0 / (kPi * h6) * (h - r), 1e-12); // [5.49], exact down to r = 0
    EXPECT_NEAR(meshfree::MuellerViscosityLaplacian(r, h), 45.0 / (kPi * h6) * (h - r), 1e-12);
  }
  EXPECT_EQ(meshfree::MuellerViscosityLaplacian(h, h), 0.0);
  EXPECT_EQ(meshfree::MuellerViscosityLaplacian(2 * h, h), 0.0);
}

TEST(KernelFormulas, ThesisShapesAndCoincidences)
{
  for (int d = 1; d <= 3; ++d)
  {
    const double h = 0.9;
    const Kernel w3(KernelType::W3, d, h), w4(KernelType::W4, d, h), w5(KernelType::W5, d, h);
    const Kernel cubic(KernelType::CubicSpline, d, h), lucy(KernelType::Lucy, d, h);
    const Kernel w2(KernelType::W2, d, h), gauss(KernelType::Gaussian, d, h);
    for (int i = 0; i < 200; ++i)
    {
      const double q = i / 200.0, r = q * h, s = 2 * q; // s: W5's own variable, support 2
      const double w3Thesis = q <= 0.5 ? 2.0 / 3.0 - 4 * q * q + 4 * q * q * q // [4.18]
                                       : 4.0 / 3.0 - 4 * q + 4 * q * q - 4.0 / 3.0 * q * q * q;
      const double w4Thesis = 1 - 6 * q * q + 8 * q * q * q - 3 * q * q * q * q; // [4.19]
      const double w5Thesis = s <= 1 ? 1 - 1.5 * s * s + 0.75 * s * s * s : 0.25 * std::pow(2 - s, 3); // [4.20]
      EXPECT_NEAR(w3.Value(r), w3.Value(0.0) * 1.5 * w3Thesis, 1e-12);
      EXPECT_NEAR(w4.Value(r), w4.Value(0.0) * w4Thesis, 1e-12);
      EXPECT_NEAR(w5.Value(r), w5.Value(0.0) * w5Thesis, 1e-12);
      EXPECT_DOUBLE_EQ(w4.Value(r), lucy.Value(r)); // W4 is Lucy's kernel
      EXPECT_DOUBLE_EQ(w3.Value(r), cubic.Value(r)); // W3, W5 are the cubic spline
      EXPECT_DOUBLE_EQ(w5.Value(r), cubic.Value(r));
      // W2 [4.17] exp(-(r/0.4h)^2) and the Gaussian exp(-(3q)^2), both shifted to vanish at h
      EXPECT_NEAR(w2.Value(r) / w2.Value(0.0),
        (std::exp(-std::pow(r / (0.4 * h), 2)) - std::exp(-6.25)) / (1 - std::exp(-6.25)), 1e-13);
      EXPECT_NEAR(gauss.Value(r) / gauss.Value(0.0),
        (std::exp(-9 * q * q) - std::exp(-9.0)) / (1 - std::exp(-9.0)), 1e-13);
    }
  }
}

//------------------------------------------------------------------------------
// Tolerances: the tests pass with 10x tighter ones; a 1e-6 relative error in a derivative fails them.
TEST(KernelDerivatives, RadialDerivativeAndGradientMatchFiniteDifferences)
{
  std::mt19937 rng(12345);
  for (const Kernel& k : DerivativeTestKernels())
  {
    const int d = k.Dimension();
    const double h = k.SupportRadius(), delta = 1e-5 * h;
    const std::vector<double> qs = SampleQ(k.Type(), 1e-3);
    double scale = 0.0;
    for (double q : qs)
      scale = std::max(scale, std::fabs(k.RadialDerivative(q * h)));
    for (double q : qs)
    {
      const double an = k.RadialDerivative(q * h);
      const double fd = FirstDifference([&](double s) { return k.Value(q * h + s); }, delta);
      EXPECT_NEAR(an, fd, 1e-7 * (std::fabs(an) + scale)) << Describe(k) << " q=" << q;
      double x[3], g[3];
      RandomPoint(rng, d, q * h, x);
      k.Gradient(x, g);
      for (int i = 0; i < 3; ++i)
      {
        const double fdi = i < d ? FirstDifference([&](double s) { return ValueAt(k, x, i, s); }, delta) : 0.0;
        EXPECT_NEAR(g[i], fdi, 1e-7 * (std::fabs(g[i]) + scale)) << Describe(k) << " q=" << q << " i=" << i;
      }
    }
  }
}

TEST(KernelDerivatives, LaplacianMatchesCartesianFiniteDifference)
{
  std::mt19937 rng(54321);
  for (const Kernel& k : DerivativeTestKernels())
  {
    const int d = k.Dimension();
    const double h = k.SupportRadius();
    // Near the centre the Cartesian stencil of a kernel singular at 0 (Viscosity ~ 1/q, Spiky's ~ 1/q
    // Laplacian) loses digits to large cancelling second derivatives; KernelFormulas checks the closed forms.
    const bool singular = k.Type() == KernelType::Viscosity || k.Type() == KernelType::Spiky;
    const std::vector<double> qs = SampleQ(k.Type(), 1e-2, singular ? 0.1 : 0.03);
    double scale = 0.0;
    for (double q : qs)
      scale = std::max(scale, std::fabs(k.Laplacian(q * h)));
    for (double q : qs)
    {
      double x[3];
      RandomPoint(rng, d, q * h, x);
      double fd = 0.0;
      for (int i = 0; i < d; ++i)
        fd += SecondDifference([&](double s) { return ValueAt(k, x, i, s); }, 3e-4 * h);
      const double an = k.Laplacian(q * h);
      EXPECT_NEAR(an, fd, 1e-6 * (std::fabs(an) + scale)) << Describe(k) << " q=" << q;
    }
  }
}

//------------------------------------------------------------------------------
TEST(KernelSupport, ZeroAtAndBeyondSupportAndContinuousThere)
{
  ForEachTypeAndDimension([](KernelType t, int d) {
    for (double h : { 1e-6, 0.25, 1.0, 3.0, 1e6 })
    {
      const Kernel k(t, d, h);
      for (double r : { h, std::nextafter(h, 2 * h), 1.0000001 * h, 1.5 * h, 10 * h, 1e300 })
      {
        double x[3] = { 0.0, 0.0, 0.0 }, g[3] = { 1, 1, 1 };
        x[d - 1] = r;
        k.Gradient(x, g);
        EXPECT_EQ(k.Value(r), 0.0) << Describe(k) << " r=" << r;
        EXPECT_EQ(k.ValueSquared(r * r), 0.0) << Describe(k) << " r=" << r;
        EXPECT_EQ(k.RadialDerivative(r), 0.0) << Describe(k) << " r=" << r;
        EXPECT_EQ(k.Laplacian(r), 0.0) << Describe(k) << " r=" << r;
        EXPECT_TRUE(g[0] == 0.0 && g[1] == 0.0 && g[2] == 0.0) << Describe(k) << " r=" << r;
      }
      // continuous at h: just inside, the value is tiny compared with the value half-way
      EXPECT_GT(k.Value(0.5 * h), 0.0);
      EXPECT_LT(k.Value((1 - 1e-6) * h), 1e-5 * k.Value(0.5 * h)) << Describe(k);
    }
  });
}

TEST(KernelSupport, ScaleInvariance)
{
  // W_h(q h), dW/dr and the Laplacian scale exactly as h^-d, h^-(d+1), h^-(d+2) (InverseDistance: h^0, h^-1,
  // h^-2; Viscosity 1D: prefactor 1/h).
  ForEachTypeAndDimension([](KernelType t, int d) {
    const Kernel ref(t, d, 1.0);
    for (double h : { 1e-6, 0.01, 7.0, 1e6 })
    {
      const Kernel k(t, d, h);
      const double s = t == KernelType::InverseDistance ? 1.0 : (k.IsNormalized() ? std::pow(h, d) : h);
      for (double q : { 0.0, 0.1, 0.3, 0.55, 0.8 })
      {
        EXPECT_NEAR(k.Value(q * h) * s, ref.Value(q), 1e-12 * std::fabs(ref.Value(q))) << Describe(k);
        EXPECT_NEAR(k.RadialDerivative(q * h) * s * h, ref.RadialDerivative(q),
          1e-12 * std::fabs(ref.RadialDerivative(q)))
          << Describe(k);
        EXPECT_NEAR(k.Laplacian(q * h) * s * h * h, ref.Laplacian(q), 1e-12 * std::fabs(ref.Laplacian(q)))
          << Describe(k);
      }
    }
  });
}

//------------------------------------------------------------------------------
TEST(KernelSymmetry, GradientIsRadialAndAntisymmetric)
{
  std::mt19937 rng(777);
  std::uniform_real_distribution<double> uq(0.02, 0.98);
  for (const Kernel& k : DerivativeTestKernels())
  {
    const int d = k.Dimension();
    for (int n = 0; n < 50; ++n)
    {
      const double r = uq(rng) * k.SupportRadius();
      double x[3], xm[3], other[3], g[3], gm[3];
      RandomPoint(rng, d, r, x);
      RandomPoint(rng, d, r, other);
      for (int i = 0; i < 3; ++i)
        xm[i] = -x[i];
      if (d < 3)
        x[2] = xm[2] = 0.3 * k.SupportRadius(); // components beyond Dimension() are ignored
      k.Gradient(x, g);
      k.Gradient(xm, gm);
      const double dWdr = k.RadialDerivative(r);
      for (int i = 0; i < 3; ++i)
      {
        EXPECT_EQ(g[i], -gm[i]) << Describe(k);
        EXPECT_NEAR(g[i], i < d ? dWdr * x[i] / r : 0.0, 1e-12 * std::fabs(dWdr)) << Describe(k) << " i=" << i;
      }
      // the value depends on |x| only
      EXPECT_NEAR(ValueAt(k, other), k.Value(r), 1e-12 * std::fabs(k.Value(r))) << Describe(k);
    }
  }
}

TEST(KernelShape, PositiveNonIncreasingAndValueSquaredAgrees)
{
  // Every kernel, including Viscosity ((1-q)^3 (1+q)/(2q) decreases) and W2 (continuous here).
  ForEachTypeAndDimension([](KernelType t, int d) {
    const Kernel k(t, d, 2.0);
    double previous = k.Value(0.0);
    EXPECT_GT(previous, 0.0);
    for (int i = 1; i < 5000; ++i)
    {
      const double r = 2.0 * i / 5000, w = k.Value(r);
      EXPECT_GT(w, 0.0) << Describe(k) << " r=" << r;
      EXPECT_LE(w, previous) << Describe(k) << " r=" << r;
      EXPECT_LE(k.RadialDerivative(r), 0.0) << Describe(k) << " r=" << r;
      EXPECT_NEAR(k.ValueSquared(r * r), w, 1e-13 * k.Value(0.2) + 1e-12 * w) << Describe(k) << " r=" << r;
      previous = w;
    }
  });
}

TEST(KernelRobustness, FiniteForEveryFiniteRadiusAndZeroGradientAtOrigin)
{
  ForEachTypeAndDimension([](KernelType t, int d) {
    for (double h : { 1e-6, 1.0, 1e6 })
    {
      const Kernel k(t, d, h);
      for (double r : { 0.0, 4.9e-324, 1e-300, 1e-160, 1e-12 * h, 1e-7 * h, 1e-6 * h, 0.5 * h, h, 1e300 })
      {
        EXPECT_TRUE(std::isfinite(k.Value(r))) << Describe(k) << " r=" << r;
        EXPECT_TRUE(std::isfinite(k.ValueSquared(r * r))) << Describe(k) << " r=" << r;
        EXPECT_TRUE(std::isfinite(k.RadialDerivative(r))) << Describe(k) << " r=" << r;
        EXPECT_TRUE(std::isfinite(k.Laplacian(r))) << Describe(k) << " r=" << r;
        for (int axis = 0; axis < d; ++axis)
        {
          double rv[3] = { 0, 0, 0 }, g[3];
          rv[axis] = r;
          k.Gradient(rv, g);
          EXPECT_TRUE(std::isfinite(g[0]) && std::isfinite(g[1]) && std::isfinite(g[2])) << Describe(k);
        }
      }
      const double zero[3] = { 0, 0, 0 };
      double g[3] = { 1, 1, 1 };
      k.Gradient(zero, g);
      EXPECT_TRUE(g[0] == 0.0 && g[1] == 0.0 && g[2] == 0.0) << Describe(k);
      if (t != KernelType::Spiky && t != KernelType::Viscosity) // (those are singular at 0, capped)
      {
        // smooth at 0: the Laplacian there is its limit, negative (a smooth maximum), not a cap
        const double l0 = k.Laplacian(0.0);
        EXPECT_NEAR(l0, k.Laplacian(1e-7 * h), 1e-6 * std::fabs(l0)) << Describe(k);
        EXPECT_LT(l0, 0.0) << Describe(k);
      }
    }
  });
}

//------------------------------------------------------------------------------
TEST(KernelInverseDistance, TaperedAndInterpolating)
{
  const double h = 2.0;
  for (double eps : { 1e-3, 1e-2, 0.5 })
  {
    const Kernel k(KernelType::InverseDistance, 2, h, eps);
    EXPECT_FALSE(k.IsNormalized());
    EXPECT_EQ(k.Epsilon(), eps);
    EXPECT_NEAR(k.Value(0.0), 1.0 / (eps * eps) - 1.0 / (1.0 + eps * eps), 1e-12 / (eps * eps));
    EXPECT_NEAR(k.Value(0.3 * h), 1.0 / (0.09 + eps * eps) - 1.0 / (1.0 + eps * eps), 1e-12);
  }
  // a smaller eps concentrates the weight at the centre (interpolating limit)
  double lastRatio = 0.0;
  for (double eps : { 0.5, 1e-1, 1e-2, 1e-3, 1e-4 })
  {
    const Kernel k(KernelType::InverseDistance, 3, h, eps);
    const double ratio = k.Value(0.0) / k.Value(0.1 * h);
    EXPECT_GT(ratio, lastRatio);
    lastRatio = ratio;
  }
  EXPECT_GT(lastRatio, 1e5);
  EXPECT_EQ(Kernel(KernelType::InverseDistance, 3, h).Epsilon(), 1e-3); // default
}

TEST(KernelViscosity, CapAndPositiveLaplacian)
{
  for (int d = 1; d <= 3; ++d)
  {
    const Kernel k(KernelType::Viscosity, d, 1.0);
    const double q = Kernel::kMinimumQ;
    EXPECT_EQ(k.Value(0.0), k.Value(q)); // flat below the cap
    EXPECT_EQ(k.Value(0.5 * q), k.Value(q));
    EXPECT_GT(k.Value(0.0), 1e5 * k.Value(0.5));
    for (int i = 0; i < 100; ++i) // Mueller's design: a positive Laplacian inside the support
      EXPECT_GT(k.Laplacian((i + 0.5) / 100.0), 0.0) << "d=" << d;
  }
  EXPECT_FALSE(Kernel(KernelType::Viscosity, 1, 1.0).IsNormalized());
  EXPECT_TRUE(Kernel(KernelType::Viscosity, 2, 1.0).IsNormalized());
}
