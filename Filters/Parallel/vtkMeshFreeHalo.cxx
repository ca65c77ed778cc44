// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMeshFreeHalo.h"

#include "vtkCommunicator.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkMultiProcessController.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include "Common/NeighborGrid.h"
#include "Common/Statistics.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkMeshFreeHalo);
vtkCxxSetObjectMacro(vtkMeshFreeHalo, Controller, vtkMultiProcessController);

namespace
{
constexpr int HaloTag = 31407;
constexpr const char* DefaultGlobalIdsName = "GlobalPointIds";

/// Squared distance from x, a finite position, to the box b (0 inside).
double SquaredDistanceToBox(const double x[3], const double b[6])
{
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    const double below = b[2 * a] - x[a];
    const double above = x[a] - b[2 * a + 1];
    const double d = below > 0.0 ? below : (above > 0.0 ? above : 0.0);
    d2 += d * d;
  }
  return d2;
}

bool IsEmptyBox(const double b[6])
{
  return !(b[0] <= b[1] && b[2] <= b[3] && b[4] <= b[5]);
}

/// Partner of `rank` in round `round` of a round-robin tournament over `size` ranks (circle method; -1: idle).
/// Every round pairs each rank with at most one other, so pairwise blocking exchanges cannot deadlock.
int TournamentPartner(int rank, int round, int size)
{
  const int m = size + (size % 2); // players, with a dummy when size is odd
  int partner;
  if (rank == m - 1)
  {
    partner = 0;
    while ((2 * partner) % (m - 1) != round % (m - 1))
    {
      ++partner;
    }
  }
  else
  {
    partner = ((round - rank) % (m - 1) + (m - 1)) % (m - 1);
    if (partner == rank)
    {
      partner = m - 1;
    }
  }
  return partner < size ? partner : -1;
}

/// The tuples `ids` of every array of `from` into `to`, global ids included.
void ExtractArrays(vtkPointData* from, vtkIdList* ids, vtkPointData* to)
{
  for (int a = 0; a < from->GetNumberOfArrays(); ++a)
  {
    vtkAbstractArray* array = from->GetAbstractArray(a);
    vtkSmartPointer<vtkAbstractArray> part = vtkSmartPointer<vtkAbstractArray>::Take(array->NewInstance());
    part->SetName(array->GetName());
    part->SetNumberOfComponents(array->GetNumberOfComponents());
    part->SetNumberOfTuples(ids->GetNumberOfIds()); // GetTuples fills, it does not allocate
    array->GetTuples(ids, part);
    to->AddArray(part);
  }
  to->SetGlobalIds(vtkDataArray::SafeDownCast(to->GetAbstractArray(from->GetGlobalIds()->GetName())));
}
} // namespace

vtkMeshFreeHalo::vtkMeshFreeHalo()
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
  this->Output = vtkSmartPointer<vtkPolyData>::New();
}

vtkMeshFreeHalo::~vtkMeshFreeHalo()
{
  this->SetController(nullptr);
}

bool vtkMeshFreeHalo::IsDistributed(vtkMultiProcessController* controller)
{
  return controller && controller->GetNumberOfProcesses() > 1;
}

void vtkMeshFreeHalo::FiniteBounds(const double* xyz, vtkIdType n, double bounds[6])
{
  for (int a = 0; a < 3; ++a)
  {
    bounds[2 * a] = VTK_DOUBLE_MAX;
    bounds[2 * a + 1] = -VTK_DOUBLE_MAX;
  }
  for (vtkIdType i = 0; i < n; ++i)
  {
    const double* x = xyz + 3 * i;
    if (!(std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2])))
    {
      continue;
    }
    for (int a = 0; a < 3; ++a)
    {
      bounds[2 * a] = std::min(bounds[2 * a], x[a]);
      bounds[2 * a + 1] = std::max(bounds[2 * a + 1], x[a]);
    }
  }
}

