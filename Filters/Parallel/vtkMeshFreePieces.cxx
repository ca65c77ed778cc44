// SPDX-License-Identifier: BSD-3-Clause
#include "vtkMeshFreePieces.h"

#include "vtkCommunicator.h"
#include "vtkDataArray.h"
#include "vtkInformation.h"
#include "vtkMultiProcessController.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

namespace vtkMeshFreePieces
{
namespace
{
using Triangle = std::array<double, 9>;

bool Less(const double* a, const double* b)
{
  return std::lexicographical_compare(a, a + 3, b, b + 3);
}
} // namespace

Range OutputShare(vtkInformation* outInfo, vtkIdType count)
{
  Range share{ 0, count };
  using SDDP = vtkStreamingDemandDrivenPipeline;
  if (!outInfo || !outInfo->Has(SDDP::UPDATE_PIECE_NUMBER()) || !outInfo->Has(SDDP::UPDATE_NUMBER_OF_PIECES()))
  {
    return share;
  }
  const long long piece = outInfo->Get(SDDP::UPDATE_PIECE_NUMBER());
  const long long pieces = outInfo->Get(SDDP::UPDATE_NUMBER_OF_PIECES());
  if (pieces <= 1)
  {
    return share;
  }
  if (piece < 0 || piece >= pieces)
  {
    return Range{ 0, 0 };
  }
  const long long n = count;
  share.Begin = static_cast<vtkIdType>(n * piece / pieces);
  share.End = static_cast<vtkIdType>(n * (piece + 1) / pieces);
  return share;
}

bool IsDistributed(vtkInformation* outInfo)
{
  using SDDP = vtkStreamingDemandDrivenPipeline;
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  return outInfo && outInfo->Has(SDDP::UPDATE_NUMBER_OF_PIECES()) &&
    outInfo->Get(SDDP::UPDATE_NUMBER_OF_PIECES()) > 1 && controller && controller->GetNumberOfProcesses() > 1;
}

void RequestInput(vtkInformation* outInfo, vtkInformation* inInfo)
{
  using SDDP = vtkStreamingDemandDrivenPipeline;
  if (!inInfo)
  {
    return;
  }
  if (IsDistributed(outInfo))
  {
    inInfo->Set(SDDP::UPDATE_PIECE_NUMBER(), outInfo->Get(SDDP::UPDATE_PIECE_NUMBER()));
    inInfo->Set(SDDP::UPDATE_NUMBER_OF_PIECES(), outInfo->Get(SDDP::UPDATE_NUMBER_OF_PIECES()));
  }
  else
  {
    inInfo->Set(SDDP::UPDATE_PIECE_NUMBER(), 0);
    inInfo->Set(SDDP::UPDATE_NUMBER_OF_PIECES(), 1);
  }
  inInfo->Set(SDDP::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
}

std::vector<double> AllGather(const std::vector<double>& local, bool distributed, vtkIdType* offset)
{
  return AllGather(distributed ? vtkMultiProcessController::GetGlobalController() : nullptr, local, offset);
}

std::vector<double> AllGather(
  vtkMultiProcessController* controller, const std::vector<double>& local, vtkIdType* offset)
{
  if (offset)
  {
    *offset = 0;
  }
  if (!controller || controller->GetNumberOfProcesses() <= 1)
  {
    return local;
  }
  const int ranks = controller->GetNumberOfProcesses();
  const vtkIdType length = static_cast<vtkIdType>(local.size());
  std::vector<vtkIdType> lengths(ranks, 0), offsets(ranks, 0);
  controller->AllGather(&length, lengths.data(), 1);
  vtkIdType total = 0;
  for (int r = 0; r < ranks; ++r)
  {
    offsets[r] = total;
    total += lengths[r];
  }
  if (offset)
  {
    *offset = offsets[controller->GetLocalProcessId()];
  }
  std::vector<double> all(static_cast<size_t>(total));
  const double dummy = 0.0; // a valid address for an empty piece
  controller->AllGatherV(local.empty() ? &dummy : local.data(), all.empty() ? nullptr : all.data(), length,
    lengths.data(), offsets.data());
  return all;
}

void CanonicalTriangles(std::vector<double>& soup)
{
  std::vector<Triangle> triangles(soup.size() / 9);
  for (size_t t = 0; t < triangles.size(); ++t)
  {
    const double* v = &soup[9 * t];
    int first = 0;
    for (int k = 1; k < 3; ++k)
    {
      first = Less(v + 3 * k, v + 3 * first) ? k : first;
    }
    for (int k = 0; k < 3; ++k) // cyclic rotation: the orientation is kept
    {
      std::copy(v + 3 * ((first + k) % 3), v + 3 * ((first + k) % 3) + 3, triangles[t].begin() + 3 * k);
    }
  }
  std::sort(triangles.begin(), triangles.end());
  triangles.erase(std::unique(triangles.begin(), triangles.end()), triangles.end());
  soup.resize(9 * triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t)
  {
    std::copy(triangles[t].begin(), triangles[t].end(), soup.begin() + 9 * t);
  }
}

std::vector<double> MergePoints(const std::vector<double>& points, double tolerance, std::vector<vtkIdType>& index)
{
  const vtkIdType n = static_cast<vtkIdType>(points.size() / 3);
  const auto x = [&points](vtkIdType p) { return &points[3 * p]; };
  // Greedy, earliest first: an unassigned point stands for every unassigned point within the tolerance, found among
  // the points sorted by x.
  std::vector<vtkIdType> byX(n);
  std::iota(byX.begin(), byX.end(), vtkIdType(0));
  std::sort(byX.begin(), byX.end(), [&](vtkIdType a, vtkIdType b) { return x(a)[0] < x(b)[0]; });
  std::vector<vtkIdType> leader(n, -1);
  std::vector<vtkIdType> leaders;
  for (vtkIdType p = 0; p < n; ++p)
  {
    if (leader[p] >= 0)
    {
      continue;
    }
    leaders.push_back(p);
    const double low = x(p)[0] - tolerance;
    auto it = std::lower_bound(byX.begin(), byX.end(), low, [&](vtkIdType a, double v) { return x(a)[0] < v; });
    for (; it != byX.end() && x(*it)[0] <= x(p)[0] + tolerance; ++it)
    {
      const double* q = x(*it);
      if (leader[*it] < 0 && std::fabs(q[1] - x(p)[1]) <= tolerance && std::fabs(q[2] - x(p)[2]) <= tolerance)
      {
        leader[*it] = p;
      }
    }
  }
  std::sort(leaders.begin(), leaders.end(), [&](vtkIdType a, vtkIdType b) { return Less(x(a), x(b)); });
  std::vector<vtkIdType> rank(n, -1);
  std::vector<double> out(3 * leaders.size());
  for (size_t k = 0; k < leaders.size(); ++k)
  {
    rank[leaders[k]] = static_cast<vtkIdType>(k);
    std::copy_n(x(leaders[k]), 3, &out[3 * k]);
  }
  index.resize(n);
  for (vtkIdType p = 0; p < n; ++p)
  {
    index[p] = rank[leader[p]];
  }
  return out;
}
} // namespace vtkMeshFreePieces
