// SPDX-License-Identifier: BSD-3-Clause
#include "Surface/UniqueCloud.h"

#include <algorithm>

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

DistinctDistribution::DistinctDistribution(const Distribution& base, const UniqueCloud& unique, Index n)
  : Base(base)
  , Unique(unique)
  , Representative(unique.Points.size() / 3, -1)
{
  for (Index i = 0; i < n; ++i)
  {
    const Index u = unique.Unique[i];
    if (u >= 0 && (this->Representative[u] < 0 || base.Key(i) < base.Key(this->Representative[u])))
    {
      this->Representative[u] = i;
    }
  }
}

void DistinctDistribution::UpdateHalo(double* values, int components) const
{
  const Index n = static_cast<Index>(this->Unique.Unique.size());
  std::vector<double> expanded(static_cast<size_t>(n * components), 0.0);
  for (Index i = 0; i < n; ++i)
  {
    const Index u = this->Unique.Unique[i];
    if (u >= 0)
    {
      std::copy_n(values + u * components, components, &expanded[static_cast<size_t>(i * components)]);
    }
  }
  this->Base.UpdateHalo(expanded.data(), components);
  for (size_t u = 0; u < this->Representative.size(); ++u)
  {
    std::copy_n(&expanded[static_cast<size_t>(this->Representative[u] * components)], components,
      values + u * components);
  }
}

Index DistinctDistribution::OwnDuplicates() const
{
  Index count = 0;
  for (size_t i = 0; i < this->Unique.Unique.size(); ++i)
  {
    const Index u = this->Unique.Unique[i];
    count += u >= 0 && this->Base.Owned(static_cast<Index>(i)) && this->Representative[u] != static_cast<Index>(i);
  }
  return count;
}

bool MergeDuplicates(const NeighborGrid& grid, const double* xyz, const double* normals, Index n, const Distribution* d,
  UniqueCloud& unique, std::unique_ptr<DistinctDistribution>& processes, Index& duplicates)
{
  const bool merged = MergeDuplicates(grid, xyz, normals, unique);
  if (!(GlobalMax(d, merged ? 1.0 : 0.0) > 0.0))
  {
    return false;
  }
  if (!merged)
  {
    MergeDuplicates(grid, xyz, normals, unique, true); // this process has none: its points as they are
  }
  duplicates = unique.Duplicates;
  if (d)
  {
    processes.reset(new DistinctDistribution(*d, unique, n));
    duplicates = processes->OwnDuplicates();
  }
  return true;
}

} // namespace meshfree
