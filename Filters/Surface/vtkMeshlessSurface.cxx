#include "vtkMeshlessSurface.h"
#include "vtkMeshFreeFilterSupport.h"

#include "vtkCellArray.h"
#include "vtkCharArray.h"
#include "vtkCommunicator.h"
#include "vtkDataSetAttributes.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMeshFreeHalo.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"
#include "vtkTypeInt64Array.h"

#include "vtkMeshFreeHaloDistribution.h"
#include "vtkMeshFreePieces.h"
#include "vtkMeshFreeSlabs.h"

#include "Approximation/Approximation.h"
#include "Common/LargeArrays.h"
#include "Surface/DataSupport.h"
#include "Surface/MeshTopology.h"
#include "Surface/SurfaceNormals.h"
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
/// Under MPI, the whole cloud (every rank's piece, in global id order).
struct vtkMeshlessSurface::Cloud
{
  vtkIdType Count = 0;
  std::vector<double> Points;
  std::vector<double> Normals; // empty: none given (or not wanted)
  std::vector<double> Volumes; // empty: none (SPH without Mass and Density)
  vtkIdType InvalidVolumes = 0;
  /// The other numeric point arrays, approximated at the vertices: their layout, and their values side by side
  /// in one row-major table (every component, as double).
  struct Array
  {
    std::string Name;
    int Components = 0;
    std::vector<std::string> ComponentNames; // empty strings: unnamed
  };
  std::vector<Array> Arrays;
  int Columns = 0;
  std::vector<double> Values;
  std::string ActiveScalars;
  /// Distributed: the coordinates as the halo holds them (Points then stays empty); null: Points.
  const double* View = nullptr;
  const double* Coordinates() const { return this->View ? this->View : this->Points.data(); }
};

/// What one row of the cloud holds: coordinates, then normals, volume and the arrays' values as agreed.
struct vtkMeshlessSurface::Layout
{
  bool UseNormals = false;
  bool UseVolumes = false;
  int Width = 3;
  std::vector<double> Rows; // this rank's points, one row each
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
const char* const kDistanceToData = "DistanceToData";

/// The array's fresh values advised for huge pages before they are first written (Common/LargeArrays.h: the
/// output's arrays, about 120 bytes per vertex, faulted 4 KiB pages in for a tenth of a second on the bunny).
template <class Array>
void AdviseFresh(Array* array)
{
  meshfree::detail::AdviseHugePages(array->GetVoidPointer(0),
    static_cast<size_t>(array->GetDataSize()) * static_cast<size_t>(array->GetDataTypeSize()));
}

/// Triangles as vtkPolyData: 64-bit offsets and connectivity, double points, unit outward `Normals`.
void WrapMesh(const meshfree::SurfaceMesh& mesh, vtkPolyData* output)
{
  const vtkIdType nv = mesh.NumberOfPoints();
  const vtkIdType nt = mesh.NumberOfTriangles();
  vtkNew<vtkDoubleArray> coordinates;
  coordinates->SetNumberOfComponents(3);
  coordinates->SetNumberOfTuples(nv);
  AdviseFresh(coordinates.Get());
  std::copy(mesh.Points.begin(), mesh.Points.end(), coordinates->GetPointer(0));
  vtkNew<vtkPoints> points;
  points->SetData(coordinates);

  vtkNew<vtkTypeInt64Array> offsets;
  offsets->SetNumberOfTuples(nt + 1);
  AdviseFresh(offsets.Get());
  for (vtkIdType t = 0; t <= nt; ++t)
  {
    offsets->SetValue(t, 3 * t);
  }
  vtkNew<vtkTypeInt64Array> connectivity;
  connectivity->SetNumberOfTuples(3 * nt);
  AdviseFresh(connectivity.Get());
  std::copy(mesh.Triangles.begin(), mesh.Triangles.end(), connectivity->GetPointer(0));
  vtkNew<vtkCellArray> polys;
  polys->SetData(offsets, connectivity);

  vtkNew<vtkDoubleArray> normals;
  normals->SetName(kNormals);
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(nv);
  AdviseFresh(normals.Get());
  std::copy(mesh.Normals.begin(), mesh.Normals.end(), normals->GetPointer(0));

  vtkNew<vtkDoubleArray> distance;
  distance->SetName(kDistanceToData);
  distance->SetNumberOfTuples(nv);
  AdviseFresh(distance.Get());
  if (mesh.DistanceToData.size() == static_cast<size_t>(nv))
  {
    std::copy(mesh.DistanceToData.begin(), mesh.DistanceToData.end(), distance->GetPointer(0));
  }
  else
  {
    distance->Fill(0.0);
  }

  output->SetPoints(points);
  output->SetPolys(polys);
  output->GetPointData()->SetNormals(normals);
  output->GetPointData()->AddArray(distance);
}

} // namespace