void vtkMeshFreeHalo::GlobalBounds(vtkMultiProcessController* controller, const double local[6], double global[6])
{
  // Reduce (-min, max) with one MAX so that a single collective call does it.
  double mine[6];
  for (int a = 0; a < 3; ++a)
  {
    const bool empty = !(local[2 * a] <= local[2 * a + 1]);
    mine[2 * a] = empty ? -VTK_DOUBLE_MAX : -local[2 * a];
    mine[2 * a + 1] = empty ? -VTK_DOUBLE_MAX : local[2 * a + 1];
  }
  double all[6];
  std::copy(mine, mine + 6, all);
  if (vtkMeshFreeHalo::IsDistributed(controller))
  {
    controller->AllReduce(mine, all, 6, vtkCommunicator::MAX_OP);
  }
  for (int a = 0; a < 3; ++a)
  {
    global[2 * a] = all[2 * a] == -VTK_DOUBLE_MAX ? VTK_DOUBLE_MAX : -all[2 * a];
    global[2 * a + 1] = all[2 * a + 1];
  }
}

vtkIdType vtkMeshFreeHalo::GlobalSum(vtkMultiProcessController* controller, vtkIdType value)
{
  vtkIdType sum = value;
  if (vtkMeshFreeHalo::IsDistributed(controller))
  {
    controller->AllReduce(&value, &sum, 1, vtkCommunicator::SUM_OP);
  }
  return sum;
}

double vtkMeshFreeHalo::GlobalMax(vtkMultiProcessController* controller, double value)
{
  double result = value;
  if (vtkMeshFreeHalo::IsDistributed(controller))
  {
    controller->AllReduce(&value, &result, 1, vtkCommunicator::MAX_OP);
  }
  return result;
}

vtkPolyData* vtkMeshFreeHalo::GetOutput()
{
  return this->Output;
}

vtkIdTypeArray* vtkMeshFreeHalo::GetGlobalIds()
{
  return vtkIdTypeArray::SafeDownCast(this->Output->GetPointData()->GetGlobalIds());
}

vtkSmartPointer<vtkPolyData> vtkMeshFreeHalo::CopyOwnedPoints()
{
  auto owned = vtkSmartPointer<vtkPolyData>::New();
  vtkPolyData* out = this->Output;
  const vtkIdType n = out ? this->NumberOfOwnedPoints : 0;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    points->SetPoint(i, out->GetPoint(i));
  }
  owned->SetPoints(points);
  vtkPointData* from = out ? out->GetPointData() : nullptr;
  for (int a = 0; from && a < from->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* array = from->GetArray(a);
    const char* name = array ? array->GetName() : nullptr;
    if (!array || (name && !strcmp(name, vtkDataSetAttributes::GhostArrayName())))
    {
      continue;
    }
    vtkSmartPointer<vtkDataArray> copy = vtk::TakeSmartPointer(array->NewInstance());
    copy->SetName(name);
    copy->SetNumberOfComponents(array->GetNumberOfComponents());
    copy->SetNumberOfTuples(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      copy->SetTuple(i, i, array);
    }
    if (array == from->GetGlobalIds())
    {
      owned->GetPointData()->SetGlobalIds(copy);
    }
    else
    {
      owned->GetPointData()->AddArray(copy);
    }
  }
  return owned;
}

