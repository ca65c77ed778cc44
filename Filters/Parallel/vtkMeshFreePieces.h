// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file    vtkMeshFreePieces.h
 * @brief   Pieces under MPI for the simulation sources (private to MeshFree::Filters, not wrapped): the share of
 *          the output a piece request asks for, the input request, and an all-gather of a small input (an obstacle
 *          or body surface) with a canonical form that does not depend on how the input was split.
 *
 * The simulations run whole on every rank (see README, "Running in parallel"): each rank's output is the
 * contiguous share of the particles that its piece number selects, and a surface input that ParaView hands over
 * split across ranks is gathered on every rank first. Every function that communicates is collective over the
 * global controller: every rank must call it, ranks with empty pieces included, or the others wait forever.
 */
#ifndef vtkMeshFreePieces_h
#define vtkMeshFreePieces_h

#include "vtkType.h"

#include <vector>

class vtkInformation;
class vtkMultiProcessController;
class vtkPointSet;

namespace vtkMeshFreePieces
{
/// Half-open index range [Begin, End).
struct Range
{
  vtkIdType Begin = 0;
  vtkIdType End = 0;
  vtkIdType Size() const { return this->End - this->Begin; }
};

/// The share of `count` items that the piece request of outInfo asks for: piece p of P gets [⌊count·p/P⌋,
/// ⌊count·(p+1)/P⌋), so the pieces cover [0, count) exactly once; no piece request means everything.
Range OutputShare(vtkInformation* outInfo, vtkIdType count);

/// Whether the request is one piece of a run on several processes (UPDATE_NUMBER_OF_PIECES > 1 and a global
/// controller with more than one process): then the input arrives split and is gathered with AllGather. The same
/// answer on every rank, since ParaView asks every rank for a piece of the same number.
bool IsDistributed(vtkInformation* outInfo);

/// Sets the input's request: its own piece without ghost levels when distributed (gathered later), otherwise the
/// whole input (piece 0 of 1), so that a serial streaming request for a piece still simulates the whole scene.
void RequestInput(vtkInformation* outInfo, vtkInformation* inInfo);

/// Every rank's `local` values concatenated in rank order, on every rank (collective); `local` itself when not
/// distributed. `offset`, if given, receives where this rank's values start.
std::vector<double> AllGather(const std::vector<double>& local, bool distributed, vtkIdType* offset = nullptr);

/// The same over `controller` (distributed when it has more than one process).
std::vector<double> AllGather(
  vtkMultiProcessController* controller, const std::vector<double>& local, vtkIdType* offset = nullptr);

/// Puts a triangle soup (9 coordinates per triangle) in a canonical form that depends only on the set of
/// triangles: each triangle rotated to start at its lexicographically smallest vertex (orientation kept), the
/// triangles sorted, exact duplicates removed (ghost cells, or an input that every rank holds whole). Serial and
/// N-rank runs then hand the core the same triangles in the same order, so they give the same bits.
void CanonicalTriangles(std::vector<double>& soup);

/// The distinct points of `points` (3 coordinates each), sorted: points closer than `tolerance` (max-norm) are one,
/// the earliest of them in `points` standing for the others. A source split into pieces may compute a point that two
/// pieces share slightly differently in each (vtkSphereSource's seam at 360°, 1e-17 away from the one at 0°): in
/// gathered pieces, rank 0's copy comes first, as computed by a serial run. `index` receives, for every point of
/// `points`, the index of the point that stands for it.
std::vector<double> MergePoints(const std::vector<double>& points, double tolerance, std::vector<vtkIdType>& index);
} // namespace vtkMeshFreePieces

#endif