vtkMeshlessSurface::vtkMeshlessSurface() = default;

int vtkMeshlessSurface::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPointSet");
  return 1;
}

void vtkMeshlessSurface::PrepareInput(
  vtkPointSet* input, vtkMultiProcessController* controller, Cloud& cloud, Layout& rowLayout)
{
  // Under MPI every rank takes part in every collective call here, with an empty piece too, and agrees on what the
  // rows hold: an array is used when every rank with points has it.
  const vtkIdType n = input->GetNumberOfPoints();
  const bool distributed = controller != nullptr;
  const bool reporter = !distributed || controller->GetLocalProcessId() == 0;
  auto agreed = [controller, n](bool has) {
    if (!controller)
    {
      return has;
    }
    const bool some = vtkMeshFreeHalo::GlobalMax(controller, n > 0 && has ? 1.0 : 0.0) > 0;
    const bool lacking = vtkMeshFreeHalo::GlobalMax(controller, n > 0 && !has ? 1.0 : 0.0) > 0;
    return some && !lacking;
  };
  vtkPointData* pd = input->GetPointData();
  vtkDataArray* normals = nullptr;
  if (this->Method != SPH && this->UseInputNormals)
  {
    normals = pd->GetArray(kNormals);
    if (normals && normals->GetNumberOfComponents() != 3)
    {
      vtkWarningMacro("The input's point array Normals has " << normals->GetNumberOfComponents()
                                                             << " components, not 3: normals are estimated instead.");
      normals = nullptr;
    }
  }
  vtkDataArray* mass = pd->GetArray("Mass");
  vtkDataArray* density = pd->GetArray("Density");
  if (!(this->Method == SPH && mass && density && mass->GetNumberOfComponents() == 1 &&
        density->GetNumberOfComponents() == 1))
  {
    mass = density = nullptr;
  }
  const bool useNormals = agreed(normals != nullptr);
  const bool useVolumes = agreed(mass != nullptr);

  // Every other numeric point array, approximated at the vertices; its layout, as text to compare over ranks.
  std::string layout;
  for (int a = 0; a < pd->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* array = pd->GetArray(a);
    const char* name = array ? array->GetName() : nullptr;
    if (!name || std::strcmp(name, kNormals) == 0 || std::strcmp(name, kValidMask) == 0 ||
      std::strcmp(name, kDistanceToData) == 0 ||
      std::strcmp(name, vtkDataSetAttributes::GhostArrayName()) == 0)
    {
      continue;
    }
    layout += std::string(name) + '\x1f' + std::to_string(array->GetNumberOfComponents());
    for (int c = 0; c < array->GetNumberOfComponents(); ++c)
    {
      const char* componentName = array->GetComponentName(c);
      layout += '\x1f' + std::string(componentName ? componentName : "");
    }
    layout += '\x1e';
  }
  if (distributed)
  {
    // The layout of the first rank with points, checked against every other rank with points.
    const int size = controller->GetNumberOfProcesses();
    const int mine = n > 0 ? controller->GetLocalProcessId() : size;
    int root = mine;
    controller->AllReduce(&mine, &root, 1, vtkCommunicator::MIN_OP);
    if (root < size)
    {
      vtkIdType length = static_cast<vtkIdType>(layout.size());
      controller->Broadcast(&length, 1, root);
      std::vector<char> text(layout.begin(), layout.end());
      text.resize(static_cast<size_t>(length) + 1, '\0');
      controller->Broadcast(text.data(), length + 1, root);
      const std::string agreedLayout(text.data(), static_cast<size_t>(length));
      if (vtkMeshFreeHalo::GlobalMax(controller, n > 0 && layout != agreedLayout ? 1.0 : 0.0) > 0)
      {
        if (reporter)
        {
          vtkWarningMacro("The ranks' pieces have different point arrays: none is approximated at the vertices.");
        }
        layout.clear();
      }
      else
      {
        layout = agreedLayout;
      }
    }
  }
  // Parse the (agreed) layout: a rank with an empty piece may have no arrays at all.
  cloud.Arrays.clear();
  cloud.Columns = 0;
  for (size_t begin = 0; begin < layout.size();)
  {
    const size_t end = layout.find('\x1e', begin);
    std::vector<std::string> fields;
    for (size_t f = begin; f <= end;)
    {
      const size_t next = std::min(layout.find('\x1f', f), end);
      fields.push_back(layout.substr(f, next - f));
      f = next + 1;
    }
    Cloud::Array array;
    array.Name = fields[0];
    array.Components = std::stoi(fields[1]);
    array.ComponentNames.assign(fields.begin() + 2, fields.end());
    cloud.Columns += array.Components;
    cloud.Arrays.push_back(array);
    begin = end + 1;
  }
  vtkDataArray* scalars = pd->GetScalars();
  cloud.ActiveScalars = scalars && scalars->GetName() ? scalars->GetName() : "";

  // One row per point: coordinates, normals, volume, the arrays' values.
  const int width = 3 + (useNormals ? 3 : 0) + (useVolumes ? 1 : 0) + cloud.Columns;
  rowLayout.UseNormals = useNormals;
  rowLayout.UseVolumes = useVolumes;
  rowLayout.Width = width;
  std::vector<double>& rows = rowLayout.Rows;
  meshfree::detail::AssignLarge(rows, static_cast<size_t>(n) * width, 0.0);
  for (vtkIdType i = 0; i < n; ++i)
  {
    double* row = &rows[static_cast<size_t>(i) * width];
    input->GetPoint(i, row);
    row += 3;
    if (useNormals)
    {
      normals->GetTuple(i, row);
      row += 3;
    }
    if (useVolumes)
    {
      *row++ = mass->GetComponent(i, 0) / density->GetComponent(i, 0);
    }
    for (const Cloud::Array& layoutArray : cloud.Arrays)
    {
      vtkDataArray* array = pd->GetArray(layoutArray.Name.c_str());
      for (int c = 0; c < layoutArray.Components; ++c)
      {
        *row++ = array->GetComponent(i, c);
      }
    }
  }
}

