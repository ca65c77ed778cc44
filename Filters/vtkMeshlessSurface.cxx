#include "vtkMeshlessSurface.h"
#include "vtkMeshFreeFilterSupport.h"

#include "vtkCellArray.h"
#include "vtkCharArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"
#include "vtkTypeInt64Array.h"

#include "Approximation/Approximation.h"
#include "Surface/MeshTopology.h"
#include "Surface/SurfaceReconstruction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkMeshlessSurface);

/// The input as the core takes it: interleaved doubles, optional normals and SPH volumes.
struct vtkMeshlessSurface::Cloud
{
  vtkIdType Count = 0;
  std::vector<double> Points;
  std::vector<double> Normals; // empty: none given (or not wanted)
  std::vector<double> Volumes; // empty: none (SPH without Mass and Density)
  vtkIdType InvalidVolumes = 0;
};

/// What the core returned, and what the VTK layer added.
struct vtkMeshlessSurface::Result
{
  meshfree::SurfaceMesh Mesh;
  meshfree::SurfaceReport Report;
  double ApproximationSeconds = 0.0;
  bool Aborted = false;
};

namespace
{
const char* const kNormals = "Normals";
const char* const kValidMask = "vtkValidPointMask";

/// Triangles as vtkPolyData: 64-bit offsets and connectivity, double points, unit outward `Normals`.
void WrapMesh(const meshfree::SurfaceMesh& mesh, vtkPolyData* output)
{
  const vtkIdType nv = mesh.NumberOfPoints();
  const vtkIdType nt = mesh.NumberOfTriangles();
  vtkNew<vtkDoubleArray> coordinates;
  coordinates->SetNumberOfComponents(3);
  coordinates->SetNumberOfTuples(nv);
  std::copy(mesh.Points.begin(), mesh.Points.end(), coordinates->GetPointer(0));
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);

  vtkNew<vtkTypeInt64Array> offsets;
  offsets->SetNumberOfTuples(nt + 1);
  for (vtkIdType t = 0; t <= nt; ++t)
  {
    offsets->SetValue(t, 3 * t);
  }
  vtkNew<vtkTypeInt64Array> connectivity;
  connectivity->SetNumberOfTuples(3 * nt);
  std::copy(mesh.Triangles.begin(), mesh.Triangles.end(), connectivity->GetPointer(0));
  vtkNew<vtkCellArray> polys;
  polys->SetData(offsets, connectivity);

  vtkNew<vtkDoubleArray> normals;
  normals->SetName(kNormals);
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(nv);
  std::copy(mesh.Normals.begin(), mesh.Normals.end(), normals->GetPointer(0));

  output->SetPoints(points);
  output->SetPolys(polys);
  output->GetPointData()->SetNormals(normals);
}
} // namespace

vtkMeshlessSurface::vtkMeshlessSurface() = default;

int vtkMeshlessSurface::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return 1;
}

void vtkMeshlessSurface::GatherInput(vtkPointSet* input, Cloud& cloud)
{
  const vtkIdType n = input->GetNumberOfPoints();
  cloud.Count = n;
  cloud.Points.resize(3 * static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    input->GetPoint(i, &cloud.Points[3 * i]);
  }
  vtkPointData* pd = input->GetPointData();
  if (this->Method != SPH && this->UseInputNormals)
  {
    if (vtkDataArray* normals = pd->GetArray(kNormals))
    {
      if (normals->GetNumberOfComponents() == 3)
      {
        cloud.Normals.resize(3 * static_cast<size_t>(n));
        for (vtkIdType i = 0; i < n; ++i)
        {
          normals->GetTuple(i, &cloud.Normals[3 * i]);
        }
      }
      else
      {
        vtkWarningMacro("The input's point array Normals has " << normals->GetNumberOfComponents()
                                                               << " components, not 3: normals are estimated instead.");
      }
    }
  }
  vtkDataArray* mass = pd->GetArray("Mass");
  vtkDataArray* density = pd->GetArray("Density");
  if (this->Method == SPH && mass && density && mass->GetNumberOfComponents() == 1 &&
    density->GetNumberOfComponents() == 1)
  {
    cloud.Volumes.resize(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      cloud.Volumes[i] = mass->GetComponent(i, 0) / density->GetComponent(i, 0);
      cloud.InvalidVolumes += (cloud.Volumes[i] > 0.0 && std::isfinite(cloud.Volumes[i])) ? 0 : 1;
    }
  }
}

