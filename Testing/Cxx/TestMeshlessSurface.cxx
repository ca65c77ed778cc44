// vtkMeshlessSurface: a closed, accurate sphere from a 20k-point cloud with exact normals (and without them,
// WLS), the SPH surface of a jittered lattice ball, the input's arrays approximated at the vertices, and the
// hostile cases: empty and all-NaN input, abort, an invalid SurfaceLevel. No NaN anywhere.
#include "vtkMeshlessSurface.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdList.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"
#include "vtkTestErrorObserver.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <limits>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <utility>
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

/// n points uniform on the unit sphere with their exact outward normals and Intensity = z.
vtkNew<vtkPolyData> SphereCloud(int n, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  vtkNew<vtkDoubleArray> intensity;
  intensity->SetName("Intensity");
  for (int i = 0; i < n; ++i)
  {
    double p[3] = { g(rng), g(rng), g(rng) };
    vtkMath::Normalize(p);
    points->InsertNextPoint(p);
    normals->InsertNextTuple(p);
    intensity->InsertNextValue(p[2]);
  }
  vtkNew<vtkPolyData> cloud;
  cloud->SetPoints(points);
  cloud->GetPointData()->AddArray(normals);
  cloud->GetPointData()->AddArray(intensity);
  return cloud;
}

/// SPH particles on a jittered cubic lattice filling the ball of radius 1, with Mass, Density and
/// Velocity = position (a linear field the vertices' MLS of degree 1 reproduces).
vtkNew<vtkPolyData> LatticeBall(double spacing, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(-0.1 * spacing, 0.1 * spacing);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> mass, density, velocity;
  mass->SetName("Mass");
  density->SetName("Density");
  velocity->SetName("Velocity");
  velocity->SetNumberOfComponents(3);
  const int m = static_cast<int>(std::ceil(1.0 / spacing)) + 1;
  for (int i = -m; i <= m; ++i)
    for (int j = -m; j <= m; ++j)
      for (int k = -m; k <= m; ++k)
      {
        double x[3] = { (i + 0.5) * spacing, (j + 0.5) * spacing, (k + 0.5) * spacing };
        if (vtkMath::Norm(x) > 1.0 - 0.5 * spacing)
          continue;
        for (double& c : x)
          c += jitter(rng);
        points->InsertNextPoint(x);
        mass->InsertNextValue(1000.0 * spacing * spacing * spacing);
        density->InsertNextValue(1000.0);
        velocity->InsertNextTuple(x);
      }
  vtkNew<vtkPolyData> ball;
  ball->SetPoints(points);
  ball->GetPointData()->AddArray(mass);
  ball->GetPointData()->AddArray(density);
  ball->GetPointData()->AddArray(velocity);
  return ball;
}

struct Topology
{
  vtkIdType Triangles = 0, Edges = 0, Vertices = 0, BoundaryEdges = 0, NonManifoldEdges = 0;
  vtkIdType Euler() const { return this->Vertices - this->Edges + this->Triangles; }
};

/// Counted independently of the core: every edge's triangles, from the polys alone.
Topology CountTopology(vtkPolyData* mesh)
{
  Topology t;
  std::map<std::pair<vtkIdType, vtkIdType>, int> edges;
  std::vector<char> used(mesh->GetNumberOfPoints(), 0);
  vtkNew<vtkIdList> ids;
  vtkCellArray* polys = mesh->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(ids);)
  {
    ++t.Triangles;
    for (vtkIdType e = 0; e < ids->GetNumberOfIds(); ++e)
    {
      const vtkIdType a = ids->GetId(e), b = ids->GetId((e + 1) % ids->GetNumberOfIds());
      used[a] = 1;
      ++edges[{ std::min(a, b), std::max(a, b) }];
    }
  }
  for (const auto& edge : edges)
  {
    t.BoundaryEdges += edge.second == 1 ? 1 : 0;
    t.NonManifoldEdges += edge.second > 2 ? 1 : 0;
  }
  t.Edges = static_cast<vtkIdType>(edges.size());
  for (char u : used)
    t.Vertices += u;
  return t;
}