namespace
{
/// Sizes the cloud's per-point arrays (all but the coordinates) for `count` points of the layout.
template <class Cloud>
void SizeCloud(Cloud& cloud, vtkIdType count, bool useNormals, bool useVolumes)
{
  cloud.Count = count;
  cloud.Normals.resize(useNormals ? 3 * static_cast<size_t>(count) : 0);
  cloud.Volumes.resize(useVolumes ? static_cast<size_t>(count) : 0);
  cloud.Values.resize(static_cast<size_t>(count) * cloud.Columns);
  cloud.InvalidVolumes = 0;
}

/// Point i's row after its coordinates (normals, volume, the arrays' values, as the layout has them) into the
/// cloud, or (GetRowTail) back out of it.
template <class Cloud>
void SetRowTail(Cloud& cloud, vtkIdType i, const double* tail)
{
  if (!cloud.Normals.empty())
  {
    std::copy_n(tail, 3, &cloud.Normals[3 * i]);
    tail += 3;
  }
  if (!cloud.Volumes.empty())
  {
    cloud.Volumes[i] = *tail++;
    cloud.InvalidVolumes += (cloud.Volumes[i] > 0.0 && std::isfinite(cloud.Volumes[i])) ? 0 : 1;
  }
  std::copy_n(tail, cloud.Columns, &cloud.Values[static_cast<size_t>(i) * cloud.Columns]);
}

template <class Cloud>
void GetRowTail(const Cloud& cloud, vtkIdType i, double* tail)
{
  if (!cloud.Normals.empty())
  {
    tail = std::copy_n(&cloud.Normals[3 * i], 3, tail);
  }
  if (!cloud.Volumes.empty())
  {
    *tail++ = cloud.Volumes[i];
  }
  std::copy_n(&cloud.Values[static_cast<size_t>(i) * cloud.Columns], cloud.Columns, tail);
}

/// The cloud's arrays from `count` rows of the layout.
template <class Cloud>
void UnpackRows(const double* rows, vtkIdType count, int width, bool useNormals, bool useVolumes, Cloud& cloud)
{
  SizeCloud(cloud, count, useNormals, useVolumes);
  meshfree::detail::ReserveLarge(cloud.Points, 3 * static_cast<size_t>(count));
  cloud.Points.resize(3 * static_cast<size_t>(count));
  for (vtkIdType i = 0; i < count; ++i)
  {
    const double* row = rows + static_cast<size_t>(i) * width;
    std::copy_n(row, 3, &cloud.Points[3 * i]);
    SetRowTail(cloud, i, row + 3);
  }
}
} // namespace

