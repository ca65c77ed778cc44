// Core tests of the meshless elastic solid's other parts: Lennard-Jones contacts, the implicit integrator,
// plasticity, the embedded surface and the built-in shapes.
#include "Elastic/ElasticShapes.h"
#include "Elastic/ElasticSolid.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace meshfree;

namespace
{
std::vector<double> Cube(int n, double a, double x0)
{
  std::vector<double> p;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        p.insert(p.end(), { x0 + i * a, j * a, k * a });
  return p;
}

ElasticSettings Weightless()
{
  ElasticSettings s;
  s.Gravity[2] = 0.0;
  return s;
}

double Energy(const ElasticSolid& solid)
{
  const auto& st = solid.State();
  double e = solid.InternalEnergy(st.Position.data());
  for (Index i = 0; i < solid.Size(); ++i)
    for (int a = 0; a < 3; ++a)
      e += 0.5 * solid.Masses()[i] * st.Velocity[3 * i + a] * st.Velocity[3 * i + a];
  return e;
}
} // namespace

// Two cubes thrown at each other: the Lennard-Jones repulsion [4.26] stops them before they interpenetrate,
// they separate again, and the pair forces are equal and opposite (momentum conserved).
TEST(ElasticFeatures, ContactsRepelAndConserveMomentum)
{
  const double a = 0.02;
  std::vector<double> rest = Cube(4, a, 0.0);
  const std::vector<double> right = Cube(4, a, 3 * a + 0.06);
  rest.insert(rest.end(), right.begin(), right.end());
  ElasticSolid solid;
  std::string msg;
  ASSERT_TRUE(solid.Initialize(rest, 0.0, Weightless(), msg)) << msg;
  const Index half = solid.Size() / 2;
  auto& v = solid.State().Velocity;
  for (Index i = 0; i < solid.Size(); ++i)
    v[3 * i] = i < half ? 1.0 : -1.0;
  double closest = 1e9;
  const double dt = solid.StableTimeStep();
  for (double t = 0.0; t < 0.12; t += dt)
  {
    solid.StepSymplectic(dt);
    const auto& x = solid.State().Position;
    for (Index i = 0; i < half; ++i)
      for (Index j = half; j < solid.Size(); ++j)
        closest = std::min(closest, std::hypot(x[3 * i] - x[3 * j], x[3 * i + 1] - x[3 * j + 1], x[3 * i + 2] - x[3 * j + 2]));
  }
  double p = 0.0, scale = 0.0, vLeft = 0.0;
  for (Index i = 0; i < solid.Size(); ++i)
  {
    p += solid.Masses()[i] * v[3 * i];
    scale += solid.Masses()[i] * std::fabs(v[3 * i]);
    if (i < half)
      vLeft += v[3 * i] / half;
  }
  EXPECT_GT(closest, 0.7 * a);
  EXPECT_LT(std::fabs(p), 1e-10 * scale);
  EXPECT_LT(vLeft, 0.0); // bounced back
}

// Backward Euler at 20x the explicit limit: finite, and the energy of a released stretched bar decays
// monotonically; symplectic Euler at that step explodes.
TEST(ElasticFeatures, ImplicitIsStableFarAboveTheExplicitLimit)
{
  std::vector<double> rest;
  const double bounds[6] = { 0, 0.2, 0, 0.06, 0, 0.06 };
  SampleLattice(bounds, 0.02, [](const double*) { return true; }, rest);
  for (int implicit : { 1, 0 })
  {
    ElasticSolid solid;
    std::string msg;
    ASSERT_TRUE(solid.Initialize(rest, 0.0, Weightless(), msg)) << msg;
    for (size_t c = 0; c < rest.size(); ++c)
      solid.State().Position[c] = rest[c] * (c % 3 == 0 ? 1.05 : 1.0);
    const double dt = 20.0 * solid.StableTimeStep();
    double previous = Energy(solid);
    const double e0 = previous;
    bool monotone = true;
    for (int s = 0; s < 30; ++s)
    {
      if (implicit)
      {
        double residual = 0.0;
        const int it = solid.StepImplicit(dt, residual);
        EXPECT_LE(residual, 1e-6) << "CG iterations " << it;
      }
      else
        solid.StepSymplectic(dt);
      const double e = Energy(solid);
      monotone = monotone && e <= previous * (1.0 + 1e-9);
      previous = e;
    }
    if (implicit)
    {
      EXPECT_TRUE(monotone);
      EXPECT_LT(previous, 0.5 * e0);
      std::printf("implicit: energy %.3g -> %.3g in 30 steps of %.3g s, %ld CG iterations\n", e0, previous, dt,
        solid.CGIterations());
    }
    else
      EXPECT_TRUE(!std::isfinite(previous) || previous > 100.0 * e0);
  }
}

