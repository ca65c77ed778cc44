// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief Small order statistics shared by the core's estimators.
 */
#ifndef meshfree_Statistics_h
#define meshfree_Statistics_h
#include <algorithm>
#include <vector>
namespace meshfree
{
/// The median (upper median for an even count) of `values`, taken by value and reordered; 0 when empty.
inline double Median(std::vector<double> values)
{
  if (values.empty())
  {
    return 0.0;
  }
  const size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  return values[mid];
}
} // namespace meshfree
#endif
