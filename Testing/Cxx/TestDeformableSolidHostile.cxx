// MLS Deformable Solid under hostile settings: E <= 0, nu >= 0.5, zero phyxels, coplanar phyxels, huge time
// steps. Each gives a clear message and a defined, finite result.
#include "vtkMeshFreeDeformableSolid.h"

#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkInformation.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkPoints.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkTestErrorObserver.h"

#include <cmath>
#include <iostream>
#include <string>

namespace
{
int failures = 0;
void Check(bool ok, const std::string& what)
{
  if (!ok)
  {
    std::cout << "ERROR: " << what << std::endl;
    ++failures;
  }
}

vtkPolyData* Phyxels(vtkMeshFreeDeformableSolid* s, double t)
{
  s->UpdateTimeStep(t);
  auto* mb = vtkMultiBlockDataSet::SafeDownCast(s->GetOutputDataObject(0));
  return mb ? vtkPolyData::SafeDownCast(mb->GetBlock(0)) : nullptr;
}

bool AllFinite(vtkPolyData* p)
{
  for (vtkIdType i = 0; i < p->GetNumberOfPoints(); ++i)
  {
    double x[3];
    p->GetPoint(i, x);
    if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
      return false;
  }
  for (int a = 0; a < p->GetPointData()->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* array = p->GetPointData()->GetArray(a);
    for (vtkIdType i = 0; array && i < array->GetNumberOfTuples(); ++i)
      for (int c = 0; c < array->GetNumberOfComponents(); ++c)
        if (!std::isfinite(array->GetComponent(i, c)))
          return false;
  }
  return true;
}

// An invalid setting: an error naming the problem, and an empty but well-formed "Phyxels" block.
void ExpectRefused(vtkMeshFreeDeformableSolid* s, const std::string& word, const std::string& what)
{
  vtkNew<vtkTest::ErrorObserver> observer;
  s->AddObserver(vtkCommand::ErrorEvent, observer);
  s->AddObserver(vtkCommand::WarningEvent, observer);
  vtkPolyData* p = Phyxels(s, 0.1);
  Check(observer->GetError(), what + ": no error reported");
  Check(observer->GetErrorMessage().find(word) != std::string::npos,
    what + ": the message does not mention " + word + ": " + observer->GetErrorMessage());
  Check(p && p->GetNumberOfPoints() == 0, what + ": the output is not an empty Phyxels block");
  s->RemoveAllObservers();
}

vtkNew<vtkMeshFreeDeformableSolid> Make()
{
  vtkNew<vtkMeshFreeDeformableSolid> s;
  s->SetEndTime(0.2);
  s->SetOutputInterval(0.1);
  s->SetPhyxelSpacing(0.05);
  return s;
}
} // namespace