void vtkMeshlessSurface::ReportReconstruction(const Cloud& cloud, const Result& result)
{
  const meshfree::SurfaceReport& report = result.Report;
  const vtkIdType valid = cloud.Count - report.InvalidPoints;
  if (report.InvalidPoints > 0)
  {
    vtkWarningMacro(<< report.InvalidPoints << " of " << cloud.Count
                    << " input points have NaN/Inf coordinates: they are ignored.");
  }
  if (valid == 0)
  {
    vtkWarningMacro("The input has no valid points: no surface.");
    return;
  }
  if (cloud.InvalidVolumes > 0)
  {
    vtkWarningMacro(<< cloud.InvalidVolumes << " of " << cloud.Count
                    << " particles have a non-positive or non-finite Mass / Density: they get the mean volume.");
  }
  if (this->Method != SPH)
  {
    if (report.Outliers + report.Duplicates > 0)
    {
      vtkDebugMacro(<< report.Outliers << " outliers left out of the fits, " << report.Duplicates
                    << " exact duplicates merged.");
    }
    if (report.NormalsEstimated)
    {
      vtkDebugMacro("Normals estimated from the points (no 3-component input Normals, or UseInputNormals off); "
        << report.Orientation.Ambiguous << " orientations were ambiguous.");
    }
    if (report.PointsWithoutNormal > 0)
    {
      const char* why = report.NormalsEstimated
        ? "degenerate neighbourhood: collinear or coincident points"
        : "zero or NaN in the input's Normals, or no neighbourhood to fit over";
      vtkWarningMacro(<< report.PointsWithoutNormal << " of " << valid << " points have no valid normal (" << why
                      << "): they are ignored by the surface fits.");
    }
  }
  if (report.CellSizeEnlarged)
  {
    vtkWarningMacro("CellSize enlarged to " << report.CellSize
                                            << ": the lattice would need more than 2^21 cells along an axis.");
  }
  const meshfree::ContourReport& contour = report.Contour;
  if (contour.UndefinedCorners > 0 || contour.RoundLimitReached || contour.LatticeEdgeReached)
  {
    const meshfree::MeshTopology topology =
      meshfree::ComputeMeshTopology(result.Mesh.Triangles, result.Mesh.NumberOfPoints());
    if (topology.BoundaryEdges > 0 || contour.RoundLimitReached || contour.LatticeEdgeReached)
    {
      vtkWarningMacro("The surface is open: "
        << topology.BoundaryEdges << " boundary edges (" << contour.UndefinedCorners
        << " lattice corners had too few points within the fits' support"
        << (contour.RoundLimitReached ? "; the contouring hit its round limit" : "")
        << (contour.LatticeEdgeReached ? "; the lattice's range was reached" : "")
        << "): raise SupportScale or NeighborCount.");
    }
  }
  if (result.Mesh.NumberOfTriangles() == 0)
  {
    vtkWarningMacro("No surface was found in " << valid
                                               << " valid points (too few, or all collinear or coincident).");
  }
}