/// Signed volume enclosed by the triangles (divergence theorem): positive when they face outward.
double EnclosedVolume(vtkPolyData* mesh)
{
  double volume = 0.0;
  vtkNew<vtkIdList> ids;
  vtkCellArray* polys = mesh->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(ids);)
  {
    double a[3], b[3], c[3], bc[3];
    mesh->GetPoint(ids->GetId(0), a);
    mesh->GetPoint(ids->GetId(1), b);
    mesh->GetPoint(ids->GetId(2), c);
    vtkMath::Cross(b, c, bc);
    volume += vtkMath::Dot(a, bc) / 6.0;
  }
  return volume;
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

/// Unit normals with n . (p - centre) > minimumDot at every vertex (outward on a ball about centre).
bool NormalsUnitOutward(vtkPolyData* mesh, double minimumDot)
{
  vtkDataArray* normals = mesh->GetPointData()->GetArray("Normals");
  if (!normals || normals->GetNumberOfComponents() != 3 || mesh->GetPointData()->GetNormals() != normals)
    return false;
  for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i)
  {
    double p[3], n[3];
    mesh->GetPoint(i, p);
    normals->GetTuple(i, n);
    vtkMath::Normalize(p);
    if (std::fabs(vtkMath::Norm(n) - 1.0) > 1e-9 || vtkMath::Dot(n, p) <= minimumDot)
      return false;
  }
  return true;
}

/// A closed sphere-like surface with no NaN.
void CheckClosedSphere(vtkPolyData* out, const std::string& what)
{
  const Topology t = CountTopology(out);
  Check(t.Triangles > 1000, what + ": too few triangles (" + std::to_string(t.Triangles) + ")");
  Check(t.BoundaryEdges == 0 && t.NonManifoldEdges == 0,
    what + ": not closed (" + std::to_string(t.BoundaryEdges) + " boundary, " +
      std::to_string(t.NonManifoldEdges) + " non-manifold edges)");
  Check(t.Euler() == 2, what + ": Euler characteristic " + std::to_string(t.Euler()) + ", not 2");
  Check(t.Vertices == out->GetNumberOfPoints(), what + ": unused vertices");
  Check(AllFinite(out), what + ": NaN/Inf in the output");
}

void TestSphere()
{
  vtkNew<vtkPolyData> cloud = SphereCloud(20000, 11);
  vtkNew<vtkMeshlessSurface> surface;
  surface->SetInputData(cloud);
  surface->Update();
  vtkPolyData* out = surface->GetOutput();
  CheckClosedSphere(out, "MLS sphere");

  double sum2 = 0.0, worstIntensity = 0.0;
  vtkDataArray* intensity = out->GetPointData()->GetArray("Intensity");
  Check(intensity && intensity->GetNumberOfComponents() == 1, "MLS sphere: Intensity not approximated");
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    double p[3];
    out->GetPoint(i, p);
    const double d = vtkMath::Norm(p) - 1.0;
    sum2 += d * d;
    if (intensity)
      worstIntensity = std::max(worstIntensity, std::fabs(intensity->GetTuple1(i) - p[2]));
  }
  const double rms = std::sqrt(sum2 / std::max<vtkIdType>(1, out->GetNumberOfPoints()));
  Check(rms < 1e-4, "MLS sphere: rms distance to the sphere " + std::to_string(rms));
  Check(worstIntensity < 0.02, "MLS sphere: Intensity differs from z by " + std::to_string(worstIntensity));
  Check(NormalsUnitOutward(out, 0.9), "MLS sphere: Normals not unit and outward");
  vtkDataArray* mask = out->GetPointData()->GetArray("vtkValidPointMask");
  double range[2] = { 0, 0 };
  if (mask)
    mask->GetRange(range);
  Check(mask && range[0] == 1, "MLS sphere: vertices masked out of the approximation");

  vtkFieldData* fd = out->GetFieldData();
  auto* method = vtkStringArray::SafeDownCast(fd->GetAbstractArray("SurfaceMethod"));
  Check(method && method->GetValue(0) == "MLS", "MLS sphere: field data SurfaceMethod");
  Check(fd->GetArray("CellSize") && fd->GetArray("CellSize")->GetTuple1(0) > 0, "MLS sphere: field data CellSize");
  Check(fd->GetArray("SupportRadius") && fd->GetArray("SupportRadius")->GetTuple1(0) > 0,
    "MLS sphere: field data SupportRadius");
  std::cout << "MLS sphere: " << out->GetNumberOfPoints() << " vertices, " << out->GetNumberOfPolys()
            << " triangles, rms " << rms << ", Intensity error " << worstIntensity << "\n";

  // WLS from the positions alone (the normals estimated): still closed and near the sphere.
  surface->SetMethodToWLS();
  surface->UseInputNormalsOff();
  surface->Update();
  CheckClosedSphere(out, "WLS sphere without normals");
  sum2 = 0.0;
  for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
  {
    double p[3];
    out->GetPoint(i, p);
    sum2 += (vtkMath::Norm(p) - 1.0) * (vtkMath::Norm(p) - 1.0);
  }
  const double wlsRms = std::sqrt(sum2 / std::max<vtkIdType>(1, out->GetNumberOfPoints()));
  Check(wlsRms < 1e-3, "WLS sphere: rms distance " + std::to_string(wlsRms));
  Check(NormalsUnitOutward(out, 0.9), "WLS sphere: Normals not unit and outward");
  std::cout << "WLS sphere without normals: rms " << wlsRms << "\n";
}