// Mueller 2004 plasticity: strain beyond the yield creeps into plastic strain and stays after unloading,
// bounded by the maximum; an elastic body returns to rest shape.
TEST(ElasticFeatures, PlasticityLeavesBoundedResidualStrain)
{
  std::vector<double> rest;
  const double bounds[6] = { 0, 0.16, 0, 0.06, 0, 0.06 };
  SampleLattice(bounds, 0.02, [](const double*) { return true; }, rest);
  double residual[2];
  for (int plastic : { 0, 1 })
  {
    ElasticSettings s = Weightless();
    s.Damping = 100.0;
    if (plastic)
    {
      s.PlasticYield = 0.01;
      s.PlasticCreep = 20.0;
      s.PlasticMaxStrain = 0.03;
    }
    ElasticSolid solid;
    std::string msg;
    ASSERT_TRUE(solid.Initialize(rest, 0.0, s, msg)) << msg;
    auto& ext = solid.ExternalForce();
    ext.assign(3 * solid.Size(), 0.0);
    int ends = 0;
    for (Index i = 0; i < solid.Size(); ++i)
      ends += (rest[3 * i] < 0.01 || rest[3 * i] > 0.15) ? 1 : 0;
    const double force = 0.06 * s.YoungModulus * 0.06 * 0.06 / (ends / 2); // ~6 % strain
    for (Index i = 0; i < solid.Size(); ++i)
      ext[3 * i] = rest[3 * i] < 0.01 ? -force : (rest[3 * i] > 0.15 ? force : 0.0);
    solid.Advance(0.3, 0.0, false);
    ext.assign(3 * solid.Size(), 0.0); // unload
    solid.Advance(0.3, 0.0, false);
    std::vector<double> F, strain, stress, det;
    solid.ComputeDeformation(F, strain, stress, det);
    double mean = 0.0;
    for (Index i = 0; i < solid.Size(); ++i)
      mean += strain[6 * i] / solid.Size();
    residual[plastic] = mean;
    if (plastic)
    {
      double largest = 0.0;
      for (size_t c = 0; c < solid.State().PlasticStrain.size(); c += 6)
        largest = std::max(largest, std::fabs(solid.State().PlasticStrain[c]));
      EXPECT_LE(largest, 0.03 + 1e-12);
    }
  }
  std::printf("residual axial strain after unloading: elastic %.2e, plastic %.2e\n", residual[0], residual[1]);
  EXPECT_LT(std::fabs(residual[0]), 1e-3);
  EXPECT_GT(residual[1], 0.005);
  EXPECT_LT(residual[1], 0.03 + 1e-3);
}

// The embedded surface follows affine motions of the phyxels exactly [4.43-4.44].
TEST(ElasticFeatures, SurfaceFollowsAffineMotionExactly)
{
  const double bounds[6] = { -0.2, 0.2, -0.08, 0.08, 0.3, 0.46 };
  std::vector<double> rest, surface;
  std::vector<Index> triangles;
  SampleLattice(bounds, 0.0196, [&](const double* p) { return InsideShape(ElasticShape::Ellipsoid, bounds, p); },
    rest);
  ShapeSurface(ElasticShape::Ellipsoid, bounds, 38, surface, triangles);
  EXPECT_EQ(rest.size() / 3, 720u);
  EXPECT_EQ(surface.size() / 3, 990u);
  EXPECT_EQ(triangles.size() / 3, 1976u);
  EXPECT_NEAR(MeshVolume(surface, triangles) / ShapeVolume(ElasticShape::Ellipsoid, bounds), 1.0, 0.02);
  ElasticSolid solid;
  std::string msg;
  ASSERT_TRUE(solid.Initialize(rest, ShapeVolume(ElasticShape::Ellipsoid, bounds), Weightless(), msg)) << msg;
  ElasticSurface embedded;
  embedded.Bind(solid, surface);
  const double G[9] = { 1.1, 0.2, 0.0, -0.1, 0.9, 0.3, 0.05, 0.0, 1.2 }, t[3] = { 0.1, 0.2, -0.3 };
  auto map = [&](const double* X, double* x) {
    for (int a = 0; a < 3; ++a)
      x[a] = G[a * 3] * X[0] + G[a * 3 + 1] * X[1] + G[a * 3 + 2] * X[2] + t[a];
  };
  for (Index i = 0; i < solid.Size(); ++i)
    map(&rest[3 * i], &solid.State().Position[3 * i]);
  std::vector<double> F, strain, stress, det, points, displacement;
  solid.ComputeDeformation(F, strain, stress, det);
  embedded.Deform(solid, F, points, displacement);
  double worst = 0.0;
  for (size_t v = 0; v < surface.size() / 3; ++v)
  {
    double expected[3];
    map(&surface[3 * v], expected);
    for (int a = 0; a < 3; ++a)
      worst = std::max(worst, std::fabs(points[3 * v + a] - expected[a]));
  }
  EXPECT_LT(worst, 1e-10);
  // Inside test of a closed mesh: the lattice points of the ellipsoid are inside its surface.
  std::vector<char> inside;
  InsideMesh(surface, triangles, rest, inside);
  size_t count = 0;
  for (char c : inside)
    count += c ? 1 : 0;
  EXPECT_GE(count, rest.size() / 3 * 95 / 100);
}
