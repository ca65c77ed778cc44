#include "vtkMeshlessNormals.h"
#include "vtkMeshFreeFilterSupport.h"

#include "vtkCharArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
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
#include "vtkSmartPointer.h"

#include "vtkMeshFreeHaloDistribution.h"
#include "vtkMeshFreePieces.h"
#include "vtkPolyData.h"

#include "Common/NeighborGrid.h"
#include "Common/Statistics.h"
#include "Surface/CloudNormals.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

vtkStandardNewMacro(vtkMeshlessNormals);

namespace
{
const char* const kNormals = "Normals";

const char* OrientationName(int orientation)
{
  static const char* const names[] = { "Auto", "Propagation", "Viewpoint", "InputNormals" };
  return orientation >= 0 && orientation < 4 ? names[orientation] : "?";
}

/// The median of the first n values whose mask is set (0 when none is), over every process of `processes` (null:
/// this one's; distributed: an exact selection, no gather).
double MaskedMedian(const meshfree::Distribution* processes, const std::vector<double>& values,
  const std::vector<unsigned char>& mask, vtkIdType n)
{
  std::vector<double> kept;
  for (size_t i = 0; i < values.size() && i < mask.size() && static_cast<vtkIdType>(i) < n; ++i)
  {
    if (mask[i])
    {
      kept.push_back(values[i]);
    }
  }
  return meshfree::GlobalMedian(processes, std::move(kept));
}

/// What a distributed run held: its piece and halo (points), the halo's radius and the attempts it took; and the
/// median neighbourhood radius of the whole cloud (field data SupportRadius).
struct HaloRun
{
  vtkIdType Held = 0;
  double Radius = 0.0;
  int Attempts = 0;
  double MedianRadius = 0.0;
};

/// The halo's first radius: this many times the distance to the k-th nearest point (below).
constexpr double HaloNeighborhoods = 8.0;

/// Distributed (collective): this rank's points with a halo from the others (vtkMeshFreeHalo), the core computing
/// its own points' results (their first `input` points), with the same bits as a serial run. referenceNormals
/// (reference orientation) is given or not on every rank alike (an empty rank passes an empty array).
bool ComputeDistributed(vtkMeshlessNormals* self, vtkMultiProcessController* controller, vtkPointSet* input,
  vtkDataArray* referenceNormals, meshfree::CloudNormalsOptions& options, meshfree::CloudNormalsResult& result,
  HaloRun& run)
{
  // This rank's points (and reference normals), with the input's global ids when it has them.
  const vtkIdType n = input->GetNumberOfPoints();
  auto mine = vtkSmartPointer<vtkPolyData>::New();
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    points->SetPoint(i, input->GetPoint(i));
  }
  mine->SetPoints(points);
  if (referenceNormals)
  {
    vtkNew<vtkDoubleArray> reference;
    reference->SetNumberOfComponents(3);
    reference->DeepCopy(referenceNormals);
    reference->SetName(kNormals);
    mine->GetPointData()->AddArray(reference);
  }
  if (vtkDataArray* ids = input->GetPointData()->GetGlobalIds())
  {
    mine->GetPointData()->SetGlobalIds(ids);
  }
  // The whole cloud's frame, and the region this rank's halo grows from (its points' box).
  const double* xyz = vtkDoubleArray::SafeDownCast(points->GetData())->GetPointer(0);
  double region[6], frame[6];
  vtkMeshFreeHalo::FiniteBounds(xyz, n, region);
  vtkMeshFreeHalo::GlobalBounds(controller, region, frame);
  vtkIdType finite = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    finite += std::isfinite(xyz[3 * i]) && std::isfinite(xyz[3 * i + 1]) && std::isfinite(xyz[3 * i + 2]) ? 1 : 0;
  }
  options.Framed = true;
  std::copy(frame, frame + 6, options.FrameBounds);
  options.FramePoints = vtkMeshFreeHalo::GlobalSum(controller, finite);

  // The halo: first as wide as a few neighbourhoods, then as wide as the computation reports it reached (its
  // Shortfall; the last attempt takes every point, which is always enough).
  const int k = std::max(3, options.Neighborhood.NeighborCount);
  double radius = HaloNeighborhoods * vtkMeshFreeHalo::GlobalMax(controller, vtkMeshFreeHalo::LocalNeighborDistance(xyz, n, k));
  if (options.Neighborhood.SupportRadius > 0.0)
  {
    radius = std::max(radius, 2.0 * options.Neighborhood.SupportRadius);
  }
  points = nullptr; // (`mine` holds them until the exchange)
  vtkNew<vtkMeshFreeHalo> halo;
  halo->SetController(controller);
  for (int attempt = 0; attempt < 4; ++attempt)
  {
    if (attempt == 3 || !std::isfinite(radius))
    {
      radius = std::numeric_limits<double>::infinity();
    }
    if (!mine)
    {
      mine = halo->CopyOwnedPoints(); // a retry: this rank's points, reference normals and global ids again
    }
    halo->Exchange(mine, region, radius);
    // This rank's points live on in the halo's output (its first ones): released here (24 bytes or more per own
    // point through the whole run, issue 24), rebuilt for a retry.
    mine = nullptr;
    run.Radius = radius;
    run.Attempts = attempt + 1;
    vtkMeshFreeHaloDistribution processes(controller, halo, region, radius);
    options.Neighborhood.Processes = &processes;
    vtkPolyData* cloud = halo->GetOutput();
    const vtkIdType held = cloud->GetNumberOfPoints();
    run.Held = held;
    const double* local = vtkDoubleArray::SafeDownCast(cloud->GetPoints()->GetData())->GetPointer(0);
    vtkDoubleArray* reference =
      referenceNormals ? vtkDoubleArray::SafeDownCast(cloud->GetPointData()->GetArray(kNormals)) : nullptr;
    const bool done = meshfree::ComputeCloudNormals(local, held, reference ? reference->GetPointer(0) : nullptr,
      options, result, attempt == 0 ? vtkMeshFreeFilterSupport::Progress(self) : meshfree::ProgressCallback());
    options.Neighborhood.Processes = nullptr;
    const bool aborted = vtkMeshFreeHalo::GlobalMax(controller, done && !result.Aborted ? 0.0 : 1.0) > 0.0;
    const double shortfall = vtkMeshFreeHalo::GlobalMax(controller, result.Shortfall);
    vtkDebugWithObjectMacro(self, "Halo radius " << radius << ": " << held << " points held, shortfall " << shortfall << ".");
    if (aborted)
    {
      result.Aborted = true;
      return false;
    }
    if (!(shortfall > 0.0) || std::isinf(radius))
    {
      run.MedianRadius = MaskedMedian(&processes, result.Radius, result.Valid, n);
      return true;
    }
    radius = std::max(radius + 1.25 * shortfall, 1.5 * radius);
  }
  return true;
}

} // namespace