void TestSPHBall()
{
  const double spacing = 0.08;
  vtkNew<vtkPolyData> ball = LatticeBall(spacing, 3);
  const vtkIdType n = ball->GetNumberOfPoints();
  vtkNew<vtkMeshlessSurface> surface;
  surface->SetInputData(ball);
  surface->SetMethodToSPH();
  surface->Update();
  vtkPolyData* out = surface->GetOutput();
  CheckClosedSphere(out, "SPH ball");
  const double volume = static_cast<double>(n) * spacing * spacing * spacing;
  const double enclosed = EnclosedVolume(out);
  Check(std::fabs(enclosed - volume) < 0.05 * volume,
    "SPH ball: encloses " + std::to_string(enclosed) + ", the particles' volume is " + std::to_string(volume));
  // The isotropic colour field's surface has shallow bumps over the lattice's layers: normals within 60 degrees.
  Check(NormalsUnitOutward(out, 0.5), "SPH ball: Normals not unit and outward");
  // Velocity = position is linear: reproduced at the vertices; Mass and Density are carried over.
  vtkDataArray* velocity = out->GetPointData()->GetArray("Velocity");
  Check(velocity && velocity->GetNumberOfComponents() == 3, "SPH ball: Velocity not approximated");
  Check(out->GetPointData()->GetArray("Mass") && out->GetPointData()->GetArray("Density"),
    "SPH ball: Mass and Density not approximated");
  double worst = 0.0;
  for (vtkIdType i = 0; velocity && i < out->GetNumberOfPoints(); ++i)
  {
    double p[3], v[3];
    out->GetPoint(i, p);
    velocity->GetTuple(i, v);
    worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(p, v)));
  }
  Check(worst < 1e-6, "SPH ball: Velocity differs from the position by " + std::to_string(worst));
  auto* method = vtkStringArray::SafeDownCast(out->GetFieldData()->GetAbstractArray("SurfaceMethod"));
  Check(method && method->GetValue(0) == "SPH", "SPH ball: field data SurfaceMethod");
  std::cout << "SPH ball: " << n << " particles, " << out->GetNumberOfPolys() << " triangles, volume "
            << enclosed << " of " << volume << "\n";
}