void vtkMeshlessSurface::ReportReconstruction(const Cloud& cloud, const Result& result, vtkIdType boundaryEdges)
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
  // Boundary edges need a pass over the mesh: only where the contouring or the trimming can have left some.
  const bool maybeOpen = contour.UndefinedCorners > 0 || contour.RoundLimitReached || contour.LatticeEdgeReached ||
    report.TrimmedTriangles > 0;
  meshfree::MeshTopology topology = maybeOpen && boundaryEdges < 0
    ? meshfree::ComputeMeshTopology(result.Mesh.Triangles, result.Mesh.NumberOfPoints())
    : meshfree::MeshTopology();
  if (boundaryEdges >= 0)
  {
    topology.BoundaryEdges = boundaryEdges; // the whole mesh's, counted by the caller (distributed)
  }
  if (contour.RoundLimitReached || contour.LatticeEdgeReached)
  {
    vtkWarningMacro("The surface may be incomplete ("
      << topology.BoundaryEdges << " boundary edges): "
      << (contour.RoundLimitReached ? "the contouring hit its round limit (a surface over 500 cells across)" : "")
      << (contour.RoundLimitReached && contour.LatticeEdgeReached ? "; " : "")
      << (contour.LatticeEdgeReached ? "the surface ran to the edge of the lattice's range" : "")
      << ". A larger CellSize covers it with fewer cells.");
  }
  else if (topology.BoundaryEdges > 0 && this->Method != SPH)
  {
    // Say what is true of the data, and advise only what helps.
    if (report.HolesFilled)
    {
      vtkWarningMacro("The surface is open (" << topology.BoundaryEdges
                                              << " boundary edges) although HoleFilling continued it across the "
                                                 "regions without samples.");
    }
    else if (this->HoleFilling == HOLE_FILLING_AUTO)
    {
      vtkWarningMacro("The cloud is open (its area-weighted normals cancel only to "
        << report.OpenShare << " of its area; a closed surface's cancel to 0): the surface follows the data's "
        << "border (" << topology.BoundaryEdges
        << " boundary edges). Set HoleFilling to On to close it across the regions without samples.");
    }
    else if (report.OpenShare < meshfree::SurfaceOptions().ClosedBelow)
    {
      vtkWarningMacro("The cloud encloses a volume but regions without samples leave the surface open ("
        << topology.BoundaryEdges << " boundary edges): HoleFilling (On or Auto) closes them.");
    }
  }
  else if (topology.BoundaryEdges > 0)
  {
    vtkWarningMacro("The surface is open: " << topology.BoundaryEdges << " boundary edges.");
  }
  if (report.RemovedPieces > 0)
  {
    vtkDebugMacro(<< report.RemovedPieces << " of " << report.Pieces << " pieces (" << report.RemovedTriangles
                  << " triangles) removed: fewer than NeighborCount samples support each.");
  }
  if (result.Mesh.NumberOfTriangles() == 0 && result.Report.Contour.ActiveCells == 0)
  {
    vtkWarningMacro("No surface was found in " << valid
                                               << " valid points (too few, or all collinear or coincident).");
  }
}

