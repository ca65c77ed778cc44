// vtkMeshlessApproximation as a VTK filter: default grid (101 x 101 x 1 for a flat cloud), integer and
// multi-component arrays, NaN coordinates, an empty cloud, SPH volumes from Mass/Density, HeightField,
// a probe, and no NaN anywhere in the output.
#include "TestFunctions.h"
#include "vtkMeshlessApproximation.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkImageData.h"
#include "vtkIntArray.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStructuredGrid.h"

#include <cmath>
#include <iostream>

namespace
{
using meshfree::testing::Halton;
#define CHECK(cond)                                                                                   \
  if (!(cond))                                                                                          \
  {                                                                                                     \
    std::cerr << "ERROR: " #cond " failed at line " << __LINE__ << "\n";                                \
    return EXIT_FAILURE;                                                                                \
  }

bool AllFinite(vtkDataSet* out)
{
  vtkPointData* pd = out->GetPointData();
  for (int a = 0; a < pd->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* array = pd->GetArray(a);
    for (vtkIdType i = 0; array && i < array->GetNumberOfValues(); ++i)
    {
      if (!std::isfinite(array->GetComponent(i / array->GetNumberOfComponents(), i % array->GetNumberOfComponents())))
      {
        return false;
      }
    }
  }
  return true;
}

vtkSmartPointer<vtkPolyData> Cloud(int n, bool withNaN, bool height)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> vec, mass, density;
  vtkNew<vtkIntArray> label;
  vec->SetName("Vector");
  vec->SetNumberOfComponents(2);
  label->SetName("Label");
  mass->SetName("Mass");
  density->SetName("Density");
  for (int i = 0; i < n; ++i)
  {
    const double x = Halton(i + 1, 2), y = Halton(i + 1, 3);
    points->InsertNextPoint(x, (withNaN && i % 50 == 7) ? vtkMath::Nan() : y, height ? x * x - y : 0.0);
    vec->InsertNextTuple2(2 * x + y, x - y);
    label->InsertNextValue(7);
    mass->InsertNextValue(2.0 / n);
    density->InsertNextValue(2.0);
  }
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(points);
  cloud->GetPointData()->AddArray(vec);
  cloud->GetPointData()->AddArray(label);
  cloud->GetPointData()->AddArray(mass);
  cloud->GetPointData()->AddArray(density);
  return cloud;
}
}

int TestMeshlessApproximation(int, char*[])
{
  // Defaults on a flat cloud with NaN points mixed in.
  vtkNew<vtkMeshlessApproximation> filter;
  filter->SetInputData(Cloud(800, true, false));
  filter->Update();
  vtkImageData* image = vtkImageData::SafeDownCast(filter->GetOutputDataObject(0));
  CHECK(image);
  int dims[3];
  image->GetDimensions(dims);
  CHECK(dims[0] == 101 && dims[1] == 101 && dims[2] == 1);
  vtkDataArray* vec = image->GetPointData()->GetArray("Vector");
  vtkDataArray* label = image->GetPointData()->GetArray("Label");
  vtkDataArray* mask = image->GetPointData()->GetArray("vtkValidPointMask");
  CHECK(vec && label && mask && vec->GetNumberOfComponents() == 2);
  CHECK(AllFinite(image));
  double worst = 0.0;
  for (vtkIdType i = 0; i < image->GetNumberOfPoints(); ++i)
  {
    double x[3];
    image->GetPoint(i, x);
    CHECK(mask->GetTuple1(i) == 1);
    worst = std::max(worst, std::fabs(vec->GetComponent(i, 0) - (2 * x[0] + x[1])));
    worst = std::max(worst, std::fabs(vec->GetComponent(i, 1) - (x[0] - x[1])));
    worst = std::max(worst, std::fabs(label->GetTuple1(i) - 7.0));
  }
  std::cout << "linear and integer data, max error " << worst << "\n";
  CHECK(worst < 1e-9);

  // SPH with Mass/Density volumes: constants exact with Shepard normalisation, finite without.
  filter->SetMethod(vtkMeshlessApproximation::SPH);
  filter->SetSampleDimensions(21, 21, 21);
  filter->Update();
  image = vtkImageData::SafeDownCast(filter->GetOutputDataObject(0));
  label = image->GetPointData()->GetArray("Label");
  for (vtkIdType i = 0; i < image->GetNumberOfPoints(); ++i)
  {
    CHECK(std::fabs(label->GetTuple1(i) - 7.0) < 1e-12);
  }
  filter->SetShepardNormalization(false);
  filter->Update();
  image = vtkImageData::SafeDownCast(filter->GetOutputDataObject(0));
  CHECK(AllFinite(image));
  // Interior points: sum_j (m_j / rho_j) W is an estimate of 1 (volumes 1/n of the unit square).
  label = image->GetPointData()->GetArray("Label");
  CHECK(std::fabs(label->GetTuple1(10 * 21 + 10) / 7.0 - 1.0) < 0.1);

  // An empty cloud: a warning, every point masked with NullValue.
  vtkNew<vtkPolyData> empty;
  vtkNew<vtkPoints> none;
  empty->SetPoints(none);
  vtkNew<vtkImageData> probe;
  probe->SetDimensions(5, 5, 1);
  vtkNew<vtkMeshlessApproximation> nothing;
  nothing->SetInputData(0, empty);
  nothing->SetInputData(1, probe);
  nothing->SetNullValue(-1.0);
  nothing->Update();
  vtkDataSet* out = vtkDataSet::SafeDownCast(nothing->GetOutputDataObject(0));
  CHECK(out && out->GetNumberOfPoints() == 25);
  mask = out->GetPointData()->GetArray("vtkValidPointMask");
  CHECK(mask && mask->GetRange()[1] == 0.0);

  // HeightField: a 2.5D cloud z = x^2 - y gives the surface with Elevation (quadratic: reproduced).
  vtkNew<vtkMeshlessApproximation> height;
  height->SetInputData(Cloud(600, false, true));
  height->SetHeightField(true);
  height->SetSampleDimensions(31, 31, 31);
  height->Update();
  vtkStructuredGrid* surface = vtkStructuredGrid::SafeDownCast(height->GetOutputDataObject(0));
  CHECK(surface && surface->GetNumberOfPoints() == 31 * 31);
  vtkDataArray* elevation = surface->GetPointData()->GetArray("Elevation");
  CHECK(elevation);
  worst = 0.0;
  for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); ++i)
  {
    double x[3];
    surface->GetPoint(i, x);
    worst = std::max(worst, std::fabs(x[2] - (x[0] * x[0] - x[1])));
    worst = std::max(worst, std::fabs(elevation->GetTuple1(i) - x[2]));
  }
  std::cout << "height field max error " << worst << "\n";
  CHECK(worst < 1e-9);
  return EXIT_SUCCESS;
}
