// The thesis' deformable scenes (figs 4.6-4.8): an octahedron of about 299 phyxels in a box, ellipsoids of about
// 568 phyxels in a cylinder and about 715 phyxels (990-vertex, 1976-triangle surface) in a box, dropped under
// gravity. They stay inside their containers, stay finite, and come to rest with damping.
#include "vtkMeshFreeDeformableSolid.h"

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkTestErrorObserver.h"

#include <cmath>
#include <iostream>
#include <string>

namespace
{
struct Scene
{
  const char* Name;
  int Shape;
  double Bounds[6];
  double Spacing;
  int Container;
  double E, Nu, Rho, Kv;
  long ExpectedPhyxels;
  long SurfacePoints, SurfaceTriangles;
};

int failures = 0;
void Check(bool ok, const std::string& what)
{
  if (!ok)
  {
    std::cout << "ERROR: " << what << std::endl;
    ++failures;
  }
}

double MaxSpeed(vtkPolyData* p)
{
  vtkDataArray* v = p->GetPointData()->GetArray("Velocity");
  double vmax = 0.0;
  for (vtkIdType i = 0; i < v->GetNumberOfTuples(); ++i)
  {
    double* t = v->GetTuple3(i);
    vmax = std::max(vmax, std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]));
  }
  return vmax;
}
} // namespace

int TestDeformableSolidScenes(int, char*[])
{
  // Geometry scaled to bodies 0.4 m long; material of the thesis' table 4.3 (the ellipsoids 20x stiffer, so that
  // a 0.3 m drop stays a moderate deformation at this size).
  const Scene scenes[] = {
    { "octahedron (fig 4.6)", vtkMeshFreeDeformableSolid::OCTAHEDRON, { -0.2, 0.2, -0.2, 0.2, 0.3, 0.5 }, 0.0268,
      vtkMeshFreeDeformableSolid::BOX_CONTAINER, 1e4, 0.1, 10.0, 100.0, 299, 0, 0 },
    { "ellipsoid 568 (fig 4.7)", vtkMeshFreeDeformableSolid::ELLIPSOID, { -0.2, 0.2, -0.1, 0.1, 0.3, 0.5 }, 0.0247,
      vtkMeshFreeDeformableSolid::CYLINDER_CONTAINER, 2000.0, 0.2, 5.0, 100.0, 568, 0, 0 },
    { "ellipsoid 715 (fig 4.8)", vtkMeshFreeDeformableSolid::ELLIPSOID, { -0.2, 0.2, -0.08, 0.08, 0.3, 0.46 },
      0.0196, vtkMeshFreeDeformableSolid::BOX_CONTAINER, 2000.0, 0.2, 5.0, 100.0, 715, 990, 1976 },
  };
  const double container[6] = { -0.3, 0.3, -0.3, 0.3, 0.0, 1.0 };
  for (const Scene& scene : scenes)
  {
    vtkNew<vtkMeshFreeDeformableSolid> s;
    s->SetShape(scene.Shape);
    s->SetShapeBounds(const_cast<double*>(scene.Bounds));
    s->SetPhyxelSpacing(scene.Spacing);
    s->SetContainer(scene.Container);
    s->SetContainerBounds(const_cast<double*>(container));
    s->SetYoungModulus(scene.E);
    s->SetPoissonRatio(scene.Nu);
    s->SetDensity(scene.Rho);
    s->SetVolumeStiffness(scene.Kv);
    s->SetInitialVelocity(0.6, 0.3, 0.0);
    s->SetDamping(4.0);
    s->SetEndTime(3.0);
    s->SetOutputInterval(0.25);
    vtkNew<vtkTest::ErrorObserver> observer;
    s->AddObserver(vtkCommand::ErrorEvent, observer);
    const std::string name = scene.Name;
    double peak = 0.0;
    for (int k = 0; k <= 12; ++k)
    {
      s->UpdateTimeStep(0.25 * k);
      auto* mb = vtkMultiBlockDataSet::SafeDownCast(s->GetOutputDataObject(0));
      auto* p = vtkPolyData::SafeDownCast(mb->GetBlock(0));
      const long n = p->GetNumberOfPoints();
      if (k == 0)
      {
        Check(std::abs(n - scene.ExpectedPhyxels) <= 0.02 * scene.ExpectedPhyxels,
          name + ": phyxel count " + std::to_string(n));
        auto* surface = vtkPolyData::SafeDownCast(mb->GetBlock(1));
        Check(surface != nullptr, name + ": no surface");
        if (scene.SurfacePoints > 0 && surface)
          Check(surface->GetNumberOfPoints() == scene.SurfacePoints &&
              surface->GetNumberOfCells() == scene.SurfaceTriangles,
            name + ": surface " + std::to_string(surface->GetNumberOfPoints()) + " vertices");
        std::cout << name << ": " << n << " phyxels, stable step " << s->GetStableTimeStep() << " s" << std::endl;
      }
      for (vtkIdType i = 0; i < n; ++i)
      {
        double x[3];
        p->GetPoint(i, x);
        bool inside = std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]) && x[2] >= 0.0 &&
          x[2] <= 1.0;
        if (scene.Container == vtkMeshFreeDeformableSolid::BOX_CONTAINER)
          inside = inside && std::fabs(x[0]) <= 0.3 && std::fabs(x[1]) <= 0.3;
        else
          inside = inside && std::hypot(x[0], x[1]) <= 0.3 + 1e-12;
        if (!inside)
        {
          Check(false, name + ": phyxel outside the container at t = " + std::to_string(0.25 * k));
          break;
        }
      }
      const double speed = MaxSpeed(p);
      peak = std::max(peak, speed);
      if (k == 12)
      {
        std::cout << name << ": peak speed " << peak << " m/s, at t = 3 s " << speed << " m/s" << std::endl;
        Check(speed < 0.02 * peak, name + ": not at rest after 3 s: " + std::to_string(speed) + " m/s");
      }
    }
    Check(!observer->GetError(), name + ": " + observer->GetErrorMessage());
  }
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