void vtkMeshlessSurface::AddApproximatedArrays(
  const Cloud& cloud, vtkPolyData* output, Result& result, bool reporter, vtkMultiProcessController* controller)
{
  // Every other numeric point array (Cloud::Arrays, values side by side in Cloud::Values).
  const int columns = cloud.Columns;
  const std::vector<double>& values = cloud.Values;
  const vtkIdType n = cloud.Count;
  const vtkIdType m = result.Mesh.NumberOfPoints();
  // The range of each component over the whole cloud (distributed: collective, every rank alike).
  std::vector<double> lows(static_cast<size_t>(columns), std::numeric_limits<double>::infinity());
  std::vector<double> highs(static_cast<size_t>(columns), -std::numeric_limits<double>::infinity());
  for (int c = 0; c < columns; ++c)
  {
    for (vtkIdType i = 0; i < n; ++i)
    {
      const double v = values[static_cast<size_t>(i) * columns + c];
      if (std::isfinite(v))
      {
        lows[c] = std::min(lows[c], v);
        highs[c] = std::max(highs[c], v);
      }
    }
    lows[c] = -vtkMeshFreeHalo::GlobalMax(controller, -lows[c]);
    highs[c] = vtkMeshFreeHalo::GlobalMax(controller, highs[c]);
  }
  if (cloud.Arrays.empty() || columns == 0 || m == 0)
  {
    return;
  }
  const auto start = std::chrono::steady_clock::now();

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
  approximator.SetCloud(cloud.Coordinates(), n, values.data(), columns);
  const vtkIdType excludedForValues = approximator.Report().ExcludedPoints - result.Report.InvalidPoints;
  if (excludedForValues > 0 && reporter)
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
    const double low = lows[c], high = highs[c];
    for (vtkIdType i = 0; i < m && low <= high; ++i)
    {
      double& v = results[static_cast<size_t>(i) * columns + c];
      v = valid[i] ? std::min(high, std::max(low, v)) : v;
    }
  }

  vtkPointData* outPD = output->GetPointData();
  int offset = 0;
  for (const Cloud::Array& source : cloud.Arrays)
  {
    const int nc = source.Components;
    vtkNew<vtkDoubleArray> array;
    array->SetName(source.Name.c_str());
    array->SetNumberOfComponents(nc);
    for (int c = 0; c < nc; ++c)
    {
      if (!source.ComponentNames[c].empty())
      {
        array->SetComponentName(c, source.ComponentNames[c].c_str());
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
  if (!cloud.ActiveScalars.empty() && outPD->GetArray(cloud.ActiveScalars.c_str()))
  {
    outPD->SetActiveScalars(cloud.ActiveScalars.c_str());
  }
  result.ApproximationSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int vtkMeshlessSurface::ReconstructDistributed(
  vtkPointSet* input, vtkMultiProcessController* controller, vtkPolyData* output)
{
  const int me = controller->GetLocalProcessId();
  const bool reporter = me == 0;
  Cloud cloud;
  Layout layout;
  this->PrepareInput(input, controller, cloud, layout);
  const vtkIdType n = input->GetNumberOfPoints();
  const vtkIdType total = vtkMeshFreeHalo::GlobalSum(controller, n);
  if (total == 0)
  {
    if (reporter)
    {
      vtkWarningMacro("The input has no points: no surface.");
    }
    return 1;
  }
  // This rank's rows as a point cloud (coordinates; the rest of the row as one array), with its global ids.
  vtkNew<vtkPolyData> piece;
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  const int rest = layout.Width - 3;
  auto tail = vtkSmartPointer<vtkDoubleArray>::New();
  tail->SetName("MeshFreeRow");
  tail->SetNumberOfComponents(std::max(rest, 1));
  tail->SetNumberOfTuples(n);
  std::vector<double> xyz(3 * static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    const double* row = &layout.Rows[static_cast<size_t>(i) * layout.Width];
    points->SetPoint(i, row);
    std::copy_n(row, 3, &xyz[3 * i]);
    for (int c = 0; c < rest; ++c)
    {
      tail->SetComponent(i, c, row[3 + c]);
    }
  }
  std::vector<double>().swap(layout.Rows);
  piece->SetPoints(points);
  piece->GetPointData()->AddArray(tail);
  if (vtkDataArray* ids = input->GetPointData()->GetGlobalIds())
  {
    piece->GetPointData()->SetGlobalIds(ids);
  }
  vtkIdType invalid = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    invalid += std::isfinite(xyz[3 * i]) && std::isfinite(xyz[3 * i + 1]) && std::isfinite(xyz[3 * i + 2]) ? 0 : 1;
  }
  invalid = vtkMeshFreeHalo::GlobalSum(controller, invalid);
  vtkIdType invalidVolumes = 0;
  for (vtkIdType i = 0; i < n && layout.UseVolumes; ++i)
  {
    const double v = tail->GetComponent(i, layout.UseNormals ? 3 : 0);
    invalidVolumes += v > 0.0 && std::isfinite(v) ? 0 : 1;
  }
  invalidVolumes = vtkMeshFreeHalo::GlobalSum(controller, invalidVolumes);

  // Space cut in slabs of equal shares, the points moved to their slab's rank; then a halo around each slab,
  // widened while the core reports a shortfall (the last attempt takes every point, always enough).
  const vtkMeshFreeSlabs::Partition slabs = vtkMeshFreeSlabs::Choose(controller, xyz.data(), n);
  std::vector<double>().swap(xyz);
  vtkSmartPointer<vtkPolyData> mine = vtkMeshFreeSlabs::Move(controller, piece, slabs);
  // The piece's coordinates and rows go (their moved copies live on in `mine`): held to the end, they were 32 bytes
  // per own point through the whole reconstruction (10M points on 4 ranks: 80 MB a rank, issue 24).
  piece->Initialize();
  points = nullptr;
  tail = nullptr;
  double region[6];
  slabs.Region(me, region);
  meshfree::SurfaceOptions options = this->Options();
  options.Framed = true;
  std::copy(slabs.Bounds, slabs.Bounds + 6, options.FrameBounds);
  options.FramePoints = slabs.Points;
  const vtkIdType own = mine->GetNumberOfPoints();
  const double* ownXyz = own > 0 ? vtkDoubleArray::SafeDownCast(mine->GetPoints()->GetData())->GetPointer(0) : nullptr;
  const int k = std::max(3, this->NeighborCount);
  // Normals read about 8 neighbourhood radii; the fits 3 supports (SupportScale neighbourhood radii) and a cell.
  const double rk = vtkMeshFreeHalo::GlobalMax(controller, vtkMeshFreeHalo::LocalNeighborDistance(ownXyz, own, k));
  double radius = std::max(8.0, 3.0 * this->SupportScale + 2.0) * rk;
  if (this->SupportRadius > 0.0)
  {
    radius = std::max(radius, (3.0 * this->SupportScale + 2.0) * this->SupportRadius);
  }
  else if (options.Method != meshfree::SurfaceMethod::SPH)
  {
    // Where the noise, not the density, sets the fits' support (NoiseScale x the noise radius R: a noisy cloud much
    // denser than its noise), a vertex reads about 1.5 supports (its support and the cells around it). Measured on
    // bench_scale.py's 10M-point cloud on 4 ranks: 10 r_k needed against the 8 above, so every run was made twice.
    // R is estimated here from each rank's own points (a first guess; the shortfall check below stays the judge):
    // there 0.0106 against the whole cloud's 0.0146 (0.044 needed), hence 2 supports rather than 1.5.
    meshfree::NeighborGrid ownGrid;
    ownGrid.Build(ownXyz, static_cast<meshfree::Index>(own));
    meshfree::NormalOptions scaleOptions;
    scaleOptions.NeighborCount = k;
    scaleOptions.WideNormals = false;
    const double noise = vtkMeshFreeHalo::GlobalMax(controller, meshfree::EstimateCloudScale(ownGrid, scaleOptions).Radius);
    radius = std::max(radius, 2.0 * options.NoiseScale * noise + 2.0 * rk);
  }
  vtkNew<vtkMeshFreeHalo> halo;
  halo->SetController(controller);
  Result result;
  int attempts = 0;
  vtkIdType held = 0;
  vtkIdType boundaryEdges = 0;
  double shortfall = 0.0;
  for (int attempt = 0; attempt < 4; ++attempt)
  {
    if (attempt == 3 || !std::isfinite(radius) || !(radius > 0.0))
    {
      radius = std::numeric_limits<double>::infinity();
    }
    if (!mine)
    {
      // A retry: this rank's slab points again, from the last halo's owned points (the first `own`, in order) with
      // their global ids (the halo's, kept), and their rows (the local cloud's).
      mine = halo->CopyOwnedPoints();
      vtkNew<vtkDoubleArray> rowsAgain;
      rowsAgain->SetName("MeshFreeRow");
      rowsAgain->SetNumberOfComponents(std::max(rest, 1));
      rowsAgain->SetNumberOfTuples(own);
      std::vector<double> tail(static_cast<size_t>(std::max(rest, 1)), 0.0);
      for (vtkIdType i = 0; i < own; ++i)
      {
        GetRowTail(cloud, i, tail.data());
        rowsAgain->SetTuple(i, tail.data());
      }
      mine->GetPointData()->AddArray(rowsAgain);
    }
    halo->Exchange(mine, region, radius);
    attempts = attempt + 1;
    // The slab's points live on in the halo's output (its first `own`): released here, rebuilt for a retry.
    mine = nullptr;
    vtkMeshFreeHaloDistribution processes(controller, halo, region, radius);
    processes.SetSlab(slabs.Axis, slabs.Lower(me), slabs.Upper(me));
    vtkPolyData* local = halo->GetOutput();
    held = local->GetNumberOfPoints();
    // The local cloud's arrays from the rows that travelled (the coordinates stay where the halo holds them, below),
    // then the halo's own copies of the arrays dropped (its exchange plan and points stay, for the halo updates).
    vtkDataArray* travelled = local->GetPointData()->GetArray("MeshFreeRow");
    cloud.Points.clear();
    SizeCloud(cloud, held, layout.UseNormals, layout.UseVolumes);
    std::vector<double> tail(static_cast<size_t>(std::max(rest, 1)), 0.0);
    for (vtkIdType i = 0; i < held; ++i)
    {
      travelled->GetTuple(i, tail.data());
      SetRowTail(cloud, i, tail.data());
    }
    // The coordinates are read where the halo holds them (double, as the exchange keeps them).
    vtkDoubleArray* coordinates =
      held > 0 ? vtkDoubleArray::SafeDownCast(local->GetPoints()->GetData()) : nullptr;
    if (held > 0 && !coordinates)
    {
      cloud.Points.resize(3 * static_cast<size_t>(held));
      for (vtkIdType i = 0; i < held; ++i)
      {
        local->GetPoint(i, &cloud.Points[3 * i]);
      }
    }
    cloud.View = coordinates ? coordinates->GetPointer(0) : nullptr;
    // The halo's copies of the arrays go but its global ids: the distribution's keys, read in place, and a retry's.
    vtkPointData* pd = local->GetPointData();
    for (int a = pd->GetNumberOfArrays(); a-- > 0;)
    {
      if (pd->GetAbstractArray(a) != pd->GetGlobalIds())
      {
        pd->RemoveArray(a);
      }
    }
    meshfree::SurfaceInput in;
    in.Points = cloud.Coordinates();
    in.Count = cloud.Count;
    in.Normals = cloud.Normals.empty() ? nullptr : cloud.Normals.data();
    in.Volumes = cloud.Volumes.empty() ? nullptr : cloud.Volumes.data();
    options.Processes = &processes;
    std::string error;
    // Progress is reported, but an abort is honoured only after the core: every rank must go through its
    // collective steps (an abort request reaches the ranks at different moments, if at all).
    const meshfree::ProgressCallback progress = [this](double f) {
      this->UpdateProgress(0.9 * f);
      return true;
    };
    const bool done = meshfree::ReconstructSurface(
      in, options, result.Mesh, result.Report, error, attempt == 0 ? progress : meshfree::ProgressCallback());
    options.Processes = nullptr;
    if (!done && !result.Report.Aborted)
    {
      vtkErrorMacro("Invalid settings: " << error << " The output is empty.");
      return 1;
    }
    if (vtkMeshFreeHalo::GlobalMax(controller, done && !result.Report.Aborted && !this->GetAbortExecute() ? 0.0 : 1.0) > 0.0)
    {
      vtkWarningMacro("Aborted: the output is empty.");
      return 1;
    }
    shortfall = vtkMeshFreeHalo::GlobalMax(controller, result.Report.Shortfall);
    vtkDebugMacro("Halo radius " << radius << ": " << held << " points held, shortfall " << shortfall << ".");
    if (!(shortfall > 0.0) || std::isinf(radius))
    {
      boundaryEdges = meshfree::BoundaryEdges(result.Mesh, 2.0 * result.Report.CellSize, &processes);
      break;
    }
    radius = std::max(radius + 1.25 * shortfall, 1.5 * radius);
  }

  // Report the whole cloud's counts (rank 0), wrap this rank's part, approximate the arrays at its vertices.
  meshfree::SurfaceReport& report = result.Report;
  report.InvalidPoints = invalid;
  report.Duplicates = vtkMeshFreeHalo::GlobalSum(controller, report.Duplicates);
  report.Outliers = vtkMeshFreeHalo::GlobalSum(controller, report.Outliers);
  report.PointsWithoutNormal = vtkMeshFreeHalo::GlobalSum(controller, report.PointsWithoutNormal);
  report.TrimmedTriangles = vtkMeshFreeHalo::GlobalSum(controller, report.TrimmedTriangles);
  report.Contour.ActiveCells = vtkMeshFreeHalo::GlobalSum(controller, report.Contour.ActiveCells);
  report.Contour.UndefinedCorners = vtkMeshFreeHalo::GlobalSum(controller, report.Contour.UndefinedCorners);
  const vtkIdType triangles = vtkMeshFreeHalo::GlobalSum(controller, result.Mesh.NumberOfTriangles());
  if (reporter)
  {
    Cloud whole;
    whole.Count = total;
    whole.InvalidVolumes = invalidVolumes;
    Result summary;
    summary.Report = report;
    summary.Report.Contour.ActiveCells = triangles > 0 ? report.Contour.ActiveCells : 0;
    this->ReportReconstruction(whole, summary, boundaryEdges);
  }
  WrapMesh(result.Mesh, output);
  this->AddApproximatedArrays(cloud, output, result, reporter, controller);
  if (result.Aborted)
  {
    output->Initialize();
    vtkWarningMacro("Aborted: the output is empty.");
    return 1;
  }
  this->AddFieldData(output, result);
  vtkFieldData* fd = output->GetFieldData();
  vtkNew<vtkTypeInt64Array> local;
  local->SetName("LocalCloudPoints");
  local->InsertNextValue(held);
  fd->AddArray(local);
  // -1 when the halo was the whole cloud (an infinite radius; no Inf leaves the filter).
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "HaloRadius", std::isfinite(radius) ? radius : -1.0);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "HaloAttempts", attempts);
  // The halo width the last attempt needed: its radius less the slack every computation left (or plus its shortfall);
  // 0 when not known (no computation measured it, or the halo was the whole cloud).
  const double needed = radius + shortfall;
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "HaloNeeded", std::isfinite(needed) ? needed : 0.0);
  return 1;
}

