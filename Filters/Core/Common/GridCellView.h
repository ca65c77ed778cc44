// A NeighborGrid as the cell walk of Common/GridCell.h reads it (host side): the geometry, and 32-bit copies of the
// sorted order and the cell ranges. The device integrator uploads these (cuda/SPHDevice.cu); the tests that replay
// its passes on the CPU read them in place.
#ifndef MeshFree_Common_GridCellView_h
#define MeshFree_Common_GridCellView_h

#include "Common/GridCell.h"
#include "Common/NeighborGrid.h"

#include <cstdint>
#include <vector>

namespace meshfree
{

/// The view of `grid`: fills `order` (sorted position -> original index) and `cells` (one range per cell) and points
/// the view at them and at grid.SortedPoints(); an empty grid gives Count 0 (no query finds anything).
inline GridCells GridCellView(
  const NeighborGrid& grid, std::vector<std::int32_t>& order, std::vector<GridCellRange32>& cells)
{
  GridCells view{};
  order.clear();
  cells.clear();
  if (grid.NumberOfValidPoints() == 0)
  {
    return view;
  }
  double bounds[6];
  grid.GetBounds(bounds);
  for (int a = 0; a < 3; ++a)
  {
    view.Origin[a] = bounds[2 * a];
    view.Extent[a] = bounds[2 * a + 1] - bounds[2 * a];
  }
  view.Size = grid.CellSize();
  view.Inverse = 1.0 / view.Size;
  grid.GetGridDimensions(view.Dims);
  order.assign(grid.SortedOrder().begin(), grid.SortedOrder().end());
  const Index count = view.Dims[0] * view.Dims[1] * view.Dims[2];
  cells.resize(static_cast<std::size_t>(count));
  const NeighborGrid::CellRange* ranges = grid.Cells();
  for (Index c = 0; c < count; ++c)
  {
    cells[c] = GridCellRange32{ static_cast<std::int32_t>(ranges[c].Begin), static_cast<std::int32_t>(ranges[c].End) };
  }
  view.Sorted = grid.SortedPoints();
  view.Order = order.data();
  view.Cells = cells.data();
  view.Count = grid.NumberOfValidPoints();
  return view;
}

} // namespace meshfree

#endif
