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
 * Distributed (a controller with several processes, e.g. pvbatch or pvserver under mpiexec): each rank's
 * output is its own piece, with the values the serial run gives on the whole cloud. The rank first receives
 * the remote points its points need (vtkMeshFreeHalo: the k + 1 nearest of each point, every point within
 * SearchRadius), then searches the local + halo cloud ordered by global id, as the serial run orders it.
 * Every rank must execute the filter, including ranks with an empty piece.
 *
 * @sa vtkStaticPointLocator
 */
#ifndef vtkMeshFreePointNeighbors_h
#define vtkMeshFreePointNeighbors_h

#include "MeshFreeFiltersModule.h"
#include "vtkPointSetAlgorithm.h"

class vtkMultiProcessController;

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

  ///@{
  /**
   * The controller over which the cloud is distributed. Default: the global controller (none, or one process:
   * the input is the whole cloud).
   */
  void SetController(vtkMultiProcessController* controller);
  vtkGetObjectMacro(Controller, vtkMultiProcessController);
  ///@}

protected:
  vtkMeshFreePointNeighbors();
  ~vtkMeshFreePointNeighbors() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int NeighborCount = 10;
  double SearchRadius = 0.0;
  vtkMultiProcessController* Controller = nullptr;

private:
  vtkMeshFreePointNeighbors(const vtkMeshFreePointNeighbors&) = delete;
  void operator=(const vtkMeshFreePointNeighbors&) = delete;
};

#endif
