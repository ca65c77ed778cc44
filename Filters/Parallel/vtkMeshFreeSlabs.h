// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file    vtkMeshFreeSlabs.h
 * @brief   Space cut in one slab per rank, each holding an equal share of a distributed cloud, and the cloud moved
 *          to them (private to MeshFree::Filters, not wrapped).
 *
 * A computation that partitions space rather than points (Meshless Surface contours the lattice cells of its
 * region) needs each rank's points to lie in its region; ParaView's pieces may be anything (split by index, each
 * piece spread over the whole cloud). Choose() cuts the longest axis of the whole cloud's bounds at the quantiles of
 * its points' coordinates (exact distributed selections, so the cuts depend on the set of points only); Move() hands
 * every point to the rank of its slab with a vtkMeshFreeHalo exchange of radius 0 (only the points inside each
 * rank's slab travel). A point on a cut belongs to the slab above it. Collective: every rank calls, with empty pieces
 * too.
 */
#ifndef vtkMeshFreeSlabs_h
#define vtkMeshFreeSlabs_h

#include "vtkSmartPointer.h"
#include "vtkType.h"

#include <vector>

class vtkMultiProcessController;
class vtkPolyData;

namespace vtkMeshFreeSlabs
{
struct Partition
{
  int Axis = 0;
  std::vector<double> Cuts;   // size - 1 cuts, ascending
  double Bounds[6] = { 0, 0, 0, 0, 0, 0 }; // the whole cloud's finite points
  vtkIdType Points = 0;       // its finite points
  /// The rank whose slab holds coordinate c along Axis.
  int Slab(double c) const;
  /// Rank r's positions: lower <= x[Axis] < upper (infinite at the ends).
  double Lower(int r) const;
  double Upper(int r) const;
  /// Rank r's region: its slab across the cloud's bounds (clipped to them along Axis).
  void Region(int r, double region[6]) const;
};

/// Collective: the partition of the cloud whose pieces (xyz: this rank's n points) the ranks hold.
Partition Choose(vtkMultiProcessController* controller, const double* xyz, vtkIdType n);

/// Collective: this rank's slab's points from every rank's `piece` (its point arrays and global ids travel with
/// them; a piece without GlobalIds gets the index in the cloud concatenated rank by rank). Points with NaN/Inf
/// coordinates stay nowhere.
vtkSmartPointer<vtkPolyData> Move(vtkMultiProcessController* controller, vtkPolyData* piece, const Partition& slabs);
} // namespace vtkMeshFreeSlabs

#endif
