// vtkMeshFreeMLSKernel inside VTK's own vtkPointInterpolator: linear data reproduced exactly (VTK's
// kernels cannot), Franke's F1 as accurate as the Meshless Approximation filter's MLS (same shape functions,
// same neighbours), and far better than vtkGaussianKernel.
#include "TestFunctions.h"
#include "vtkMeshFreeMLSKernel.h"
#include "vtkMeshlessApproximation.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkGaussianKernel.h"
#include "vtkIdList.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPointInterpolator.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <cmath>
#include <iostream>

namespace
{
using meshfree::testing::Franke;
using meshfree::testing::Halton;
double Rms(vtkDataSet* out, const char* name, double (*exact)(double, double), double& maxError)
{
  vtkDataArray* a = out->GetPointData()->GetArray(name);
  double sum = 0.0;
  maxError = 0.0;
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    double x[3];
    out->GetPoint(i, x);
    const double d = a->GetTuple1(i) - exact(x[0], x[1]);
    sum += d * d;
    maxError = std::max(maxError, std::fabs(d));
  }
  return std::sqrt(sum / out->GetNumberOfPoints());
}

double Linear(double x, double y)
{
  return 1.0 + 2.0 * x - 3.0 * y;
}
}

int TestMLSKernel(int, char*[])
{
  const int n = 1000;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> f, lin;
  f->SetName("F");
  lin->SetName("L");
  for (int i = 0; i < n; ++i)
  {
    const double x = Halton(i + 1, 2), y = Halton(i + 1, 3);
    points->InsertNextPoint(x, y, 0.0);
    f->InsertNextValue(Franke(x, y));
    lin->InsertNextValue(Linear(x, y));
  }
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(points);
  cloud->GetPointData()->AddArray(f);
  cloud->GetPointData()->AddArray(lin);

  vtkNew<vtkImageData> probe;
  probe->SetDimensions(51, 51, 1);
  probe->SetOrigin(0.0, 0.0, 0.0);
  probe->SetSpacing(0.02, 0.02, 1.0);

  vtkNew<vtkMeshFreeMLSKernel> kernel;
  vtkNew<vtkPointInterpolator> interpolator;
  interpolator->SetInputData(probe);
  interpolator->SetSourceData(cloud);
  interpolator->SetKernel(kernel);
  interpolator->Update();
  vtkDataSet* out = interpolator->GetOutput();
  double maxLinear = 0.0, maxFranke = 0.0;
  Rms(out, "L", Linear, maxLinear);
  const double rms = Rms(out, "F", Franke, maxFranke);
  std::cout << "vtkPointInterpolator + vtkMeshFreeMLSKernel: linear max error " << maxLinear << ", Franke rms "
            << rms << "\n";
  if (!(maxLinear < 1e-10) || !(rms < 5e-4))
  {
    std::cerr << "ERROR: the MLS kernel does not reproduce linear data or is inaccurate\n";
    return EXIT_FAILURE;
  }

  // The same shape functions as the filter's MLS.
  vtkNew<vtkMeshlessApproximation> filter;
  filter->SetInputData(0, cloud);
  filter->SetInputData(1, probe);
  filter->Update();
  vtkDataArray* mine = vtkDataSet::SafeDownCast(filter->GetOutputDataObject(0))->GetPointData()->GetArray("F");
  vtkDataArray* theirs = out->GetPointData()->GetArray("F");
  double diff = 0.0;
  for (vtkIdType i = 0; i < mine->GetNumberOfTuples(); ++i)
  {
    diff = std::max(diff, std::fabs(mine->GetTuple1(i) - theirs->GetTuple1(i)));
  }
  std::cout << "max |kernel - filter| = " << diff << "\n";
  if (!(diff < 1e-10))
  {
    std::cerr << "ERROR: kernel and filter disagree\n";
    return EXIT_FAILURE;
  }

  // Cubics in 3D with the default 20 neighbours: 20 basis terms, so the kernel, like the filter, takes at least
  // 2 neighbours per term (40) and both give the same values.
  {
    vtkNew<vtkPoints> points3;
    points3->SetDataTypeToDouble();
    vtkNew<vtkDoubleArray> g;
    g->SetName("G");
    for (int i = 0; i < 2000; ++i)
    {
      const double x = Halton(i + 1, 2), y = Halton(i + 1, 3), z = Halton(i + 1, 5);
      points3->InsertNextPoint(x, y, z);
      g->InsertNextValue(Franke(x, y) * (1.0 + z * z));
    }
    vtkNew<vtkPolyData> cloud3;
    cloud3->SetPoints(points3);
    cloud3->GetPointData()->AddArray(g);
    vtkNew<vtkImageData> probe3;
    probe3->SetDimensions(7, 7, 7);
    probe3->SetOrigin(0.2, 0.2, 0.2);
    probe3->SetSpacing(0.1, 0.1, 0.1);
    vtkNew<vtkMeshFreeMLSKernel> cubic;
    cubic->SetBasisDegree(3);
    cubic->Initialize(nullptr, cloud3, cloud3->GetPointData());
    vtkNew<vtkIdList> ids;
    double centre[3] = { 0.5, 0.5, 0.5 };
    const vtkIdType used = cubic->ComputeBasis(centre, ids);
    std::cout << "cubic 3D kernel: " << used << " neighbours for NeighborCount 20\n";
    vtkNew<vtkPointInterpolator> interpolator3;
    interpolator3->SetInputData(probe3);
    interpolator3->SetSourceData(cloud3);
    interpolator3->SetKernel(cubic);
    interpolator3->Update();
    vtkNew<vtkMeshlessApproximation> filter3;
    filter3->SetBasisDegree(3);
    filter3->SetInputData(0, cloud3);
    filter3->SetInputData(1, probe3);
    filter3->Update();
    vtkDataArray* a = vtkDataSet::SafeDownCast(filter3->GetOutputDataObject(0))->GetPointData()->GetArray("G");
    vtkDataArray* b = interpolator3->GetOutput()->GetPointData()->GetArray("G");
    double diff3 = 0.0;
    for (vtkIdType i = 0; a && b && i < a->GetNumberOfTuples(); ++i)
    {
      diff3 = std::max(diff3, std::fabs(a->GetTuple1(i) - b->GetTuple1(i)));
    }
    std::cout << "cubic 3D: max |kernel - filter| = " << diff3 << "\n";
    if (used != 40 || !a || !b || !(diff3 < 1e-10))
    {
      std::cerr << "ERROR: the cubic 3D kernel does not take 2 neighbours per basis term as the filter does\n";
      return EXIT_FAILURE;
    }
  }

  // VTK's Gaussian kernel (normalised positive weights) on the same data: first order at best.
  vtkNew<vtkGaussianKernel> gaussian;
  gaussian->SetKernelFootprintToNClosest();
  gaussian->SetNumberOfPoints(20);
  interpolator->SetKernel(gaussian);
  interpolator->Update();
  double maxGauss = 0.0;
  const double rmsGauss = Rms(interpolator->GetOutput(), "F", Franke, maxGauss);
  std::cout << "vtkGaussianKernel (20 closest): Franke rms " << rmsGauss << "\n";
  if (!(rms < rmsGauss / 5))
  {
    std::cerr << "ERROR: MLS is expected to beat a Gaussian kernel clearly\n";
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
