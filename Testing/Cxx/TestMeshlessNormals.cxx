// vtkMeshlessNormals on 20k-point clouds: a noisy torus without normals (accurate, outward everywhere;
// ProjectPoints removes most of the noise), the curvature of a sphere, the Viewpoint and InputNormals
// orientations, NaN points masked, and InputNormals without Normals refused.
#include "vtkMeshlessNormals.h"

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkTestErrorObserver.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

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

constexpr double RingRadius = 1.0;
constexpr double TubeRadius = 0.35;

/// n points uniform by area on the unit sphere or the torus (R = 1, r = 0.35, axis z), Gaussian noise
/// sigma per axis. No arrays.
vtkNew<vtkPolyData> SurfaceCloud(bool torus, int n, double sigma, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  while (points->GetNumberOfPoints() < n)
  {
    double p[3];
    if (torus)
    {
      const double u = 2.0 * vtkMath::Pi() * u01(rng), v = 2.0 * vtkMath::Pi() * u01(rng);
      if (u01(rng) * (RingRadius + TubeRadius) >= RingRadius + TubeRadius * std::cos(v))
        continue; // area element (R + r cos v)
      const double ring = RingRadius + TubeRadius * std::cos(v);
      p[0] = ring * std::cos(u);
      p[1] = ring * std::sin(u);
      p[2] = TubeRadius * std::sin(v);
    }
    else
    {
      p[0] = g(rng);
      p[1] = g(rng);
      p[2] = g(rng);
      vtkMath::Normalize(p);
    }
    for (double& c : p)
      c += sigma * g(rng);
    points->InsertNextPoint(p);
  }
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(points);
  return cloud;
}

/// Distance to the exact surface (positive outside) and the outward normal at the nearest surface point.
double SurfaceDistance(const double p[3], bool torus, double normal[3])
{
  double q[3] = { p[0], p[1], p[2] };
  if (torus)
  {
    const double rho = std::hypot(p[0], p[1]);
    q[0] -= RingRadius * p[0] / rho;
    q[1] -= RingRadius * p[1] / rho;
  }
  const double len = vtkMath::Norm(q);
  for (int a = 0; a < 3; ++a)
    normal[a] = q[a] / len;
  return len - (torus ? TubeRadius : 1.0);
}

struct Score
{
  double MeanAngle = 0.0; // degrees, to the exact normal
  double Outward = 0.0;   // fraction of valid points with n . exact > 0
  double Rms = 0.0;       // distance of the output points to the surface
  vtkIdType Valid = 0;
  bool Unit = true, Finite = true;
};

Score Evaluate(vtkPointSet* out, bool torus)
{
  Score s;
  vtkDataArray* normals = out->GetPointData()->GetNormals();
  vtkDataArray* mask = out->GetPointData()->GetArray("vtkValidPointMask");
  if (!normals || !mask || normals->GetNumberOfComponents() != 3)
  {
    s.Finite = false;
    return s;
  }
  vtkIdType outward = 0;
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    if (mask->GetTuple1(i) == 0)
      continue;
    double p[3], n[3], t[3];
    out->GetPoint(i, p);
    normals->GetTuple(i, n);
    const double d = SurfaceDistance(p, torus, t);
    s.Finite = s.Finite && std::isfinite(d) && std::isfinite(vtkMath::Norm(n));
    s.Unit = s.Unit && std::fabs(vtkMath::Norm(n) - 1.0) < 1e-9;
    const double c = vtkMath::Dot(n, t);
    outward += c > 0.0 ? 1 : 0;
    s.MeanAngle += vtkMath::DegreesFromRadians(std::acos(std::min(1.0, std::fabs(c))));
    s.Rms += d * d;
    ++s.Valid;
  }
  const double valid = static_cast<double>(std::max<vtkIdType>(1, s.Valid));
  s.MeanAngle /= valid;
  s.Outward = outward / valid;
  s.Rms = std::sqrt(s.Rms / valid);
  return s;
}

double RmsDistance(vtkPointSet* cloud, bool torus)
{
  double sum2 = 0.0, t[3];
  for (vtkIdType i = 0; i < cloud->GetNumberOfPoints(); ++i)
  {
    double p[3];
    cloud->GetPoint(i, p);
    const double d = SurfaceDistance(p, torus, t);
    sum2 += d * d;
  }
  return std::sqrt(sum2 / std::max<vtkIdType>(1, cloud->GetNumberOfPoints()));
}

