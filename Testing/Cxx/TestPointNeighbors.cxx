// vtkMeshFreePointNeighbors against brute force on a random cloud with NaN points mixed in.
#include "vtkMeshFreePointNeighbors.h"

#include "vtkCharArray.h"
#include "vtkDataArray.h"
#include "vtkIdTypeArray.h"
#include "vtkMath.h"
#include "vtkMinimalStandardRandomSequence.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <vector>

int TestPointNeighbors(int, char*[])
{
  const int n = 3000;
  const int k = 10;
  const double radius = 0.08;
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(7);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (int i = 0; i < n; ++i)
  {
    double x[3];
    for (double& c : x)
    {
      c = random->GetValue();
      random->Next();
    }
    if (i % 500 == 3)
    {
      x[1] = std::numeric_limits<double>::quiet_NaN(); // invalid points must be masked, not crash
    }
    points->InsertNextPoint(x);
  }
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(points);

  vtkNew<vtkMeshFreePointNeighbors> filter;
  filter->SetInputData(cloud);
  filter->SetNeighborCount(k);
  filter->SetSearchRadius(radius);
  filter->Update();
  vtkPointSet* out = vtkPointSet::SafeDownCast(filter->GetOutputDataObject(0));
  vtkDataArray* mean = out->GetPointData()->GetArray("MeanNeighborDistance");
  vtkDataArray* mask = out->GetPointData()->GetArray("vtkValidPointMask");
  vtkDataArray* count = out->GetPointData()->GetArray("NeighborsInRadius");
  if (!mean || !mask || !count || mean->GetNumberOfTuples() != n)
  {
    std::cerr << "ERROR: missing output arrays\n";
    return EXIT_FAILURE;
  }

  int failures = 0;
  std::vector<double> d;
  for (int i = 0; i < n; ++i)
  {
    double xi[3];
    points->GetPoint(i, xi);
    const bool valid = std::isfinite(xi[0]) && std::isfinite(xi[1]) && std::isfinite(xi[2]);
    if (mask->GetTuple1(i) != (valid ? 1 : 0))
    {
      ++failures;
      continue;
    }
    if (!valid)
    {
      if (mean->GetTuple1(i) != 0 || count->GetTuple1(i) != 0)
      {
        ++failures;
      }
      continue;
    }
    d.clear();
    int inRadius = 0;
    for (int j = 0; j < n; ++j)
    {
      double xj[3];
      points->GetPoint(j, xj);
      if (j == i || !std::isfinite(xj[1]))
      {
        continue;
      }
      const double dist = std::sqrt(vtkMath::Distance2BetweenPoints(xi, xj));
      d.push_back(dist);
      inRadius += dist <= radius ? 1 : 0;
    }
    std::partial_sort(d.begin(), d.begin() + k, d.end());
    double expected = 0;
    for (int j = 0; j < k; ++j)
    {
      expected += d[j];
    }
    expected /= k;
    if (std::abs(mean->GetTuple1(i) - expected) > 1e-12 * std::max(1.0, expected) ||
      count->GetTuple1(i) != inRadius)
    {
      if (failures < 5)
      {
        std::cerr << "point " << i << ": mean " << mean->GetTuple1(i) << " expected " << expected
                  << ", count " << count->GetTuple1(i) << " expected " << inRadius << "\n";
      }
      ++failures;
    }
  }
  if (failures)
  {
    std::cerr << "ERROR: " << failures << " points disagree with brute force\n";
    return EXIT_FAILURE;
  }
  std::cout << "All " << n << " points agree with brute force.\n";
  return EXIT_SUCCESS;
}