meshfree::SurfaceOptions vtkMeshlessSurface::Options() const
{
  meshfree::SurfaceOptions options;
  options.Method = static_cast<meshfree::SurfaceMethod>(this->Method);
  options.NeighborCount = this->NeighborCount;
  options.SupportRadius = this->SupportRadius;
  options.SupportScale = this->SupportScale;
  options.CellSize = this->CellSize;
  options.Level = this->SurfaceLevel;
  options.Anisotropic = this->AnisotropicKernels;
  options.ProjectVertices = this->ProjectVertices;
  options.HoleFilling = static_cast<meshfree::HoleFillingMode>(this->HoleFilling);
  return options;
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

  // Under MPI (a piece of several, on several ranks): each rank its slab of space and a halo (see the class doc).
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  if (vtkMeshFreePieces::IsDistributed(outInfo))
  {
    return this->ReconstructDistributed(input, vtkMultiProcessController::GetGlobalController(), output);
  }

  // Validate.
  Cloud cloud;
  Layout layout;
  this->PrepareInput(input, nullptr, cloud, layout);
  UnpackRows(layout.Rows.data(), input->GetNumberOfPoints(), layout.Width, layout.UseNormals, layout.UseVolumes, cloud);
  std::vector<double>().swap(layout.Rows);
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
  const meshfree::SurfaceOptions options = this->Options();
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
  WrapMesh(result.Mesh, output);
  this->AddApproximatedArrays(cloud, output, result, true);
  if (result.Aborted)
  {
    output->Initialize();
    vtkWarningMacro("Aborted: the output is empty.");
    return 1;
  }

  this->AddFieldData(output, result);
  return 1;
}

void vtkMeshlessSurface::AddFieldData(vtkPolyData* output, const Result& result)
{
  const meshfree::SurfaceOptions options = this->Options();
  vtkFieldData* fd = output->GetFieldData();
  vtkNew<vtkStringArray> method;
  method->SetName("SurfaceMethod");
  method->InsertNextValue(meshfree::SurfaceMethodName(options.Method));
  fd->AddArray(method);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "CellSize", result.Report.CellSize);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "SupportRadius", result.Report.SupportRadius);
  if (options.Method != meshfree::SurfaceMethod::SPH)
  {
    vtkMeshFreeFilterSupport::AddFieldValue(fd, "OpenShare", result.Report.OpenShare);
    vtkMeshFreeFilterSupport::AddFieldValue(fd, "HolesFilled", result.Report.HolesFilled ? 1.0 : 0.0);
  }
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "SetupSeconds", result.Report.SetupSeconds);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "ContourSeconds", result.Report.ContourSeconds);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "ProjectionSeconds", result.Report.ProjectionSeconds);
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "ApproximationSeconds", result.ApproximationSeconds);
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
  os << indent << "HoleFilling: " << this->HoleFilling << "\n";
}