vtkSmartPointer<vtkPolyData> vtkMeshFreeHalo::OwnedCloud(vtkPointSet* local)
{
  // Collective: the id offsets need every rank's count.
  const vtkIdType n = local ? local->GetNumberOfPoints() : 0;
  vtkMultiProcessController* controller = this->Controller;
  const bool distributed = vtkMeshFreeHalo::IsDistributed(controller);
  const int size = distributed ? controller->GetNumberOfProcesses() : 1;
  const int rank = distributed ? controller->GetLocalProcessId() : 0;
  std::vector<vtkIdType> counts(size, n);
  if (distributed)
  {
    controller->AllGather(&n, counts.data(), 1);
  }
  const vtkIdType offset = std::accumulate(counts.begin(), counts.begin() + rank, vtkIdType(0));
  this->NumberOfGlobalPoints = std::accumulate(counts.begin(), counts.end(), vtkIdType(0));

  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    double x[3];
    local->GetPoint(i, x);
    points->SetPoint(i, x);
  }
  cloud->SetPoints(points);

  vtkPointData* in = local ? local->GetPointData() : nullptr;
  vtkDataArray* inputIds = in ? in->GetGlobalIds() : nullptr;
  const bool integral = inputIds && inputIds->GetDataType() != VTK_FLOAT && inputIds->GetDataType() != VTK_DOUBLE;
  if (inputIds && (inputIds->GetNumberOfComponents() != 1 || !integral))
  {
    vtkWarningMacro("The input's GlobalIds array is not one integer component: ids are generated instead.");
    inputIds = nullptr;
  }
  vtkNew<vtkIdTypeArray> ids;
  ids->SetName(inputIds && inputIds->GetName() ? inputIds->GetName() : DefaultGlobalIdsName);
  ids->SetNumberOfTuples(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    ids->SetValue(i, inputIds ? static_cast<vtkIdType>(inputIds->GetTuple1(i)) : offset + i);
  }
  vtkPointData* out = cloud->GetPointData();
  if (this->ShipPointData && in)
  {
    for (int a = 0; a < in->GetNumberOfArrays(); ++a)
    {
      vtkAbstractArray* array = in->GetAbstractArray(a);
      const char* name = array->GetName();
      if (!name || array == inputIds || !strcmp(name, vtkDataSetAttributes::GhostArrayName()) ||
        !strcmp(name, ids->GetName()))
      {
        continue;
      }
      out->AddArray(array);
    }
  }
  out->AddArray(ids);
  out->SetGlobalIds(ids);
  return cloud;
}

