// Stress: SPH Fluid (vtkMeshFreeSPHFluid) under long runs (energy bounded, nothing leaves the container),
// stiff gases and oversized time steps, offsets and scales, degenerate bounds and spacings, hostile obstacle
// inputs, hostile parameters and time requests. Each case: no crash, no NaN/Inf in the output, the expected
// message, a defined result.
#include "StressCommon.h"

#include "vtkMeshFreeSPHFluid.h"

#include <algorithm>
#include <functional>

using namespace stress;

namespace
{
vtkPolyData* At(vtkMeshFreeSPHFluid* f, double t)
{
  f->UpdateTimeStep(t);
  return f->GetOutput();
}

vtkNew<vtkMeshFreeSPHFluid> Make(int dim)
{
  vtkNew<vtkMeshFreeSPHFluid> f;
  f->SetDimension(dim);
  f->SetFluidBounds(0, 0.2, 0, 0.2, 0, 0.4);
  f->SetDomainBounds(0, 0.8, 0, 0.2, 0, 0.5);
  f->SetParticleSpacing(dim == 2 ? 0.02 : 0.04);
  f->SetEndTime(0.1);
  f->SetOutputInterval(0.05);
  return f;
}

// Kinetic plus gravitational energy per unit particle mass (all particles have the same mass).
double SpecificEnergy(vtkPolyData* p, const double g[3])
{
  vtkDataArray* velocity = p->GetPointData()->GetArray("Velocity");
  if (!velocity)
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  double e = 0.0;
  for (vtkIdType i = 0; i < p->GetNumberOfPoints(); ++i)
  {
    double x[3], v[3];
    p->GetPoint(i, x);
    velocity->GetTuple(i, v);
    e += 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) - (g[0] * x[0] + g[1] * x[1] + g[2] * x[2]);
  }
  return e;
}

bool Inside(vtkPolyData* p, const double b[6], int dim, double tol)
{
  for (vtkIdType i = 0; i < p->GetNumberOfPoints(); ++i)
  {
    double x[3];
    p->GetPoint(i, x);
    for (int a = 0; a < 3; ++a)
    {
      if (dim == 2 && a == 1)
      {
        continue; // 2D lives in the x-z plane
      }
      if (x[a] < b[2 * a] - tol || x[a] > b[2 * a + 1] + tol)
      {
        return false;
      }
    }
  }
  return true;
}
}