vtkMeshlessNormals::vtkMeshlessNormals() = default;

int vtkMeshlessNormals::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0], 0);
  vtkPointSet* output = vtkPointSet::GetData(outputVector, 0);
  if (!input || !output)
  {
    vtkErrorMacro("Missing input or output point set.");
    return 0;
  }
  output->Initialize();

  // Under MPI (a piece of several, on several ranks) every rank takes part in every collective call below, with
  // an empty piece too, and every decision that guards one is the same on every rank.
  const bool distributed = vtkMeshFreePieces::IsDistributed(outputVector->GetInformationObject(0));
  vtkMultiProcessController* controller = distributed ? vtkMultiProcessController::GetGlobalController() : nullptr;
  const bool reporter = !distributed || controller->GetLocalProcessId() == 0; // one rank warns about the cloud

  // Validate and gather: coordinates as doubles, the input's Normals as orientation reference.
  const vtkIdType n = input->GetNumberOfPoints();
  const vtkIdType total = vtkMeshFreeHalo::GlobalSum(controller, n);
  vtkDataArray* inputNormals = input->GetPointData()->GetArray(kNormals);
  if (inputNormals && inputNormals->GetNumberOfComponents() != 3)
  {
    vtkWarningMacro("The input's point array Normals has " << inputNormals->GetNumberOfComponents()
                                                           << " components, not 3: it is not used.");
    inputNormals = nullptr;
  }
  bool haveNormals = inputNormals != nullptr;
  if (distributed)
  {
    // Used when every rank with points has them (all ranks' pieces empty: when any rank has them).
    const bool some = vtkMeshFreeHalo::GlobalMax(controller, (n > 0 || total == 0) && inputNormals ? 1.0 : 0.0) > 0;
    const bool lacking = vtkMeshFreeHalo::GlobalMax(controller, n > 0 && !inputNormals ? 1.0 : 0.0) > 0;
    if (some && lacking && reporter)
    {
      vtkWarningMacro("Some ranks' pieces have a 3-component point array Normals and others do not: it is not used.");
    }
    haveNormals = some && !lacking;
  }
  if (this->Orientation == INPUT_NORMALS && !haveNormals)
  {
    // Returning 1 keeps the executive from adding its own error: one clear message, an empty output.
    vtkErrorMacro("Orientation InputNormals needs a 3-component point array Normals on the input; the output is "
                  "empty.");
    return 1;
  }
  const bool useReference = haveNormals && (this->Orientation == AUTO || this->Orientation == INPUT_NORMALS);
  output->ShallowCopy(input);
  if (total == 0 && reporter)
  {
    vtkWarningMacro("The input has no points: nothing to compute.");
  }

  meshfree::CloudNormalsOptions options;
  options.Neighborhood.NeighborCount = this->NeighborCount;
  options.Neighborhood.SupportRadius = this->SupportRadius;
  options.Orientation = useReference ? meshfree::OrientationMode::Reference
    : this->Orientation == VIEWPOINT ? meshfree::OrientationMode::Viewpoint
                                     : meshfree::OrientationMode::Propagation;
  std::copy(this->Viewpoint, this->Viewpoint + 3, options.Viewpoint);
  options.ComputeCurvature = this->ComputeCurvature;
  options.ProjectPoints = this->ProjectPoints;
  options.ProjectionIterations = this->ProjectionIterations;
  meshfree::CloudNormalsResult result;
  bool done = false;
  HaloRun run; // distributed: what this rank held, and the whole cloud's median radius
  if (!distributed)
  {
    // Fresh memory on huge pages (Common/LargeArrays.h: at 10M points the faults of 4 KiB pages took seconds).
    meshfree::detail::Buffer<double> xyz(3 * static_cast<size_t>(n)),
      reference(useReference ? 3 * static_cast<size_t>(n) : 0);
    for (vtkIdType i = 0; i < n; ++i)
    {
      input->GetPoint(i, &xyz[3 * i]);
      if (useReference)
      {
        inputNormals->GetTuple(i, &reference[3 * i]);
      }
    }
    done = meshfree::ComputeCloudNormals(xyz.data(), n, useReference ? reference.data() : nullptr, options, result,
      vtkMeshFreeFilterSupport::Progress(this));
  }
  else
  {
    vtkNew<vtkDoubleArray> none; // an empty piece's reference: the same orientation mode as the other ranks'
    none->SetNumberOfComponents(3);
    vtkDataArray* reference = useReference ? (inputNormals ? inputNormals : none.GetPointer()) : nullptr;
    done = ComputeDistributed(this, controller, input, reference, options, result, run);
  }
  if (!done || result.Aborted)
  {
    output->Initialize();
    vtkWarningMacro("Aborted: the output is empty.");
    return 1;
  }
  const vtkIdType count = total;
  result.Invalid = vtkMeshFreeHalo::GlobalSum(controller, result.Invalid);
  result.Outliers = vtkMeshFreeHalo::GlobalSum(controller, result.Outliers);
  result.Duplicates = vtkMeshFreeHalo::GlobalSum(controller, result.Duplicates);
  if (result.Invalid > 0 && reporter)
  {
    vtkWarningMacro(<< result.Invalid << " of " << count
                    << " points have no normal (NaN/Inf coordinates, or fewer than 3 non-collinear neighbours): "
                       "their arrays are 0 and vtkValidPointMask is 0.");
  }
  vtkDebugMacro("Orientation " << OrientationName(this->Orientation) << ": " << result.Orientation.Components
                               << " connected pieces, " << result.Orientation.FlippedComponents << " turned, "
                               << result.Orientation.Ambiguous << " ambiguous points; " << result.Projected
                               << " points projected; " << result.Outliers << " outliers left out of the fits, "
                               << result.Duplicates << " exact duplicates merged.");

  // Wrap the results of this rank's own points: the first n of its local cloud, in input order.
  auto ownArray = [n](const char* name, int components, const std::vector<double>& values) {
    auto array = vtkSmartPointer<vtkDoubleArray>::New();
    array->SetName(name);
    array->SetNumberOfComponents(components);
    array->SetNumberOfTuples(n);
    meshfree::detail::AdviseHugePages(array->GetPointer(0), sizeof(double) * components * static_cast<size_t>(n));
    std::copy_n(values.data(), static_cast<size_t>(components) * n, array->GetPointer(0));
    return array;
  };
  if (this->ProjectPoints && n > 0)
  {
    vtkNew<vtkPoints> moved;
    moved->SetDataType(input->GetPoints()->GetDataType());
    moved->SetNumberOfPoints(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      moved->SetPoint(i, &result.Points[3 * i]);
    }
    output->SetPoints(moved);
  }
  vtkPointData* pd = output->GetPointData();
  pd->SetNormals(ownArray(kNormals, 3, result.Normals));
  if (this->ComputeCurvature)
  {
    pd->AddArray(ownArray("Curvature", 1, result.Curvature));
  }
  pd->AddArray(ownArray("SurfaceVariation", 1, result.SurfaceVariation));
  pd->AddArray(ownArray("OrientationConfidence", 1, result.Confidence));
  vtkNew<vtkCharArray> mask;
  mask->SetName("vtkValidPointMask");
  mask->SetNumberOfTuples(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    mask->SetValue(i, static_cast<char>(result.Valid[i] ? 1 : 0));
  }
  pd->AddArray(mask);
  pd->SetActiveScalars(this->ComputeCurvature ? "Curvature" : "OrientationConfidence");

  // Field data: of the whole cloud, the same on every rank.
  vtkFieldData* fd = output->GetFieldData();
  vtkMeshFreeFilterSupport::AddFieldValue(fd, "NoiseEstimate", result.Scale.Noise);
  vtkMeshFreeFilterSupport::AddFieldValue(
    fd, "SupportRadius", distributed ? run.MedianRadius : MaskedMedian(nullptr, result.Radius, result.Valid, n));
  vtkNew<vtkIdTypeArray> ambiguous;
  ambiguous->SetName("AmbiguousOrientations");
  ambiguous->InsertNextValue(static_cast<vtkIdType>(result.Orientation.Ambiguous));
  fd->AddArray(ambiguous);
  if (distributed)
  {
    // This rank's own, per rank: how many points it computed over (its piece and its halo).
    vtkNew<vtkIdTypeArray> local;
    local->SetName("LocalCloudPoints");
    local->InsertNextValue(run.Held);
    fd->AddArray(local);
    // -1 when the halo was the whole cloud (an infinite radius; no Inf leaves the filter).
    vtkMeshFreeFilterSupport::AddFieldValue(fd, "HaloRadius", std::isfinite(run.Radius) ? run.Radius : -1.0);
    vtkNew<vtkIdTypeArray> rounds;
    rounds->SetName("HaloAttempts");
    rounds->InsertNextValue(run.Attempts);
    fd->AddArray(rounds);
  }
  return 1;
}

void vtkMeshlessNormals::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NeighborCount: " << this->NeighborCount << "\n";
  os << indent << "SupportRadius: " << this->SupportRadius << "\n";
  os << indent << "Orientation: " << OrientationName(this->Orientation) << "\n";
  os << indent << "Viewpoint: " << this->Viewpoint[0] << ", " << this->Viewpoint[1] << ", " << this->Viewpoint[2]
     << "\n";
  os << indent << "ComputeCurvature: " << this->ComputeCurvature << "\n";
  os << indent << "ProjectPoints: " << this->ProjectPoints << "\n";
  os << indent << "ProjectionIterations: " << this->ProjectionIterations << "\n";
}