void TestHostile()
{
  // Empty input: an empty output and a warning, no error.
  {
    vtkNew<vtkPolyData> empty;
    vtkNew<vtkMeshlessSurface> surface;
    vtkNew<vtkTest::ErrorObserver> observer;
    surface->AddObserver(vtkCommand::ErrorEvent, observer);
    surface->AddObserver(vtkCommand::WarningEvent, observer);
    surface->SetInputData(empty);
    surface->Update();
    Check(surface->GetOutput()->GetNumberOfPoints() == 0, "empty input: output not empty");
    Check(!observer->GetError() && observer->GetWarning(), "empty input: a warning expected, no error");
  }
  // Only NaN points: the same, with a warning about them.
  {
    vtkNew<vtkPoints> points;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (int i = 0; i < 10; ++i)
      points->InsertNextPoint(nan, i, 0.0);
    vtkNew<vtkPolyData> cloud;
    cloud->SetPoints(points);
    vtkNew<vtkMeshlessSurface> surface;
    vtkNew<vtkTest::ErrorObserver> observer;
    surface->AddObserver(vtkCommand::ErrorEvent, observer);
    surface->AddObserver(vtkCommand::WarningEvent, observer);
    surface->SetInputData(cloud);
    surface->Update();
    Check(surface->GetOutput()->GetNumberOfPoints() == 0, "NaN input: output not empty");
    Check(!observer->GetError() && observer->GetWarningMessage().find("NaN") != std::string::npos,
      "NaN input: a warning about NaN expected, no error: " + observer->GetWarningMessage());
  }
  // Abort from a progress observer: an empty output, no crash; the next update works again.
  {
    vtkNew<vtkPolyData> cloud = SphereCloud(5000, 5);
    vtkNew<vtkMeshlessSurface> surface;
    surface->SetInputData(cloud);
    vtkNew<vtkTest::ErrorObserver> observer;
    surface->AddObserver(vtkCommand::WarningEvent, observer);
    int progressEvents = 0;
    vtkNew<vtkCallbackCommand> abort;
    abort->SetClientData(&progressEvents);
    abort->SetCallback([](vtkObject* caller, unsigned long, void* clientData, void*) {
      auto* algorithm = static_cast<vtkMeshlessSurface*>(caller);
      if (algorithm->GetProgress() > 0.0 && algorithm->GetProgress() < 1.0)
      {
        ++*static_cast<int*>(clientData);
        algorithm->AbortExecuteOn();
      }
    });
    const unsigned long tag = surface->AddObserver(vtkCommand::ProgressEvent, abort);
    surface->Update();
    Check(progressEvents > 0, "abort: no progress reported");
    Check(surface->GetOutput()->GetNumberOfPoints() == 0, "abort: the output is not empty");
    Check(observer->GetWarningMessage().find("Aborted") != std::string::npos, "abort: no warning");
    // This VTK (ParaView 5.11) no longer clears AbortExecute when an execution starts: the caller does.
    surface->RemoveObserver(tag);
    surface->AbortExecuteOff();
    surface->Modified();
    surface->Update();
    Check(surface->GetOutput()->GetNumberOfPolys() > 1000, "abort: the next update gives no surface");
  }
  // Invalid SurfaceLevel (SPH): an error that says so, an empty output.
  for (double level : { 0.0, 1.5 })
  {
    vtkNew<vtkPolyData> ball = LatticeBall(0.2, 1);
    vtkNew<vtkMeshlessSurface> surface;
    vtkNew<vtkTest::ErrorObserver> observer;
    surface->AddObserver(vtkCommand::ErrorEvent, observer);
    surface->SetInputData(ball);
    surface->SetMethodToSPH();
    surface->SetSurfaceLevel(level);
    surface->Update();
    Check(observer->GetError() && observer->GetErrorMessage().find("level") != std::string::npos,
      "SurfaceLevel " + std::to_string(level) + ": no error naming the level: " + observer->GetErrorMessage());
    Check(surface->GetOutput()->GetNumberOfPoints() == 0, "invalid SurfaceLevel: output not empty");
  }
}
} // namespace

int TestMeshlessSurface(int, char*[])
{
  TestSphere();
  TestSPHBall();
  TestHostile();
  vtkNew<vtkMeshlessSurface> printed;
  std::ostringstream os;
  printed->Print(os);
  Check(os.str().find("SurfaceLevel: 0.5") != std::string::npos, "PrintSelf");
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