int vtkMeshFreeHalo::Exchange(vtkPointSet* local, const double region[6], double radius)
{
  int status = 1;
  if (std::isnan(radius) || radius < 0.0)
  {
    vtkErrorMacro("Halo radius " << radius << " is negative or NaN: no halo for this rank.");
    radius = 0.0;
    status = 0;
  }
  vtkSmartPointer<vtkPolyData> owned = this->OwnedCloud(local);
  const vtkIdType nOwned = owned->GetNumberOfPoints();
  this->NumberOfOwnedPoints = nOwned;
  this->Radius = radius;
  this->NumberOfRounds = 1;
  vtkMultiProcessController* controller = this->Controller;
  if (!vtkMeshFreeHalo::IsDistributed(controller))
  {
    this->Output = owned;
    vtkNew<vtkUnsignedCharArray> ghost;
    ghost->SetName(vtkDataSetAttributes::GhostArrayName());
    ghost->SetNumberOfTuples(nOwned);
    ghost->FillValue(0);
    this->Output->GetPointData()->AddArray(ghost);
    return status;
  }
  const int size = controller->GetNumberOfProcesses();
  const int rank = controller->GetLocalProcessId();
  this->Sent.assign(size, std::vector<vtkIdType>());
  this->Received.assign(size, std::vector<vtkIdType>());
  std::vector<int> sender; // per received message: the partner

  // Every rank's request: its box and radius.
  double mine[7];
  std::copy(region, region + 6, mine);
  mine[6] = radius;
  if (IsEmptyBox(region))
  {
    mine[6] = -1.0; // asks for nothing
  }
  std::vector<double> requests(7 * size);
  controller->AllGather(mine, requests.data(), 7);

  // Pair by pair: send the partner the owned points in its grown box, receive ours.
  const double* xyz = vtkDoubleArray::SafeDownCast(owned->GetPoints()->GetData())->GetPointer(0);
  std::vector<vtkSmartPointer<vtkPolyData>> received;
  const int rounds = size + (size % 2) - 1;
  for (int round = 0; round < rounds; ++round)
  {
    const int partner = TournamentPartner(rank, round, size);
    if (partner < 0)
    {
      continue;
    }
    const double* request = &requests[7 * partner];
    vtkNew<vtkIdList> selected;
    if (request[6] >= 0.0)
    {
      // A margin of a few ulps keeps every point the neighbour search accepts (d2 <= r^2 in the same arithmetic).
      const double r2 = std::isinf(request[6]) ? request[6] : request[6] * request[6] * (1.0 + 1e-12);
      for (vtkIdType i = 0; i < nOwned; ++i)
      {
        const double* x = xyz + 3 * i;
        if (std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]) &&
          SquaredDistanceToBox(x, request) <= r2)
        {
          selected->InsertNextId(i);
        }
      }
    }
    this->Sent[partner].assign(selected->begin(), selected->end());
    vtkNew<vtkPolyData> message;
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(selected->GetNumberOfIds());
    owned->GetPoints()->GetPoints(selected, points);
    message->SetPoints(points);
    ExtractArrays(owned->GetPointData(), selected, message->GetPointData());

    auto incoming = vtkSmartPointer<vtkPolyData>::New();
    if (rank < partner)
    {
      controller->Send(message, partner, HaloTag);
      controller->Receive(incoming, partner, HaloTag);
    }
    else
    {
      controller->Receive(incoming, partner, HaloTag);
      controller->Send(message, partner, HaloTag);
    }
    if (incoming->GetNumberOfPoints() > 0)
    {
      received.push_back(incoming);
      sender.push_back(partner);
    }
  }

  // Ghost order: by global id, whichever rank they came from.
  vtkIdTypeArray* ownedIds = vtkIdTypeArray::SafeDownCast(owned->GetPointData()->GetGlobalIds());
  const std::string idsName = ownedIds->GetName();
  struct Ghost
  {
    vtkIdType Id;
    int Block;
    vtkIdType Index;
  };
  std::vector<Ghost> ghosts;
  for (int b = 0; b < static_cast<int>(received.size()); ++b)
  {
    vtkDataArray* ids = received[b]->GetPointData()->GetArray(idsName.c_str());
    const vtkIdType m = received[b]->GetNumberOfPoints();
    if (!ids || ids->GetNumberOfTuples() != m)
    {
      vtkErrorMacro("A halo message from another rank lacks its global ids: dropped.");
      status = 0;
      continue;
    }
    for (vtkIdType i = 0; i < m; ++i)
    {
      ghosts.push_back({ static_cast<vtkIdType>(ids->GetTuple1(i)), b, i });
    }
  }
  std::sort(ghosts.begin(), ghosts.end(), [](const Ghost& a, const Ghost& b) { return a.Id < b.Id; });
  const vtkIdType total = nOwned + static_cast<vtkIdType>(ghosts.size());

  // Assemble: owned block, then each message's tuples at their sorted positions.
  std::vector<vtkSmartPointer<vtkIdList>> from(received.size()), to(received.size());
  for (size_t b = 0; b < received.size(); ++b)
  {
    from[b] = vtkSmartPointer<vtkIdList>::New();
    to[b] = vtkSmartPointer<vtkIdList>::New();
  }
  for (size_t b = 0; b < received.size(); ++b)
  {
    this->Received[sender[b]].assign(received[b]->GetNumberOfPoints(), -1);
  }
  for (size_t g = 0; g < ghosts.size(); ++g)
  {
    from[ghosts[g].Block]->InsertNextId(ghosts[g].Index);
    to[ghosts[g].Block]->InsertNextId(nOwned + static_cast<vtkIdType>(g));
    this->Received[sender[ghosts[g].Block]][ghosts[g].Index] = nOwned + static_cast<vtkIdType>(g);
  }
  auto cloud = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(total);
  vtkDataArray* coordinates = points->GetData();
  coordinates->InsertTuples(0, nOwned, 0, owned->GetPoints()->GetData());
  for (size_t b = 0; b < received.size(); ++b)
  {
    coordinates->InsertTuples(to[b], from[b], received[b]->GetPoints()->GetData());
  }
  cloud->SetPoints(points);
  vtkPointData* ownedData = owned->GetPointData();
  vtkPointData* out = cloud->GetPointData();
  for (int a = 0; a < ownedData->GetNumberOfArrays(); ++a)
  {
    vtkAbstractArray* array = ownedData->GetAbstractArray(a);
    vtkSmartPointer<vtkAbstractArray> all = vtkSmartPointer<vtkAbstractArray>::Take(array->NewInstance());
    all->SetName(array->GetName());
    all->SetNumberOfComponents(array->GetNumberOfComponents());
    all->SetNumberOfTuples(total);
    vtkDataArray* numeric = vtkDataArray::SafeDownCast(all);
    if (numeric)
    {
      numeric->Fill(0.0);
    }
    all->InsertTuples(0, nOwned, 0, array);
    for (size_t b = 0; b < received.size(); ++b)
    {
      vtkAbstractArray* part = received[b]->GetPointData()->GetAbstractArray(array->GetName());
      if (!part || part->GetNumberOfComponents() != array->GetNumberOfComponents() ||
        part->GetDataType() != array->GetDataType())
      {
        // Another rank's piece has a different set of arrays: its halo points keep zeros here.
        vtkWarningMacro("Point array " << array->GetName() << " is missing or different on another rank: "
                                       << "its halo values are zero.");
        status = 0;
        continue;
      }
      all->InsertTuples(to[b], from[b], part);
    }
    out->AddArray(all);
  }
  out->SetGlobalIds(vtkDataArray::SafeDownCast(out->GetAbstractArray(idsName.c_str())));
  vtkNew<vtkUnsignedCharArray> ghost;
  ghost->SetName(vtkDataSetAttributes::GhostArrayName());
  ghost->SetNumberOfTuples(total);
  std::fill_n(ghost->GetPointer(0), nOwned, 0);
  std::fill_n(ghost->GetPointer(0) + nOwned, total - nOwned, vtkDataSetAttributes::DUPLICATEPOINT);
  out->AddArray(ghost);
  this->Output = cloud;
  return status;
}