void vtkMeshlessSurface::AddApproximatedArrays(
  vtkPointSet* input, const Cloud& cloud, vtkPolyData* output, Result& result)
{
  // Every other numeric point array, side by side in one row-major table (every component, as double).
  vtkPointData* inPD = input->GetPointData();
  std::vector<vtkDataArray*> selected;
  int columns = 0;
  for (int a = 0; a < inPD->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* array = inPD->GetArray(a);
    const char* name = array ? array->GetName() : nullptr;
    if (!name || std::strcmp(name, kNormals) == 0 || std::strcmp(name, kValidMask) == 0)
    {
      continue;
    }
    selected.push_back(array);
    columns += array->GetNumberOfComponents();
  }
  const vtkIdType n = cloud.Count;
  const vtkIdType m = result.Mesh.NumberOfPoints();
  if (selected.empty() || columns == 0 || m == 0)
  {
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  std::vector<double> values(static_cast<size_t>(n) * columns);
  for (vtkIdType i = 0; i < n; ++i)
  {
    double* row = &values[static_cast<size_t>(i) * columns];
    for (vtkDataArray* array : selected)
    {
      for (int c = 0; c < array->GetNumberOfComponents(); ++c)
      {
        *row++ = array->GetComponent(i, c);
      }
    }
  }

  meshfree::ApproximationOptions options;
  options.Method = meshfree::ApproximationMethod::MLS;
  options.Degree = 1;
  options.NeighborCount = this->NeighborCount;
  meshfree::Approximator approximator;
  if (!approximator.SetOptions(options))
  {
    vtkWarningMacro("The point arrays are not approximated: " << approximator.Error());
    return;
  }
  approximator.SetCloud(cloud.Points.data(), n, values.data(), columns);
  const vtkIdType excludedForValues = approximator.Report().ExcludedPoints - result.Report.InvalidPoints;
  if (excludedForValues > 0)
  {
    vtkWarningMacro(<< excludedForValues
                    << " input points have NaN/Inf in a point array: they are left out of the vertices' values.");
  }
  std::vector<double> results(static_cast<size_t>(m) * columns);
  std::vector<unsigned char> valid(m, 0);
  meshfree::ApproximationOutput out;
  out.Values = results.data();
  out.Valid = valid.data();
  approximator.Evaluate(result.Mesh.Points.data(), m, out, vtkMeshFreeFilterSupport::Progress(this, 0.9, 1.0));
  if (approximator.Report().Aborted)
  {
    result.Aborted = true;
    return;
  }
  if (approximator.Report().Masked > 0)
  {
    vtkWarningMacro(<< approximator.Report().Masked << " of " << m
                    << " vertices could not be given the point arrays' values (no usable fit): they get 0 and "
                       "vtkValidPointMask = 0.");
  }

  // A degree-1 fit extrapolates where a point-set surface bridges a gap in the data (a scan's intensity in
  // [0, 1] came out in [-0.82, 1.24]): each component is kept within the range of its input values. A fluid's
  // surface stays within the kernel radius of its particles, so its values keep the linear extrapolation.
  for (int c = 0; c < columns && this->Method != SPH; ++c)
  {
    double low = std::numeric_limits<double>::infinity(), high = -low;
    for (vtkIdType i = 0; i < n; ++i)
    {
      const double v = values[static_cast<size_t>(i) * columns + c];
      if (std::isfinite(v))
      {
        low = std::min(low, v);
        high = std::max(high, v);
      }
    }
    for (vtkIdType i = 0; i < m && low <= high; ++i)
    {
      double& v = results[static_cast<size_t>(i) * columns + c];
      v = valid[i] ? std::min(high, std::max(low, v)) : v;
    }
  }

  vtkPointData* outPD = output->GetPointData();
  int offset = 0;
  for (vtkDataArray* source : selected)
  {
    const int nc = source->GetNumberOfComponents();
    vtkNew<vtkDoubleArray> array;
    array->SetName(source->GetName());
    array->SetNumberOfComponents(nc);
    for (int c = 0; c < nc; ++c)
    {
      if (const char* componentName = source->GetComponentName(c))
      {
        array->SetComponentName(c, componentName);
      }
    }
    array->SetNumberOfTuples(m);
    double* dst = array->GetPointer(0);
    for (vtkIdType i = 0; i < m; ++i)
    {
      std::copy_n(&results[static_cast<size_t>(i) * columns + offset], nc, dst + i * nc);
    }
    offset += nc;
    outPD->AddArray(array);
  }
  vtkNew<vtkCharArray> mask;
  mask->SetName(kValidMask);
  mask->SetNumberOfTuples(m);
  for (vtkIdType i = 0; i < m; ++i)
  {
    mask->SetValue(i, static_cast<char>(valid[i]));
  }
  outPD->AddArray(mask);
  if (inPD->GetScalars() && inPD->GetScalars()->GetName() && outPD->GetArray(inPD->GetScalars()->GetName()))
  {
    outPD->SetActiveScalars(inPD->GetScalars()->GetName());
  }
  result.ApproximationSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int vtkMeshlessSurface::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0], 0);
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  if (!input || !output)
  {
    vtkErrorMacro("Missing input point set or output.");
    return 0;
  }
  output->Initialize();

  // Validate and gather.
  Cloud cloud;
  this->GatherInput(input, cloud);
  if (cloud.Count == 0)
  {
    vtkWarningMacro("The input has no points: no surface.");
    return 1;
  }

  // Reconstruct.
  meshfree::SurfaceInput in;
  in.Points = cloud.Points.data();
  in.Count = cloud.Count;
  in.Normals = cloud.Normals.empty() ? nullptr : cloud.Normals.data();
  in.Volumes = cloud.Volumes.empty() ? nullptr : cloud.Volumes.data();
  meshfree::SurfaceOptions options;
  options.Method = static_cast<meshfree::SurfaceMethod>(this->Method);
  options.NeighborCount = this->NeighborCount;
  options.SupportRadius = this->SupportRadius;
  options.SupportScale = this->SupportScale;
  options.CellSize = this->CellSize;
  options.Level = this->SurfaceLevel;
  options.Anisotropic = this->AnisotropicKernels;
  options.ProjectVertices = this->ProjectVertices;
  Result result;
  std::string error;
  if (!meshfree::ReconstructSurface(in, options, result.Mesh, result.Report, error, vtkMeshFreeFilterSupport::Progress(this, 0.0, 0.9)))
  {
    if (result.Report.Aborted)
    {
      vtkWarningMacro("Aborted: the output is empty.");
      return 1;
    }
    // Returning 1 keeps the executive from adding its own error: one clear message, an empty output.
    vtkErrorMacro("Invalid settings: " << error << " The output is empty.");
    return 1;
  }
  this->ReportReconstruction(cloud, result);

  // Wrap the mesh, then approximate the input's arrays at its vertices.
  WrapMesh(result.Mesh, output);
  this->AddApproximatedArrays(input, cloud, output, result);
  if (result.Aborted)
  {
    output->Initialize();
    vtkWarningMacro("Aborted: the output is empty.");
    return 1;
  }

  vtkFieldData* fd = output->GetFieldData();
  vtkNew<vtkStringArray> method;
  method->SetName("SurfaceMethod");
  method->InsertNextValue(meshfree::SurfaceMethodName(options.Method));
  fd->AddArray(method);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "CellSize", result.Report.CellSize);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "SupportRadius", result.Report.SupportRadius);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "SetupSeconds", result.Report.SetupSeconds);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "ContourSeconds", result.Report.ContourSeconds);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "ProjectionSeconds", result.Report.ProjectionSeconds);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "ApproximationSeconds", result.ApproximationSeconds);
  return 1;
}

void vtkMeshlessSurface::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Method: " << meshfree::SurfaceMethodName(static_cast<meshfree::SurfaceMethod>(this->Method))
     << "\n";
  os << indent << "NeighborCount: " << this->NeighborCount << "\n";
  os << indent << "SupportRadius: " << this->SupportRadius << "\n";
  os << indent << "CellSize: " << this->CellSize << "\n";
  os << indent << "SupportScale: " << this->SupportScale << "\n";
  os << indent << "SurfaceLevel: " << this->SurfaceLevel << "\n";
  os << indent << "AnisotropicKernels: " << this->AnisotropicKernels << "\n";
  os << indent << "ProjectVertices: " << this->ProjectVertices << "\n";
  os << indent << "UseInputNormals: " << this->UseInputNormals << "\n";
}
