// SPDX-License-Identifier: BSD-3-Clause
#include "Surface/UniqueCloud.h"

namespace meshfree
{

bool MergeDuplicates(
  const NeighborGrid& grid, const double* xyz, const double* normals, UniqueCloud& unique, bool always)
{
  std::vector<Index> representative;
  const Index duplicates = grid.FindDuplicates(representative);
  if (duplicates == 0 && !always)
  {
    return false;
  }
  const Index n = grid.NumberOfPoints();
  unique = UniqueCloud();
  unique.Duplicates = duplicates;
  unique.Unique.assign(static_cast<size_t>(n), -1);
  Index count = 0;
  for (Index i = 0; i < n; ++i)
  {
    if (representative[i] == i)
    {
      unique.Unique[i] = count++;
      unique.Points.insert(unique.Points.end(), xyz + 3 * i, xyz + 3 * i + 3);
      if (normals)
      {
        unique.Normals.insert(unique.Normals.end(), normals + 3 * i, normals + 3 * i + 3);
      }
    }
  }
  for (Index i = 0; i < n; ++i)
  {
    if (representative[i] >= 0 && representative[i] != i)
    {
      unique.Unique[i] = unique.Unique[representative[i]];
    }
  }
  return true;
}

} // namespace meshfree