int vtkMeshFreeHalo::UpdateHalo(vtkDataArray* values)
{
  vtkMultiProcessController* controller = this->Controller;
  if (!vtkMeshFreeHalo::IsDistributed(controller))
  {
    return 1;
  }
  const int size = controller->GetNumberOfProcesses();
  const int rank = controller->GetLocalProcessId();
  vtkDoubleArray* array = vtkDoubleArray::SafeDownCast(values);
  const vtkIdType total = this->Output ? this->Output->GetNumberOfPoints() : 0;
  const bool usable = array && array->GetNumberOfTuples() == total &&
    static_cast<int>(this->Sent.size()) == size && static_cast<int>(this->Received.size()) == size;
  if (!usable)
  {
    vtkErrorMacro("UpdateHalo needs a double array with one tuple per point of the last exchange's output.");
  }
  // Every rank takes part in every message the plan has, whatever its own input (zeros where unusable).
  const int components = array ? array->GetNumberOfComponents() : 1;
  int widest = components;
  controller->AllReduce(&components, &widest, 1, vtkCommunicator::MAX_OP);
  std::vector<double> outgoing, incoming;
  const int rounds = size + (size % 2) - 1;
  for (int round = 0; round < rounds; ++round)
  {
    const int partner = TournamentPartner(rank, round, size);
    if (partner < 0 || static_cast<int>(this->Sent.size()) != size)
    {
      continue;
    }
    const std::vector<vtkIdType>& sent = this->Sent[partner];
    const std::vector<vtkIdType>& into = this->Received[partner];
    outgoing.assign(sent.size() * widest, 0.0);
    for (size_t j = 0; usable && components == widest && j < sent.size(); ++j)
    {
      array->GetTypedTuple(sent[j], &outgoing[j * widest]);
    }
    incoming.assign(into.size() * widest, 0.0);
    auto send = [&]() {
      if (!outgoing.empty())
      {
        controller->Send(outgoing.data(), static_cast<vtkIdType>(outgoing.size()), partner, HaloTag + 1);
      }
    };
    auto receive = [&]() {
      if (!incoming.empty())
      {
        controller->Receive(incoming.data(), static_cast<vtkIdType>(incoming.size()), partner, HaloTag + 1);
      }
    };
    if (rank < partner)
    {
      send();
      receive();
    }
    else
    {
      receive();
      send();
    }
    for (size_t j = 0; usable && components == widest && j < into.size(); ++j)
    {
      if (into[j] >= 0)
      {
        array->SetTypedTuple(into[j], &incoming[j * widest]);
      }
    }
  }
  return usable && components == widest ? 1 : 0;
}

