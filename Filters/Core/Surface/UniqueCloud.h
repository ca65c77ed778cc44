// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: a surface cloud without its exact duplicates. A point repeated m times would count m times
// among its neighbours' k nearest and shrink every neighbourhood to 1/m of the sampling it stands for (holes
// in the surface); the normals and surface filters work on the distinct points and give duplicates their
// representative's results.
#ifndef meshfree_UniqueCloud_h
#define meshfree_UniqueCloud_h

#include "Common/NeighborGrid.h"

#include <vector>

namespace meshfree
{

struct UniqueCloud
{
  std::vector<double> Points;  // the distinct valid points, 3 each, in the order of their first occurrence
  std::vector<double> Normals; // their normals (when the input had normals)
  std::vector<Index> Unique;   // per input point: its distinct point, or -1 (invalid coordinates)
  Index Duplicates = 0;
};

/// Fills `unique` from the points the grid was built over (xyz, and normals or null) when they hold exact
/// duplicates, or always with `always` (then without duplicates it is the valid points themselves); returns
/// whether it filled it (unique untouched otherwise).
bool MergeDuplicates(
  const NeighborGrid& grid, const double* xyz, const double* normals, UniqueCloud& unique, bool always = false);

} // namespace meshfree

#endif