int StressSPHFluid(int, char*[])
{
  Suite suite;
  Window();
  const double g[3] = { 0, 0, -9.81 };

  // 1. Long runs: a dam break in 2D and 3D, and a sideways-thrown block; energy bounded, nothing leaves,
  // no particle lost, Id stable.
  for (int dim = 2; dim <= 3; ++dim)
  {
    for (int kernels = 0; kernels <= 2; ++kernels)
    {
      const std::string name = "long dam break, dimension " + std::to_string(dim) + " KernelPair " + std::to_string(kernels);
      suite.Begin(name);
      auto f = Make(dim);
      f->SetKernelPair(kernels);
      f->SetEndTime(dim == 2 ? 2.0 : 1.0);
      f->SetOutputInterval(0.25);
      vtkNew<vtkPolyData> p0;
      p0->DeepCopy(At(f, 0.0));
      const vtkIdType n = p0->GetNumberOfPoints();
      if (!suite.Check(n > 50, "too few particles at t = 0"))
      {
        continue;
      }
      const double e0 = SpecificEnergy(p0, g);
      const double scale = n * 9.81 * 0.5; // g * domain height per unit mass, all particles
      double b[6];
      f->GetDomainBounds(b);
      const int outputs = dim == 2 ? 8 : 4;
      for (int k = 1; k <= outputs; ++k)
      {
        const double t = 0.25 * k;
        vtkPolyData* p = At(f, t);
        if (!suite.Check(p->GetNumberOfPoints() == n, "particles lost at t = " + Str(t)))
        {
          break;
        }
        CheckFinite(suite, p);
        const double e = SpecificEnergy(p, g);
        // The 'Mueller' pair (poly6 density, spiky pressure gradient) is documented as not conservative:
        // it warns instead (checked below); the others must not create energy.
        if (kernels != 2 && !suite.Check(e <= e0 + 0.02 * scale,
              "energy grew from " + Str(e0) + " to " + Str(e) + " at t = " + Str(t)))
        {
          break;
        }
        if (!suite.Check(Inside(p, b, dim, 1e-9), "a particle left the container at t = " + Str(t)))
        {
          break;
        }
        vtkDataArray* ids = p->GetPointData()->GetArray("Id");
        suite.Check(ids && ids->GetRange(0)[0] == 0 && ids->GetRange(0)[1] == n - 1, "Id not 0..n-1");
      }
      suite.ExpectNoError();
      if (kernels == 2)
      {
        suite.ExpectWarning("conserve energy");
      }
    }
  }

  // 2. Stiff gases and oversized steps: reduced with a warning (fixed steps) or adaptive (CFL), finite.
  for (double stiffness : { 0.0, 1e9 })
  {
    for (double cfl : { 0.0, 0.25, 10.0 })
    {
      const std::string name = "GasStiffness " + Str(stiffness) + " TimeStep 1 CFLNumber " + Str(cfl);
      suite.Begin(name);
      auto f = Make(2);
      f->SetGasStiffness(stiffness);
      f->SetTimeStep(1.0);
      f->SetCFLNumber(cfl);
      f->SetEndTime(stiffness > 0 ? 0.002 : 0.1);
      f->SetOutputInterval(stiffness > 0 ? 0.001 : 0.05);
      vtkPolyData* p = At(f, stiffness > 0 ? 0.002 : 0.1);
      CheckFinite(suite, p);
      suite.ExpectNoError();
      double b[6];
      f->GetDomainBounds(b);
      suite.Check(p->GetNumberOfPoints() > 0 && Inside(p, b, 2, 1e-9), "particles lost or outside");
      if (cfl == 0.0 || cfl > 1.0)
      {
        // A fixed step of 1 s (or a CFL number far above 1) is far beyond the stability limit.
        suite.ExpectWarning("TimeStep");
      }
    }
  }
  {
    // The viscous step limit (~ rho h^2 / mu = 1e-6 s here) makes this slow: a short run.
    suite.Begin("Viscosity 1e6 (explicit viscous limit)");
    auto f = Make(2);
    f->SetViscosity(1e6);
    f->SetEndTime(0.001);
    f->SetOutputInterval(0.0005);
    vtkPolyData* p = At(f, 0.001);
    CheckFinite(suite, p);
    suite.ExpectNoError();
    suite.Check(p->GetNumberOfPoints() > 0, "no particles");
  }
  {
    suite.Begin("SurfaceTension 1e6");
    auto f = Make(2);
    f->SetSurfaceTension(1e6);
    vtkPolyData* p = At(f, 0.1);
    CheckFinite(suite, p);
    suite.ExpectNoError();
    double b[6];
    f->GetDomainBounds(b);
    suite.Check(p->GetNumberOfPoints() > 0 && Inside(p, b, 2, 1e-9), "particles lost or outside");
  }
  {
    suite.Begin("Gravity 1e6 sideways");
    auto f = Make(2);
    f->SetGravity(1e6, 0, -1e6);
    f->SetEndTime(0.01);
    f->SetOutputInterval(0.005);
    vtkPolyData* p = At(f, 0.01);
    CheckFinite(suite, p);
    suite.ExpectNoError();
    double b[6];
    f->GetDomainBounds(b);
    suite.Check(p->GetNumberOfPoints() > 0 && Inside(p, b, 2, 1e-9), "particles lost or outside");
  }

  // 3. Offsets and scales of the whole scene.
  {
    suite.Begin("scene offset by 1e6");
    auto a = Make(2);
    auto f = Make(2);
    const double o = 1e6;
    f->SetFluidBounds(o, o + 0.2, o, o + 0.2, o, o + 0.4);
    f->SetDomainBounds(o, o + 0.8, o, o + 0.2, o, o + 0.5);
    vtkNew<vtkPolyData> pa;
    pa->DeepCopy(At(a, 0.1));
    vtkPolyData* p = At(f, 0.1);
    CheckFinite(suite, p);
    suite.ExpectNoError();
    double b[6];
    f->GetDomainBounds(b);
    suite.Check(p->GetNumberOfPoints() == pa->GetNumberOfPoints() && Inside(p, b, 2, 1e-9),
      "the offset scene lost particles or let them out");
    // The same flow, translated: compare the mean height (chaotic particle paths differ in detail).
    double za = 0, z = 0;
    for (vtkIdType i = 0; i < p->GetNumberOfPoints() && i < pa->GetNumberOfPoints(); ++i)
    {
      za += pa->GetPoint(i)[2];
      z += p->GetPoint(i)[2] - o;
    }
    const double n = std::max<vtkIdType>(1, p->GetNumberOfPoints());
    suite.Check(std::abs(za - z) / n < 0.01, "the offset scene flows differently: mean height differs by " +
        Str(std::abs(za - z) / n));
  }
  for (double scale : { 1e-6, 1e6 })
  {
    suite.Begin("scene scaled by " + Str(scale));
    auto f = Make(2);
    f->SetFluidBounds(0, 0.2 * scale, 0, 0.2 * scale, 0, 0.4 * scale);
    f->SetDomainBounds(0, 0.8 * scale, 0, 0.2 * scale, 0, 0.5 * scale);
    f->SetParticleSpacing(0.02 * scale);
    f->SetEndTime(scale < 1 ? 1e-4 : 1.0);
    f->SetOutputInterval(scale < 1 ? 1e-4 : 1.0);
    vtkPolyData* p = At(f, scale < 1 ? 1e-4 : 1.0);
    CheckFinite(suite, p);
    double b[6];
    f->GetDomainBounds(b);
    if (scale < 1 && Window()->Errors > 0)
    {
      // Water at 1e-6 m: the stable step collapses (~1e-11 s); refusing with a clear error is defined.
      suite.ExpectError("time step");
      suite.Check(p->GetNumberOfPoints() == 0, "an error, but particles are output");
    }
    else
    {
      suite.ExpectNoError();
      suite.Check(p->GetNumberOfPoints() > 0 && Inside(p, b, 2, 1e-9 * scale), "particles lost or outside");
    }
  }

  // 4. Degenerate geometry and hostile parameters: refused with an error (empty output) or corrected with a
  // warning naming the parameter.
  struct Case
  {
    const char* Name;
    const char* Word;
    std::function<void(vtkMeshFreeSPHFluid*)> Apply;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<Case> cases = {
    { "ParticleSpacing 0", "ParticleSpacing", [](vtkMeshFreeSPHFluid* f) { f->SetParticleSpacing(0.0); } },
    { "ParticleSpacing NaN", "ParticleSpacing", [nan](vtkMeshFreeSPHFluid* f) { f->SetParticleSpacing(nan); } },
    { "ParticleSpacing 1e-7 (too many particles)", "ParticleSpacing",
      [](vtkMeshFreeSPHFluid* f) { f->SetParticleSpacing(1e-7); } },
    { "ParticleSpacing 10 (no particle)", "particle", [](vtkMeshFreeSPHFluid* f) { f->SetParticleSpacing(10.0); } },
    { "SmoothingLength NaN", "SmoothingLength", [nan](vtkMeshFreeSPHFluid* f) { f->SetSmoothingLength(nan); } },
    { "SmoothingLength 1e-9", "SmoothingLength", [](vtkMeshFreeSPHFluid* f) { f->SetSmoothingLength(1e-9); } },
    { "SmoothingLength 100", "SmoothingLength", [](vtkMeshFreeSPHFluid* f) { f->SetSmoothingLength(100.0); } },
    { "RestDensity 0", "RestDensity", [](vtkMeshFreeSPHFluid* f) { f->SetRestDensity(0.0); } },
    { "RestDensity Inf", "RestDensity", [inf](vtkMeshFreeSPHFluid* f) { f->SetRestDensity(inf); } },
    { "GasStiffness NaN", "GasStiffness", [nan](vtkMeshFreeSPHFluid* f) { f->SetGasStiffness(nan); } },
    { "Viscosity -1", "Viscosity", [](vtkMeshFreeSPHFluid* f) { f->SetViscosity(-1.0); } },
    { "SurfaceTension NaN", "SurfaceTension", [nan](vtkMeshFreeSPHFluid* f) { f->SetSurfaceTension(nan); } },
    { "Gravity NaN", "Gravity", [nan](vtkMeshFreeSPHFluid* f) { f->SetGravity(0, nan, -9.81); } },
    { "TimeStep 0", "TimeStep", [](vtkMeshFreeSPHFluid* f) { f->SetTimeStep(0.0); } },
    { "TimeStep NaN", "TimeStep", [nan](vtkMeshFreeSPHFluid* f) { f->SetTimeStep(nan); } },
    { "CFLNumber NaN", "CFLNumber", [nan](vtkMeshFreeSPHFluid* f) { f->SetCFLNumber(nan); } },
    { "EndTime NaN", "EndTime", [nan](vtkMeshFreeSPHFluid* f) { f->SetEndTime(nan); } },
    { "OutputInterval 0", "OutputInterval", [](vtkMeshFreeSPHFluid* f) { f->SetOutputInterval(0.0); } },
    { "OutputInterval Inf", "OutputInterval", [inf](vtkMeshFreeSPHFluid* f) { f->SetOutputInterval(inf); } },
    { "FluidBounds empty (x0 == x1)", "FluidBounds",
      [](vtkMeshFreeSPHFluid* f) { f->SetFluidBounds(0.1, 0.1, 0, 0.2, 0, 0.4); } },
    { "FluidBounds inverted", "FluidBounds",
      [](vtkMeshFreeSPHFluid* f) { f->SetFluidBounds(0.2, 0, 0.2, 0, 0.4, 0); } },
    { "FluidBounds NaN", "FluidBounds",
      [nan](vtkMeshFreeSPHFluid* f) { f->SetFluidBounds(0, nan, 0, 0.2, 0, 0.4); } },
    { "FluidBounds outside DomainBounds", "FluidBounds",
      [](vtkMeshFreeSPHFluid* f) { f->SetFluidBounds(5, 6, 5, 6, 5, 6); } },
    { "DomainBounds empty", "DomainBounds",
      [](vtkMeshFreeSPHFluid* f) { f->SetDomainBounds(0, 0, 0, 0, 0, 0); } },
    { "DomainBounds Inf", "DomainBounds",
      [inf](vtkMeshFreeSPHFluid* f) { f->SetDomainBounds(-inf, inf, 0, 0.2, 0, 0.5); } },
  };
  for (const Case& c : cases)
  {
    suite.Begin(std::string("parameter ") + c.Name);
    auto f = Make(2);
    c.Apply(f);
    f->UpdateInformation();
    vtkPolyData* p = At(f, 0.05);
    CheckFinite(suite, p);
    suite.ExpectMessage(c.Word);
    if (Window()->Errors > 0)
    {
      suite.Check(p->GetNumberOfPoints() == 0, "an error, but particles are output");
    }
    // Without an error, either particles or (ParticleSpacing 10) an empty fluid with a warning naming it.
  }

  // 5. Hostile obstacles: empty, NaN vertices, collinear (degenerate) triangles, huge offset.
  for (int damage = 0; damage <= 3; ++damage)
  {
    const char* names[] = { "empty obstacle", "obstacle with NaN vertices", "degenerate triangles",
      "obstacle far away (1e6)" };
    suite.Begin(names[damage]);
    auto f = Make(2);
    vtkNew<vtkPolyData> obstacle;
    if (damage > 0)
    {
      vtkNew<vtkPoints> pts;
      pts->SetDataTypeToDouble();
      const double o = damage == 3 ? 1e6 : 0.0;
      pts->InsertNextPoint(o + 0.4, -0.1, 0.0);
      pts->InsertNextPoint(o + 0.5, -0.1, 0.0);
      pts->InsertNextPoint(o + 0.45, -0.1, damage == 2 ? 0.0 : 0.2);
      pts->InsertNextPoint(o + 0.45, 0.3, damage == 1 ? nan : 0.1);
      vtkNew<vtkCellArray> tris;
      const vtkIdType t[4][3] = { { 0, 1, 2 }, { 0, 1, 3 }, { 1, 2, 3 }, { 0, 2, 3 } };
      for (const auto& tri : t)
      {
        tris->InsertNextCell(3, tri);
      }
      obstacle->SetPoints(pts);
      obstacle->SetPolys(tris);
    }
    f->SetInputData(obstacle);
    vtkPolyData* p = At(f, 0.1);
    CheckFinite(suite, p);
    suite.ExpectNoError();
    double b[6];
    f->GetDomainBounds(b);
    suite.Check(p->GetNumberOfPoints() > 0 && Inside(p, b, 2, 1e-9), "particles lost or outside");
    if (damage == 1)
    {
      suite.ExpectWarning("NaN");
    }
  }

  // 6. Hostile time requests: before 0, after EndTime, NaN: the nearest output time.
  for (double t : { -5.0, 1e9, nan })
  {
    suite.Begin("time request " + Str(t));
    auto f = Make(2);
    vtkPolyData* p = At(f, t);
    CheckFinite(suite, p);
    suite.ExpectNoError();
    suite.Check(p->GetNumberOfPoints() > 0, "no particles for an out-of-range time");
  }
  return suite.Finish("StressSPHFluid");
}