int vtkMeshFreeHalo::ExchangeForKNearest(vtkPointSet* local, const double* queries, vtkIdType numberOfQueries, int k,
  double minimumRadius, double radiusFactor)
{
  vtkMultiProcessController* controller = this->Controller;
  double region[6];
  vtkMeshFreeHalo::FiniteBounds(queries, numberOfQueries, region);
  int status = 1;
  if (k < 1)
  {
    vtkErrorMacro("k = " << k << " nearest neighbours: k must be at least 1.");
    k = 1;
    status = 0;
  }
  if (std::isnan(minimumRadius) || minimumRadius < 0.0)
  {
    minimumRadius = 0.0;
  }
  if (!(radiusFactor >= 1.0) || !std::isfinite(radiusFactor))
  {
    radiusFactor = 1.0;
  }

  // Round 1: a radius for the whole region. Twice the radius of a ball holding k points at the cloud's mean
  // density, when the cloud has an extent: checked after the exchange. Otherwise (no extent: coincident points)
  // the largest distance from this rank's queries to their k-th nearest own point, an upper bound (the
  // largest of the other ranks' where this rank holds fewer than k points, checked).
  const vtkIdType n = local ? local->GetNumberOfPoints() : 0;
  std::vector<double> xyz(3 * static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    local->GetPoint(i, &xyz[3 * i]);
  }
  meshfree::NeighborGrid grid;
  grid.Build(xyz.data(), n);
  const vtkIdType globalValid = vtkMeshFreeHalo::GlobalSum(controller, grid.NumberOfValidPoints());
  const int kEffective = static_cast<int>(std::min<vtkIdType>(k, globalValid));
  std::vector<meshfree::Index> ids;
  std::vector<double> dist2;
  auto finite = [](const double* x) { return std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]); };
  // The largest k-th distance over the queries (all, or those not flagged in `done`); infinity when a query
  // has fewer than k points in g.
  auto farthestKth = [&](const meshfree::NeighborGrid& g, const std::vector<char>* done) {
    double far2 = 0.0;
    for (vtkIdType q = 0; q < numberOfQueries && kEffective > 0; ++q)
    {
      const double* x = queries + 3 * q;
      if (!finite(x) || (done && (*done)[q]))
      {
        continue;
      }
      if (g.FindKNearest(x, kEffective, ids, dist2) < kEffective)
      {
        return std::numeric_limits<double>::infinity();
      }
      far2 = std::max(far2, dist2.back());
    }
    return far2;
  };
  double localBounds[6], cloudBounds[6];
  vtkMeshFreeHalo::FiniteBounds(xyz.data(), n, localBounds);
  vtkMeshFreeHalo::GlobalBounds(controller, localBounds, cloudBounds);
  double volume = 1.0, largestExtent = 0.0;
  int dimension = 0;
  for (int a = 0; a < 3; ++a)
  {
    largestExtent = std::max(largestExtent, cloudBounds[2 * a + 1] - cloudBounds[2 * a]);
  }
  for (int a = 0; a < 3; ++a)
  {
    const double extent = cloudBounds[2 * a + 1] - cloudBounds[2 * a];
    if (extent > 1e-6 * largestExtent)
    {
      volume *= extent;
      ++dimension;
    }
  }
  double radius = minimumRadius;
  bool checked = true;
  if (dimension > 0 && kEffective > 0)
  {
    const double pi = 3.141592653589793;
    const double ball = dimension == 1 ? 2.0 : (dimension == 2 ? pi : 4.0 * pi / 3.0);
    const double guess = 2.0 * radiusFactor *
      std::pow(kEffective * volume / (ball * static_cast<double>(globalValid)), 1.0 / dimension);
    radius = std::max(minimumRadius, std::isfinite(guess) ? guess : largestExtent);
  }
  else if (kEffective > 0)
  {
    const double far2 = farthestKth(grid, nullptr);
    const bool enough = std::isfinite(far2);
    radius = std::max(minimumRadius, enough ? radiusFactor * std::sqrt(far2) : 0.0);
    const double largest = vtkMeshFreeHalo::GlobalMax(controller, enough ? radius : 0.0);
    checked = vtkMeshFreeHalo::GlobalMax(controller, enough ? 0.0 : 1.0) == 0.0;
    radius = enough ? radius : std::max(radius, largest);
  }
  if (!this->Exchange(local, region, radius))
  {
    status = 0;
  }
  const bool check = vtkMeshFreeHalo::GlobalMax(controller, checked && dimension == 0 ? 0.0 : 1.0) > 0.0;
  if (!check || kEffective == 0)
  {
    return status;
  }

  // Check on local + halo points: a query with k points within radius / radiusFactor has all it needs (the
  // true k-th distance is no larger); for the others, the k-th distance among local + halo points bounds the
  // true one, and a second round, agreed by all ranks, widens the halo to it.
  vtkPoints* halo = this->Output->GetPoints();
  const double* haloXYZ = vtkDoubleArray::SafeDownCast(halo->GetData())->GetPointer(0);
  meshfree::NeighborGrid haloGrid;
  haloGrid.Build(haloXYZ, halo->GetNumberOfPoints());
  std::vector<char> done(static_cast<size_t>(numberOfQueries), 0);
  const double reach = radius / radiusFactor;
  bool allDone = true;
  for (vtkIdType q = 0; q < numberOfQueries; ++q)
  {
    const double* x = queries + 3 * q;
    done[q] = !finite(x) || haloGrid.CountWithinRadius(x, reach) >= kEffective;
    allDone = allDone && done[q];
  }
  double need = 0.0;
  if (!allDone)
  {
    const double need2 = farthestKth(haloGrid, &done);
    need = std::isfinite(need2) ? std::max(minimumRadius, radiusFactor * std::sqrt(need2))
                                : std::numeric_limits<double>::infinity();
  }
  const bool again = vtkMeshFreeHalo::GlobalMax(controller, need > radius ? 1.0 : 0.0) > 0.0;
  if (again)
  {
    if (!this->Exchange(local, region, std::max(radius, need)))
    {
      status = 0;
    }
    this->NumberOfRounds = 2;
  }
  return status;
}