bool AllFinite(vtkPointSet* p)
{
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

void TestNoisyTorus()
{
  vtkNew<vtkPolyData> cloud = SurfaceCloud(true, 20000, 0.005, 21);
  const double inputRms = RmsDistance(cloud, true);
  vtkNew<vtkMeshlessNormals> normals;
  normals->SetInputData(cloud);
  normals->Update();
  vtkPointSet* out = normals->GetOutput();
  const Score s = Evaluate(out, true);
  Check(s.Valid == 20000, "torus: " + std::to_string(20000 - s.Valid) + " points without a normal");
  Check(s.Finite && s.Unit && AllFinite(out), "torus: normals not unit, or NaN in the output");
  Check(s.MeanAngle < 8.0, "torus: mean angle error " + std::to_string(s.MeanAngle) + " degrees");
  Check(s.Outward == 1.0, "torus: " + std::to_string(100.0 * (1.0 - s.Outward)) + " % of the normals point inward");
  Check(out->GetPoints() == cloud->GetPoints(), "torus: the points were copied without ProjectPoints");
  for (const char* name : { "Curvature", "SurfaceVariation", "OrientationConfidence" })
    Check(out->GetPointData()->GetArray(name) != nullptr, std::string("torus: no array ") + name);
  vtkFieldData* fd = out->GetFieldData();
  vtkDataArray* noise = fd->GetArray("NoiseEstimate");
  Check(noise && noise->GetTuple1(0) > 0.001 && noise->GetTuple1(0) < 0.02,
    "torus: NoiseEstimate " + std::to_string(noise ? noise->GetTuple1(0) : -1.0) + " for sigma 0.005");
  Check(fd->GetArray("SupportRadius") && fd->GetArray("SupportRadius")->GetTuple1(0) > 0, "torus: SupportRadius");
  Check(fd->GetArray("AmbiguousOrientations") != nullptr, "torus: AmbiguousOrientations");
  std::cout << "Noisy torus: mean angle error " << s.MeanAngle << " degrees, " << 100.0 * s.Outward
            << " % outward, noise estimate " << (noise ? noise->GetTuple1(0) : -1.0) << "\n";

  // ComputeCurvature off: the same normals, no Curvature array.
  vtkNew<vtkDoubleArray> kept;
  kept->DeepCopy(out->GetPointData()->GetNormals());
  normals->ComputeCurvatureOff();
  normals->Update();
  Check(out->GetPointData()->GetArray("Curvature") == nullptr, "ComputeCurvature off: a Curvature array");
  double largest = 0.0;
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
    for (int a = 0; a < 3; ++a)
      largest = std::max(largest,
        std::fabs(out->GetPointData()->GetNormals()->GetComponent(i, a) - kept->GetComponent(i, a)));
  Check(largest == 0.0, "ComputeCurvature off changed the normals by " + std::to_string(largest));
  normals->ComputeCurvatureOn();

  double before[3];
  cloud->GetPoint(0, before);
  normals->ProjectPointsOn();
  normals->Update();
  const Score projected = Evaluate(out, true);
  Check(out->GetPoints() != cloud->GetPoints(), "torus: ProjectPoints did not replace the points");
  Check(cloud->GetPoint(0)[0] == before[0] && out->GetPoint(0)[0] != before[0], "torus: the input's points changed");
  Check(projected.Rms < 2.5e-3,
    "torus: projected rms distance " + std::to_string(projected.Rms) + " (input " + std::to_string(inputRms) + ")");
  Check(projected.Outward == 1.0 && projected.Unit, "torus: projected normals not unit and outward");
  std::cout << "ProjectPoints: rms distance " << inputRms << " -> " << projected.Rms << ", mean angle error "
            << projected.MeanAngle << "\n";
}

void TestSphereCurvatureAndOrientations()
{
  vtkNew<vtkPolyData> cloud = SurfaceCloud(false, 20000, 0.002, 4);
  vtkNew<vtkMeshlessNormals> normals;
  normals->SetInputData(cloud);
  normals->Update();
  vtkPointSet* out = normals->GetOutput();
  vtkDataArray* curvature = out->GetPointData()->GetArray("Curvature");
  std::vector<double> k;
  for (vtkIdType i = 0; curvature && i < curvature->GetNumberOfTuples(); ++i)
    k.push_back(curvature->GetTuple1(i));
  std::nth_element(k.begin(), k.begin() + k.size() / 2, k.end());
  const double median = k.empty() ? 0.0 : k[k.size() / 2];
  Check(std::fabs(median - 1.0) < 0.05, "sphere: median curvature " + std::to_string(median) + ", not 1");
  Check(Evaluate(out, false).Outward == 1.0, "sphere: not outward");
  std::cout << "Sphere: median curvature " << median << "\n";

  // A viewpoint at the centre turns every normal inward (and the curvature negative).
  normals->SetOrientationToViewpoint();
  normals->SetViewpoint(0.0, 0.0, 0.0);
  normals->Update();
  Check(Evaluate(out, false).Outward == 0.0, "Viewpoint at the centre: some normals point outward");

  // Reference normals of any length, all inward: InputNormals (and Auto) follow them, not the propagation.
  vtkNew<vtkDoubleArray> reference;
  reference->SetName("Normals");
  reference->SetNumberOfComponents(3);
  reference->SetNumberOfTuples(cloud->GetNumberOfPoints());
  for (vtkIdType i = 0; i < cloud->GetNumberOfPoints(); ++i)
  {
    double p[3];
    cloud->GetPoint(i, p);
    const double scale = -0.1 - (i % 7);
    reference->SetTuple3(i, scale * p[0], scale * p[1], scale * p[2]);
  }
  vtkNew<vtkPolyData> withNormals;
  withNormals->ShallowCopy(cloud);
  withNormals->GetPointData()->AddArray(reference);
  normals->SetInputData(withNormals);
  for (int orientation : { vtkMeshlessNormals::INPUT_NORMALS, vtkMeshlessNormals::AUTO })
  {
    normals->SetOrientation(orientation);
    normals->Update();
    const Score s = Evaluate(out, false);
    Check(s.Outward == 0.0 && s.Unit, "orientation " + std::to_string(orientation) + ": not along the input's Normals");
  }
  // Propagation ignores them.
  normals->SetOrientationToPropagation();
  normals->Update();
  Check(Evaluate(out, false).Outward == 1.0, "Propagation with input Normals: not outward");
}

void TestHostile()
{
  // InputNormals without Normals: an error naming them, an empty output.
  {
    vtkNew<vtkPolyData> cloud = SurfaceCloud(false, 500, 0.0, 1);
    vtkNew<vtkMeshlessNormals> normals;
    vtkNew<vtkTest::ErrorObserver> observer;
    normals->AddObserver(vtkCommand::ErrorEvent, observer);
    normals->SetInputData(cloud);
    normals->SetOrientationToInputNormals();
    normals->Update();
    Check(observer->GetError() && observer->GetErrorMessage().find("Normals") != std::string::npos,
      "InputNormals without Normals: no error naming them");
    Check(normals->GetOutput()->GetNumberOfPoints() == 0, "InputNormals without Normals: output not empty");
  }
  // NaN points: masked, zero normals, a warning; the others unaffected.
  {
    vtkNew<vtkPolyData> cloud = SurfaceCloud(false, 3000, 0.0, 2);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (vtkIdType i = 5; i < 3000; i += 500)
      cloud->GetPoints()->SetPoint(i, nan, 0.0, 0.0);
    vtkNew<vtkMeshlessNormals> normals;
    vtkNew<vtkTest::ErrorObserver> observer;
    normals->AddObserver(vtkCommand::WarningEvent, observer);
    normals->SetInputData(cloud);
    normals->ProjectPointsOn();
    normals->Update();
    vtkPointSet* out = normals->GetOutput();
    vtkDataArray* mask = out->GetPointData()->GetArray("vtkValidPointMask");
    vtkDataArray* n = out->GetPointData()->GetArray("Normals");
    Check(observer->GetWarning(), "NaN points: no warning");
    Check(mask && n && mask->GetTuple1(5) == 0 && mask->GetTuple1(6) == 1 && vtkMath::Norm(n->GetTuple3(5)) == 0,
      "NaN points: not masked");
    Check(AllFinite(out), "NaN points: NaN in the output arrays");
    const Score s = Evaluate(out, false);
    Check(s.Valid == 2994 && s.Outward == 1.0, "NaN points: the others are affected");
  }
  // Only NaN points: all masked, a warning, no crash.
  {
    vtkNew<vtkPoints> points;
    for (int i = 0; i < 10; ++i)
      points->InsertNextPoint(std::numeric_limits<double>::quiet_NaN(), i, 0.0);
    vtkNew<vtkPolyData> cloud;
    cloud->SetPoints(points);
    vtkNew<vtkMeshlessNormals> normals;
    vtkNew<vtkTest::ErrorObserver> observer;
    normals->AddObserver(vtkCommand::WarningEvent, observer);
    normals->SetInputData(cloud);
    normals->ProjectPointsOn();
    normals->Update();
    vtkPointSet* out = normals->GetOutput();
    vtkDataArray* mask = out->GetPointData()->GetArray("vtkValidPointMask");
    double range[2] = { 1, 1 };
    if (mask)
      mask->GetRange(range);
    Check(out->GetNumberOfPoints() == 10 && mask && range[1] == 0 && AllFinite(out) && observer->GetWarning(),
      "only NaN points: all masked with a warning expected");
  }
  // Empty input: a warning, an empty output.
  {
    vtkNew<vtkPolyData> empty;
    vtkNew<vtkMeshlessNormals> normals;
    vtkNew<vtkTest::ErrorObserver> observer;
    normals->AddObserver(vtkCommand::WarningEvent, observer);
    normals->AddObserver(vtkCommand::ErrorEvent, observer);
    normals->SetInputData(empty);
    normals->Update();
    Check(normals->GetOutput()->GetNumberOfPoints() == 0 && observer->GetWarning() && !observer->GetError(),
      "empty input: a warning and an empty output expected");
  }
}
} // namespace

int TestMeshlessNormals(int, char*[])
{
  TestNoisyTorus();
  TestSphereCurvatureAndOrientations();
  TestHostile();
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
