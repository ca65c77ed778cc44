// Shared by the SPH back-end tests (Cuda/CudaSPH*.cxx, CudaNoDevice.cxx): dam-break scenes, a bitwise comparison
// of two states, the device check that makes a GPU test skip and the count of failed checks.
#ifndef MeshFree_Testing_SPHBackendSupport_h
#define MeshFree_Testing_SPHBackendSupport_h

#include "SPH/SPHFluid.h"
#include "cuda/Device.h"

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace sphtest
{

/// A dam break with walls: a block of water in the corner of a tank, spacing dx, viscosity, surface tension and
/// artificial viscosity on (every term of the acceleration), fixed step `dt` (CFLNumber 0) unless dt = 0.
inline meshfree::SPHParameters DamBreak(int dimension, double dx, bool tait, double dt)
{
  meshfree::SPHParameters p;
  p.Dimension = dimension;
  p.ParticleSpacing = dx;
  p.Viscosity = 1e-3;
  p.SurfaceTension = 0.0728;
  p.ArtificialViscosity = 0.02;
  p.EquationOfState = tait ? meshfree::SPHEquationOfState::Tait : meshfree::SPHEquationOfState::Ideal;
  const double fluid[6] = { 0.0, 0.1, 0.0, dimension == 2 ? 0.0 : 0.06, 0.0, 0.15 };
  const double domain[6] = { 0.0, 0.3, 0.0, dimension == 2 ? 0.0 : 0.06, 0.0, 0.2 };
  for (int a = 0; a < 6; ++a)
  {
    p.FluidBounds[a] = fluid[a];
    p.DomainBounds[a] = domain[a];
  }
  if (dt > 0.0)
  {
    p.TimeStep = dt;
    p.CFLNumber = 0.0;
  }
  return p;
}

template <class T>
bool SameBits(const std::vector<T>& a, const std::vector<T>& b)
{
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), sizeof(T) * a.size()) == 0);
}

/// Whether two states are equal bit for bit; prints what differs (with `what`).
inline bool SameState(const meshfree::SPHState& a, const meshfree::SPHState& b, const std::string& what)
{
  bool same = true;
  auto check = [&](bool ok, const char* field) {
    if (!ok)
    {
      std::printf("%s: %s differs\n", what.c_str(), field);
      same = false;
    }
  };
  check(std::memcmp(&a.Time, &b.Time, sizeof(double)) == 0, "Time");
  check(a.Steps == b.Steps, "Steps");
  check(SameBits(a.Position, b.Position), "Position");
  check(SameBits(a.Velocity, b.Velocity), "Velocity");
  check(SameBits(a.Acceleration, b.Acceleration), "Acceleration");
  check(SameBits(a.Density, b.Density), "Density");
  check(SameBits(a.Pressure, b.Pressure), "Pressure");
  check(SameBits(a.Id, b.Id), "Id");
  return same;
}

/// Whether a usable CUDA device is present (its name printed); otherwise prints "SKIPPED: <reason>" and the GPU
/// test returns 77 (ctest's SKIP_RETURN_CODE).
inline bool DevicePresent()
{
  std::string reason;
  if (!meshfree::cuda::Available(&reason))
  {
    std::printf("SKIPPED: %s\n", reason.c_str());
    return false;
  }
  std::printf("device: %s\n", meshfree::cuda::DeviceName().c_str());
  return true;
}

/// The checks of a test program: Check(ok, what) prints each failure; Exit() is the program's exit status.
struct Checks
{
  int Failures = 0;
  void operator()(bool ok, const std::string& what)
  {
    if (!ok)
    {
      std::printf("FAILED: %s\n", what.c_str());
      ++this->Failures;
    }
  }
  int Exit() const
  {
    std::printf(this->Failures == 0 ? "OK\n" : "%d FAILURES\n", this->Failures);
    return this->Failures == 0 ? 0 : 1;
  }
};

} // namespace sphtest

#endif