void vtkMeshFreeHalo::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Controller: " << this->Controller << "\n";
  os << indent << "ShipPointData: " << this->ShipPointData << "\n";
  os << indent << "NumberOfOwnedPoints: " << this->NumberOfOwnedPoints << "\n";
  os << indent << "NumberOfGlobalPoints: " << this->NumberOfGlobalPoints << "\n";
  os << indent << "Radius: " << this->Radius << "\n";
  os << indent << "NumberOfRounds: " << this->NumberOfRounds << "\n";
}

double vtkMeshFreeHalo::LocalNeighborDistance(const double* xyz, vtkIdType n, int k)
{
  meshfree::NeighborGrid grid;
  grid.Build(xyz, n);
  const meshfree::Index nv = grid.NumberOfValidPoints();
  if (nv <= k)
  {
    return 0.0;
  }
  std::vector<meshfree::Index> ids;
  std::vector<double> dist2, kth;
  const meshfree::Index samples = std::min<meshfree::Index>(nv, 256);
  for (meshfree::Index j = 0; j < samples; ++j)
  {
    if (grid.FindKNearest(grid.SortedPoints() + 3 * (j * nv / samples), k + 1, ids, dist2) == k + 1)
    {
      kth.push_back(std::sqrt(dist2.back()));
    }
  }
  return meshfree::Median(std::move(kth));
}
