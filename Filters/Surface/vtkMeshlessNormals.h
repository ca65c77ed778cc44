/**
 * @class   vtkMeshlessNormals
 * @brief   oriented normals and curvature of a point cloud, optionally moved onto its MLS surface
 *          (ParaView "Meshless Normals")
 *
 * Input port 0 is a point cloud (vtkPointSet). The output is the input (shallow copy) with the point arrays
 * - `Normals`: unit, consistently oriented (outward on a closed object); also the active normals;
 * - `Curvature` (unless ComputeCurvature is off): mean curvature, 1 / length, positive where the surface is convex
 *   with respect to the normals, exact on spheres: from the normals' own jets (a second, sphere-exact jet over the
 *   same neighbours), averaged over the nearest neighbours; with ProjectPoints, that of the algebraic sphere
 *   fitted at the moved point (Core/Surface/CloudNormals.h);
 * - `SurfaceVariation`: l0 / (l0 + l1 + l2) of the neighbourhood's PCA (0 on a plane, 1/3 for isotropic scatter);
 * - `OrientationConfidence`: how unambiguous the orientation was (below 0.5: ambiguous);
 * - `vtkValidPointMask`: 0 where no normal could be computed (NaN/Inf coordinates, degenerate
 *   neighbourhood); Normals, Curvature and the others are 0 there.
 * With ProjectPoints on, the points are moved onto the MLS (algebraic point-set) surface, which removes
 * noise along the normal; normals and curvature are then those at the moved points.
 *
 * Normals are degree-2 jet normals (Cazals & Pouget 2005) over a neighbourhood of at least NeighborCount
 * points, widened where the cloud's noise asks for it and kept within the curvature and away from creases
 * (a point whose neighbourhood reaches across an edge takes the normal of the neighbourhood on its side;
 * Core/Surface/SurfaceNormals.h). SupportRadius > 0 fixes the radius. Orientation:
 * - Auto (default): like InputNormals when the input has a 3-component point array `Normals`, else Propagation;
 * - Propagation: a minimum spanning tree over the neighbour graph, each connected piece then turned outward;
 * - Viewpoint: as Propagation, each piece then turned towards Viewpoint (a scanner's position);
 * - InputNormals: each normal flipped to agree with the input's `Normals` (an error when there are none).
 * Details in Filters/Core/Surface/CloudNormals.h.
 *
 * Field data: `NoiseEstimate` (spread of the points about the surface), `SupportRadius` (median
 * neighbourhood radius), `AmbiguousOrientations` (points with OrientationConfidence < 0.5).
 *
 * Under MPI (pvbatch, pvserver: each rank's input is piece = rank of N) each rank outputs its own points, in the
 * order of its piece, with the arrays and field data that a serial run gives them, bit for bit. The computation is
 * distributed: each rank holds its piece and a halo (vtkMeshFreeHalo: the other ranks' points within a radius of
 * its piece's box, first 8 neighbourhood radii, widened and recomputed when the estimation reports it reached
 * farther), estimates its own points, and shares what the neighbours' computations read through halo updates;
 * the global steps are distributed too: the scale estimate's sample (chosen by a hash of the positions),
 * the medians (exact selections over the ranks), the orientation (blocks oriented where their points are, then
 * the same small graph of blocks solved on every rank) and the duplicates (each owned where its smallest global
 * id is). Memory per rank: its piece and halo (field data `LocalCloudPoints`, `HaloRadius` (-1 when it was the whole cloud), `HaloAttempts`, per
 * rank); pieces compact in space (slabs, RedistributeDataSet) keep the halo a band along their faces, pieces
 * split by index span the whole cloud and hold all of it. An input that every rank holds whole (piece 0 of 1 on
 * each rank) is computed locally, without communication.
 *
 * @sa vtkMeshlessSurface vtkPCANormalEstimation
 */
#ifndef vtkMeshlessNormals_h
#define vtkMeshlessNormals_h

#include "MeshFreeFiltersModule.h"
#include "vtkPointSetAlgorithm.h"

class MESHFREEFILTERS_EXPORT vtkMeshlessNormals : public vtkPointSetAlgorithm
{
public:
  static vtkMeshlessNormals* New();
  vtkTypeMacro(vtkMeshlessNormals, vtkPointSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Orientations
  {
    AUTO = 0,
    PROPAGATION = 1,
    VIEWPOINT = 2,
    INPUT_NORMALS = 3
  };

  ///@{
  /**
   * The smallest neighbourhood of every point: its NeighborCount nearest other points, widened where the
   * noise asks for more. Default 20.
   */
  vtkSetClampMacro(NeighborCount, int, 3, 1000);
  vtkGetMacro(NeighborCount, int);
  ///@}

  ///@{
  /// When > 0, one fixed neighbourhood radius for every point, in data units. Default 0: automatic.
  vtkSetClampMacro(SupportRadius, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(SupportRadius, double);
  ///@}

  ///@{
  /// How the normals' signs are chosen: Auto (default), Propagation, Viewpoint or InputNormals.
  vtkSetClampMacro(Orientation, int, AUTO, INPUT_NORMALS);
  vtkGetMacro(Orientation, int);
  void SetOrientationToAuto() { this->SetOrientation(AUTO); }
  void SetOrientationToPropagation() { this->SetOrientation(PROPAGATION); }
  void SetOrientationToViewpoint() { this->SetOrientation(VIEWPOINT); }
  void SetOrientationToInputNormals() { this->SetOrientation(INPUT_NORMALS); }
  ///@}

  ///@{
  /// The point the normals face with Orientation Viewpoint (default 0, 0, 0).
  vtkSetVector3Macro(Viewpoint, double);
  vtkGetVector3Macro(Viewpoint, double);
  ///@}

  ///@{
  /// Compute the Curvature array (default on). It costs 10-20 % of the normals' time (a second jet over
  /// each normal's neighbours, then averages over the nearest neighbours); off, the output has no Curvature.
  vtkSetMacro(ComputeCurvature, bool);
  vtkGetMacro(ComputeCurvature, bool);
  vtkBooleanMacro(ComputeCurvature, bool);
  ///@}

  ///@{
  /// Move the points onto their MLS surface (default off).
  vtkSetMacro(ProjectPoints, bool);
  vtkGetMacro(ProjectPoints, bool);
  vtkBooleanMacro(ProjectPoints, bool);
  ///@}

  ///@{
  /// Refits of the projection (default 2); more converge closer to the surface, at more cost.
  vtkSetClampMacro(ProjectionIterations, int, 1, 100);
  vtkGetMacro(ProjectionIterations, int);
  ///@}

protected:
  vtkMeshlessNormals();
  ~vtkMeshlessNormals() override = default;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int NeighborCount = 20;
  double SupportRadius = 0.0;
  int Orientation = AUTO;
  double Viewpoint[3] = { 0.0, 0.0, 0.0 };
  bool ComputeCurvature = true;
  bool ProjectPoints = false;
  int ProjectionIterations = 2;

private:
  vtkMeshlessNormals(const vtkMeshlessNormals&) = delete;
  void operator=(const vtkMeshlessNormals&) = delete;
};

#endif