int TestDeformableSolidHostile(int, char*[])
{
  {
    auto s = Make();
    s->SetYoungModulus(0.0);
    ExpectRefused(s, "YoungModulus", "E = 0");
    s->SetYoungModulus(-1e5);
    ExpectRefused(s, "YoungModulus", "E < 0");
    s->SetYoungModulus(1e5);
    s->SetPoissonRatio(0.5);
    ExpectRefused(s, "PoissonRatio", "nu = 0.5");
    s->SetPoissonRatio(0.7);
    ExpectRefused(s, "PoissonRatio", "nu = 0.7");
    s->SetPoissonRatio(0.3);
    s->SetPhyxelSpacing(0.0);
    ExpectRefused(s, "PhyxelSpacing", "spacing 0");
    s->SetPhyxelSpacing(1e-7);
    ExpectRefused(s, "PhyxelSpacing", "spacing far too small");
    // Back to sane settings: the same source recovers.
    s->SetPhyxelSpacing(0.05);
    vtkPolyData* p = Phyxels(s, 0.2);
    Check(p && p->GetNumberOfPoints() > 50 && AllFinite(p), "sane settings after hostile ones");
  }
  {
    // Zero phyxels: two small closed octahedra far apart; the lattice (centred between them, coarse) misses
    // both.
    vtkNew<vtkPolyData> both;
    vtkNew<vtkPoints> pts;
    vtkNew<vtkCellArray> tris;
    for (double cx : { -1.0, 1.0 })
    {
      const vtkIdType o = pts->GetNumberOfPoints();
      const double r = 0.05;
      pts->InsertNextPoint(cx + r, 0, 0.5);
      pts->InsertNextPoint(cx - r, 0, 0.5);
      pts->InsertNextPoint(cx, r, 0.5);
      pts->InsertNextPoint(cx, -r, 0.5);
      pts->InsertNextPoint(cx, 0, 0.5 + r);
      pts->InsertNextPoint(cx, 0, 0.5 - r);
      for (vtkIdType xi : { 0, 1 })
        for (vtkIdType yi : { 2, 3 })
          for (vtkIdType zi : { 4, 5 })
          {
            // outward when the signs of the three axes multiply to +1 (x: +,-; y: +,-; z: +,-)
            const bool outward = ((xi == 0) == (yi == 2)) == (zi == 4);
            const vtkIdType tri[3] = { o + xi, o + (outward ? yi : zi), o + (outward ? zi : yi) };
            tris->InsertNextCell(3, tri);
          }
    }
    both->SetPoints(pts);
    both->SetPolys(tris);
    auto s = Make();
    s->SetInputData(both);
    s->SetPhyxelSpacing(0.5);
    ExpectRefused(s, "No phyxels", "zero phyxels");
  }
  {
    // Coplanar phyxels (a flat box): a warning, finite output, the plate still falls under gravity.
    auto s = Make();
    s->SetShape(vtkMeshFreeDeformableSolid::BOX);
    s->SetShapeBounds(-0.2, 0.2, -0.2, 0.2, 0.5, 0.5);
    vtkNew<vtkTest::ErrorObserver> observer;
    s->AddObserver(vtkCommand::ErrorEvent, observer);
    s->AddObserver(vtkCommand::WarningEvent, observer);
    vtkPolyData* p = Phyxels(s, 0.2);
    Check(!observer->GetError(), "coplanar: unexpected error " + observer->GetErrorMessage());
    Check(observer->GetWarningMessage().find("coplanar") != std::string::npos,
      "coplanar: no warning about coplanar neighbourhoods: " + observer->GetWarningMessage());
    Check(p && p->GetNumberOfPoints() == 64 && AllFinite(p), "coplanar: output not finite");
    double x[3];
    p->GetPoint(0, x);
    Check(x[2] < 0.5 - 0.1, "coplanar: the plate did not fall");
  }
  {
    // A huge explicit step is sub-stepped with a warning; an implicit step 50x the explicit limit is stable
    // and both keep the body in its box (asked for: the default is no container).
    for (int integrator : { 0, 1 })
    {
      auto s = Make();
      s->SetContainer(vtkMeshFreeDeformableSolid::BOX_CONTAINER);
      s->SetContainerBounds(-0.5, 0.5, -0.5, 0.5, 0.0, 1.0);
      s->SetEndTime(1.0);
      s->SetOutputInterval(0.25);
      s->SetIntegrator(integrator);
      s->SetDamping(2.0);
      vtkNew<vtkTest::ErrorObserver> observer;
      s->AddObserver(vtkCommand::ErrorEvent, observer);
      s->AddObserver(vtkCommand::WarningEvent, observer);
      s->SetTimeStep(integrator == 0 ? 0.25 : 0.0);
      s->UpdateInformation();
      Phyxels(s, 0.0);
      const double stable = s->GetStableTimeStep();
      if (integrator == 1)
      {
        s->SetTimeStep(50.0 * stable);
        observer->Clear();
      }
      vtkPolyData* p = Phyxels(s, 1.0);
      const std::string name = integrator ? "implicit" : "explicit";
      Check(!observer->GetError(), name + " huge step: error " + observer->GetErrorMessage());
      if (integrator == 0)
        Check(observer->GetWarningMessage().find("sub-steps") != std::string::npos,
          "explicit huge step: no sub-stepping warning: " + observer->GetWarningMessage());
      else
        Check(s->GetConjugateGradientIterations() > 0, "implicit: no CG iterations reported");
      Check(p && p->GetNumberOfPoints() > 50 && AllFinite(p), name + " huge step: output not finite");
      double bounds[6];
      p->GetBounds(bounds);
      Check(bounds[4] >= 0.0 && bounds[5] < 1.0 && bounds[0] >= -0.5 && bounds[1] <= 0.5,
        name + " huge step: left the container");
      std::cout << name << ": stable explicit step " << stable << " s, CG iterations "
                << s->GetConjugateGradientIterations() << ", z range " << bounds[4] << " " << bounds[5]
                << std::endl;
    }
  }
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
