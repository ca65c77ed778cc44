// Cell arithmetic of NeighborGrid as MESHFREE_HD functions: the grid's build and queries use them, and so does
// code that reproduces the grid on the CUDA device (cuda/SPHDevice.cu), which must assign every point to the same
// cell and visit the same cells.
#ifndef MeshFree_Common_GridCell_h
#define MeshFree_Common_GridCell_h

#include "Common/HostDevice.h"

#include <cmath>
#include <cstdint>

namespace meshfree
{

/// Cell coordinate, along one axis, of a point at `rel` from the grid's origin, clamped into [0, dim).
MESHFREE_HD inline std::int64_t GridAxisCell(double rel, double inverseSize, std::int64_t dim)
{
  const double t = rel * inverseSize;
  if (!(t > 0.0))
  {
    return 0;
  }
  return t >= static_cast<double>(dim - 1) ? dim - 1 : static_cast<std::int64_t>(t);
}

/// The margin a radius query adds to its reach: it absorbs the rounding of the cell assignment and of the
/// query's relative coordinates rel (cell edge `size`, the points' extents `extent`).
MESHFREE_HD inline double GridGapMargin(const double rel[3], double size, const double extent[3])
{
  double scale = 0.0;
  const double values[6] = { fabs(rel[0]), fabs(rel[1]), fabs(rel[2]), extent[0], extent[1], extent[2] };
  for (int k = 0; k < 6; ++k)
  {
    scale = scale < values[k] ? values[k] : scale;
  }
  return 1e-9 * size + 1e-13 * scale;
}

/// The cells [first, last] along one axis that a radius query at rel (with `margin`) may reach; false when none.
MESHFREE_HD inline bool GridAxisReach(double rel, double radius, double margin, double inverseSize, std::int64_t dim,
  std::int64_t* first, std::int64_t* last)
{
  const double top = static_cast<double>(dim - 1);
  const double low = floor((rel - radius - margin) * inverseSize);
  const double high = floor((rel + radius + margin) * inverseSize);
  if (low > top || high < 0.0)
  {
    return false;
  }
  *first = low > 0.0 ? static_cast<std::int64_t>(low) : 0;
  *last = high < top ? static_cast<std::int64_t>(high) : dim - 1;
  return true;
}

} // namespace meshfree

#endif
