/**
 * @class   vtkMeshFreePointNeighbors
 * @brief   neighbourhood statistics of a point cloud from MeshFree's shared neighbour grid
 *
 * For every input point, finds its `NeighborCount` nearest other points with the core's Morton-sorted
 * cell grid (meshfree::NeighborGrid, the one spatial index every MeshFree method uses) and adds:
 * - `MeanNeighborDistance`: r̄_i, the mean distance to those neighbours (the thesis' r̄ of eq. 4.15, which
 *   sets phyxel masses and supports, and the usual measure of local sampling density);
 * - `NeighborsInRadius` (only when `SearchRadius` > 0): how many other points lie within that radius.
 *
 * Points with NaN/Inf coordinates are excluded from the grid, get 0 in both arrays and 0 in
 * `vtkValidPointMask`; a warning gives their count. The output is a shallow copy of the input plus these arrays.
 *
 * @sa vtkStaticPointLocator
 */
#ifndef vtkMeshFreePointNeighbors_h
#define vtkMeshFreePointNeighbors_h

#include "MeshFreeFiltersModule.h"
#include "vtkPointSetAlgorithm.h"

class MESHFREEFILTERS_EXPORT vtkMeshFreePointNeighbors : public vtkPointSetAlgorithm
{
public:
  static vtkMeshFreePointNeighbors* New();
  vtkTypeMacro(vtkMeshFreePointNeighbors, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Number of nearest neighbours (excluding the point itself) averaged into MeanNeighborDistance. Default 10.
   */
  vtkSetClampMacro(NeighborCount, int, 1, 1000);
  vtkGetMacro(NeighborCount, int);
  ///@}

  ///@{
  /**
   * When > 0, also count the other points within this distance (array NeighborsInRadius). Default 0 (off).
   */
  vtkSetClampMacro(SearchRadius, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(SearchRadius, double);
  ///@}

protected:
  vtkMeshFreePointNeighbors();
  ~vtkMeshFreePointNeighbors() override = default;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int NeighborCount = 10;
  double SearchRadius = 0.0;

private:
  vtkMeshFreePointNeighbors(const vtkMeshFreePointNeighbors&) = delete;
  void operator=(const vtkMeshFreePointNeighbors&) = delete;
};

#endif
