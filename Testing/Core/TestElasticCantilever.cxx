// Cantilever under self-weight, clamped by FixedBounds: static tip deflection against Euler-Bernoulli with the
// Timoshenko shear correction, and the first bending frequency (research/elastic.md 4.3, 4.4). The beam is the
// note's worked example made slender, L/h = 10 (L = 0.8, h = b = 0.08, rho = 1000, E = 1e4, nu = 0, g = 0.005:
// delta_tip = 0.048 m = 6 % of L, f1 = 0.064 Hz), 4 phyxels across. At L/h = 5 the same model is ~25 % too
// flexible: the compliance of the clamp's root region, which the beam formulas ignore, weighs 8x more there.
#include "Elastic/ElasticShapes.h"
#include "Elastic/ElasticSolid.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace meshfree;

namespace
{
constexpr double L = 0.8, H = 0.08, Rho = 1000.0, E = 1e4, G0 = 0.005, Spacing = 0.02;

// Beam [0, L] x [0, H] x [0, H] plus a clamp block [-H, 0] (pinned), phyxels at the lattice cell centres.
std::vector<double> BeamWithClamp()
{
  const double bounds[6] = { -H, L, 0.0, H, 0.0, H };
  std::vector<double> points;
  SampleLattice(bounds, Spacing, [](const double*) { return true; }, points);
  return points;
}

ElasticSettings BeamSettings(double damping, double alpha)
{
  ElasticSettings s;
  s.YoungModulus = E;
  s.PoissonRatio = 0.0;
  s.Density = Rho;
  s.VolumeStiffness = 0.0;
  s.HourglassStiffness = alpha;
  s.Gravity[0] = s.Gravity[1] = 0.0;
  s.Gravity[2] = -G0;
  s.Damping = damping;
  s.Contacts = false;
  const double fixed[6] = { -1.0, 0.0, -1.0, 1.0, -1.0, 1.0 };
  for (int a = 0; a < 6; ++a)
    s.FixedBounds[a] = fixed[a];
  return s;
}

// Mean z displacement of the free-end layer and its abscissa.
double TipDeflection(const ElasticSolid& solid, double& xTip)
{
  const auto& X = solid.RestPositions();
  const auto& x = solid.State().Position;
  xTip = 0.0;
  for (Index i = 0; i < solid.Size(); ++i)
    xTip = std::max(xTip, X[3 * i]);
  double sum = 0.0;
  int count = 0;
  for (Index i = 0; i < solid.Size(); ++i)
    if (X[3 * i] > xTip - 1e-9)
    {
      sum += x[3 * i + 2] - X[3 * i + 2];
      ++count;
    }
  return sum / count;
}

// Euler-Bernoulli deflection under a uniform load q at abscissa s, plus the Timoshenko shear term (kappa 5/6).
double ReferenceDeflection(double s)
{
  const double q = Rho * G0 * H * H, I = H * H * H * H / 12.0, Gs = E / 2.0, kappa = 5.0 / 6.0;
  const double bending = q * s * s * (6.0 * L * L - 4.0 * L * s + s * s) / (24.0 * E * I);
  const double shear = q * (L * s - 0.5 * s * s) / (kappa * Gs * H * H);
  return bending + shear;
}
} // namespace

TEST(ElasticCantilever, StaticTipDeflectionAndFirstFrequency)
{
  const auto rest = BeamWithClamp();
  ElasticSolid solid;
  std::string msg;
  ASSERT_TRUE(solid.Initialize(rest, (L + H) * H * H, BeamSettings(0.8, 0.05), msg)) << msg;
  ASSERT_EQ(solid.Size(), 44 * 4 * 4);

  // Static: dynamic relaxation (near-critical damping of the first mode, omega1 = 0.4 rad/s) for ~4 periods.
  ASSERT_TRUE(solid.Advance(60.0, 0.0, false));
  double xTip = 0.0;
  const double delta = -TipDeflection(solid, xTip);
  const double reference = ReferenceDeflection(xTip);
  std::printf("cantilever: tip deflection %.5f m at x = %.3f, Euler-Bernoulli + shear %.5f m (%+.1f %%)\n", delta,
    xTip, reference, 100.0 * (delta / reference - 1.0));
  EXPECT_NEAR(delta / reference, 1.0, 0.10);

  // Dynamic: switch gravity off and let the beam swing back, undamped; period from the zero crossings of the
  // tip deflection. Reference: f1 = (1.8751^2 / 2 pi) sqrt(EI / (rho A L^4)), lowered by the shear flexibility
  // (Rayleigh: f ~ 1/sqrt(static deflection)).
  ElasticSettings free = BeamSettings(0.0, 0.05);
  free.Gravity[2] = 0.0;
  ElasticSolid swing;
  ASSERT_TRUE(swing.Initialize(rest, (L + H) * H * H, free, msg)) << msg;
  swing.State().Position = solid.State().Position;
  const double dt = swing.StableTimeStep();
  double previous = -TipDeflection(swing, xTip), t = 0.0;
  std::vector<double> crossings;
  while (t < 40.0 && crossings.size() < 4)
  {
    swing.StepSymplectic(dt);
    t += dt;
    const double now = -TipDeflection(swing, xTip);
    if ((previous > 0.0) != (now > 0.0))
      crossings.push_back(t - dt * now / (now - previous)); // linear interpolation
    previous = now;
  }
  ASSERT_GE(crossings.size(), 4u);
  const double period = 2.0 * (crossings.back() - crossings.front()) / (crossings.size() - 1);
  const double I = H * H * H * H / 12.0, A = H * H;
  const double fEB = 1.8751 * 1.8751 / (2.0 * M_PI) * std::sqrt(E * I / (Rho * A * L * L * L * L));
  const double q = Rho * G0 * A;
  const double bendingOnly = q * L * L * L * L / (8.0 * E * I);
  const double fRef = fEB * std::sqrt(bendingOnly / ReferenceDeflection(L));
  std::printf("cantilever: first frequency %.4f Hz, reference %.4f Hz (Euler-Bernoulli %.4f) (%+.1f %%)\n",
    1.0 / period, fRef, fEB, 100.0 * (1.0 / period / fRef - 1.0));
  EXPECT_NEAR(1.0 / period / fRef, 1.0, 0.10);
}
