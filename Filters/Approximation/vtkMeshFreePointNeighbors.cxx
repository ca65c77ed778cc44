#include "vtkMeshFreePointNeighbors.h"

#include "vtkCharArray.h"
#include "vtkDoubleArray.h"
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

#include "Common/NeighborGrid.h"
#include "Common/Parallel.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

vtkStandardNewMacro(vtkMeshFreePointNeighbors);
vtkCxxSetObjectMacro(vtkMeshFreePointNeighbors, Controller, vtkMultiProcessController);

vtkMeshFreePointNeighbors::vtkMeshFreePointNeighbors()
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

vtkMeshFreePointNeighbors::~vtkMeshFreePointNeighbors()
{
  this->SetController(nullptr);
}

namespace
{
/// The cloud the neighbours are searched in: serial, the input; distributed, the input and its halo, ordered by
/// global id so that the grid breaks distance ties as the serial run does. position[i]: where input point i is.
void SearchCloud(vtkMeshFreeHalo* halo, const std::vector<double>& own, std::vector<double>& cloud,
  std::vector<meshfree::Index>& position)
{
  const vtkIdType n = static_cast<vtkIdType>(own.size() / 3);
  position.resize(n);
  if (!halo)
  {
    cloud = own;
    std::iota(position.begin(), position.end(), meshfree::Index(0));
    return;
  }
  vtkPoints* points = halo->GetOutput()->GetPoints();
  const vtkIdType* ids = halo->GetGlobalIds()->GetPointer(0);
  const vtkIdType total = points->GetNumberOfPoints();
  std::vector<vtkIdType> order(total);
  std::iota(order.begin(), order.end(), vtkIdType(0));
  std::stable_sort(order.begin(), order.end(), [ids](vtkIdType a, vtkIdType b) { return ids[a] < ids[b]; });
  cloud.resize(3 * static_cast<size_t>(total));
  for (vtkIdType s = 0; s < total; ++s)
  {
    points->GetPoint(order[s], &cloud[3 * s]);
    if (order[s] < n) // the owned points come first in the halo's output, in input order
    {
      position[order[s]] = s;
    }
  }
}
} // namespace

int vtkMeshFreePointNeighbors::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPointSet* input = vtkPointSet::GetData(inputVector[0]);
  vtkPointSet* output = vtkPointSet::GetData(outputVector);
  if (!input || !output)
  {
    vtkErrorMacro("Missing input or output point set.");
    return 0;
  }
  output->ShallowCopy(input);

  const vtkIdType n = input->GetNumberOfPoints();
  vtkNew<vtkDoubleArray> meanDistance;
  meanDistance->SetName("MeanNeighborDistance");
  meanDistance->SetNumberOfTuples(n);
  vtkNew<vtkCharArray> valid;
  valid->SetName("vtkValidPointMask");
  valid->SetNumberOfTuples(n);
  vtkNew<vtkIdTypeArray> inRadius;
  inRadius->SetName("NeighborsInRadius");
  if (this->SearchRadius > 0)
  {
    inRadius->SetNumberOfTuples(n);
  }

  const int k = this->NeighborCount;
  const double radius = this->SearchRadius;
  vtkMultiProcessController* controller = this->Controller;
  const bool distributed = vtkMeshFreeHalo::IsDistributed(controller);
  const vtkIdType globalCount = vtkMeshFreeHalo::GlobalSum(controller, n); // collective
  if (globalCount == 0 && (!distributed || controller->GetLocalProcessId() == 0))
  {
    vtkWarningMacro("The input has no points: nothing to compute.");
  }

  // One copy of the coordinates as doubles: the core takes raw interleaved xyz.
  std::vector<double> xyz(static_cast<size_t>(3 * n));
  vtkIdType invalid = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    double* x = &xyz[3 * i];
    input->GetPoint(i, x);
    invalid += std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]) ? 0 : 1;
  }
  if (invalid > 0)
  {
    vtkWarningMacro(<< invalid << " of " << n
                    << " points have NaN or Inf coordinates: they are ignored and masked out.");
  }

  // Distributed: every point's k + 1 nearest (itself included) and its radius neighbours from all ranks.
  vtkNew<vtkMeshFreeHalo> halo;
  if (distributed)
  {
    halo->SetController(controller);
    halo->ShipPointDataOff();
    halo->ExchangeForKNearest(input, xyz.data(), n, k + 1, radius);
  }
  std::vector<double> cloud;
  std::vector<meshfree::Index> position;
  SearchCloud(distributed ? halo.Get() : nullptr, xyz, cloud, position);
  meshfree::NeighborGrid grid;
  grid.Build(cloud.data(), static_cast<meshfree::Index>(cloud.size() / 3));

  double* meanPtr = meanDistance->GetPointer(0);
  char* validPtr = valid->GetPointer(0);
  vtkIdType* radiusPtr = radius > 0 ? inRadius->GetPointer(0) : nullptr;
  const vtkIdType chunk = 4096;
  struct Buffers
  {
    std::vector<meshfree::Index> Ids, RadiusIds;
    std::vector<double> Dist2;
  };
  std::vector<Buffers> buffers(static_cast<size_t>(meshfree::MaxThreads()));
  for (Buffers& b : buffers)
  {
    b.Ids.resize(k + 1);
    b.Dist2.resize(k + 1);
  }
  for (vtkIdType begin = 0; begin < n; begin += chunk)
  {
    if (this->GetAbortExecute())
    {
      break;
    }
    const vtkIdType end = std::min(n, begin + chunk);
    meshfree::ParallelFor(end - begin, 256, [&](meshfree::Index b0, meshfree::Index b1) {
      Buffers& mine = buffers[static_cast<size_t>(meshfree::ThreadIndex())];
      std::vector<meshfree::Index>& ids = mine.Ids;
      std::vector<double>& dist2 = mine.Dist2;
      std::vector<meshfree::Index>& radiusIds = mine.RadiusIds;
      for (vtkIdType i = begin + b0; i < begin + b1; ++i)
      {
        const double* x = &xyz[3 * i];
        const bool finite = std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]);
        validPtr[i] = finite ? 1 : 0;
        meanPtr[i] = 0.0;
        if (radiusPtr)
        {
          radiusPtr[i] = 0;
        }
        if (!finite)
        {
          continue;
        }
        // k + 1 because the point finds itself (and any duplicates of itself) first.
        const int found = grid.FindKNearest(x, k + 1, ids.data(), dist2.data());
        double sum = 0.0;
        int used = 0;
        bool skippedSelf = false;
        for (int j = 0; j < found && used < k; ++j)
        {
          if (!skippedSelf && ids[j] == position[i])
          {
            skippedSelf = true;
            continue;
          }
          sum += std::sqrt(dist2[j]);
          ++used;
        }
        meanPtr[i] = used > 0 ? sum / used : 0.0;
        if (radiusPtr)
        {
          grid.FindWithinRadius(x, radius, radiusIds);
          radiusPtr[i] = std::max<vtkIdType>(0, static_cast<vtkIdType>(radiusIds.size()) - 1);
        }
      }
    });
    this->UpdateProgress(static_cast<double>(end) / n);
  }

  vtkPointData* pd = output->GetPointData();
  pd->AddArray(meanDistance);
  pd->AddArray(valid);
  if (radius > 0)
  {
    pd->AddArray(inRadius);
  }
  pd->SetActiveScalars("MeanNeighborDistance");
  return 1;
}

void vtkMeshFreePointNeighbors::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NeighborCount: " << this->NeighborCount << "\n";
  os << indent << "SearchRadius: " << this->SearchRadius << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
}
