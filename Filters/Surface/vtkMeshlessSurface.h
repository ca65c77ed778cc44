/**
 * @class   vtkMeshlessSurface
 * @brief   triangle mesh of the surface a point cloud or a particle fluid samples (ParaView "Meshless Surface")
 *
 * Input port 0 (`Input`) is a point cloud or a set of SPH particles (vtkPointSet). The output is a
 * vtkPolyData of triangles, closed where the sampled object is closed, with the point arrays `Normals` (unit,
 * outward; also the active normals) and `DistanceToData` (distance from the vertex to the nearest input point:
 * 0 on the data, growing across a filled hole), and every other numeric point array of the input approximated
 * at the vertices (same names, every component, as double).
 *
 * Methods (details in Filters/Core/Surface/SurfaceReconstruction.h):
 * - MLS (default): the algebraic point-set surface (APSS: a sphere fitted at every point of space) of the
 *   oriented cloud.
 * - WLS: a partition of unity of local weighted least-squares fits (Ohtake's multi-level partition of unity).
 * - SPH: the level SurfaceLevel of the particles' colour field sum_j V_j W(x - x_j, H), with volumes
 *   V_j = Mass / Density when both arrays exist; AnisotropicKernels stretches the kernels along the local
 *   particle distribution (Yu & Turk 2013), keeping flat free surfaces flat.
 * For MLS and WLS the input's point array `Normals` (3 components) orients the fits when UseInputNormals is
 * on; otherwise normals are estimated by PCA over a neighbourhood adapted to density and noise and oriented
 * outward by a minimum-spanning-tree propagation.
 *
 * Scales: NeighborCount sets the smallest neighbourhood of every point (SupportRadius > 0 fixes its radius
 * instead); the implicit fits use SupportScale times it; CellSize (0 = automatic: 1.5 sample spacings or a
 * quarter of the fits' support, or half the particle spacing for SPH) is the contouring lattice's spacing. The zero set is contoured only in
 * the cells it passes through, and the vertices are then projected onto the surface (ProjectVertices).
 *
 * The other point arrays are approximated at the vertices by MLS of degree 1 over the NeighborCount nearest
 * input points (meshfree::Approximator, with its fallbacks: wider support, then Shepard); for MLS and WLS each
 * component is kept within the range of its input values (a linear fit would overshoot where the surface
 * bridges a gap in the data; a fluid's surface stays within a kernel radius of its particles). A vertex where
 * even the fallbacks fail gets 0 and 0 in `vtkValidPointMask`, which is added whenever arrays are
 * approximated. No NaN is ever written.
 *
 * Field data: `SurfaceMethod` (text), `CellSize`, `SupportRadius` (median fit support, or the SPH kernel
 * radius H), for MLS and WLS `OpenShare` (|sum a n| / sum a of the samples: 0 closed, 1 flat) and `HolesFilled`
 * (1 when HoleFilling closed the regions without samples), and the stages' wall-clock seconds (`SetupSeconds`, `ContourSeconds`, `ProjectionSeconds`,
 * `ApproximationSeconds`).
 *
 * Under MPI (pvbatch, pvserver: each rank's input is piece = rank of N) the pieces' outputs together are the
 * serial surface, each triangle on exactly one rank, with the serial vertex positions, Normals, DistanceToData and
 * approximated arrays bit for bit.
 * - Every method is distributed: space is cut in one slab per rank along the cloud's longest axis at the quantiles
 *   of its points (exact distributed selections), every point moves to its slab's rank, and each rank brings in a
 *   halo (every point within a radius of its slab, vtkMeshFreeHalo: first 8 neighbourhood radii, widened and
 *   recomputed when the core reports that a computation reached beyond it). Each rank estimates its own points'
 *   normals and fits (whole-cloud statistics by reductions, the orientation across slabs as Meshless Normals
 *   does) and contours the lattice cells whose centre lies in its slab; the contouring hands the cells beyond the
 *   slab to their rank round by round, so the ranks' parts are the serial surface's and meet without cracks (a
 *   vertex on a seam is on both ranks). HoleFilling's winding number sums over every point: each rank sums the
 *   cubes near it from its halo and the others by their moments, gathered from their owners (WindingNumber.h).
 *   Stray pieces are judged on the whole mesh (pieces joined across the seams). A rank holds its slab and a band of
 *   halo, never the whole cloud unless the halo needs it (field data `LocalCloudPoints`, `HaloRadius` (-1 when it was the whole cloud),
 *   `HaloAttempts`, per rank). Each rank's output is its slab's part (not the ParaView piece it was given). The
 *   SPH method's kernel radius and bulk volume come from a sample of particles chosen by a hash of their positions
 *   (the same sample in any order and split), evaluated where each is owned.
 * A point array is approximated when every rank with points has it (same name, components); otherwise none is,
 * with a warning. An input that every rank holds whole (piece 0 of 1 on each rank) is reconstructed locally,
 * whole, without communication.
 *
 * @sa vtkMeshlessNormals vtkMeshlessApproximation vtkSurfaceReconstructionFilter
 */
#ifndef vtkMeshlessSurface_h
#define vtkMeshlessSurface_h

#include "MeshFreeFiltersModule.h"
#include "vtkPolyDataAlgorithm.h"

class vtkMultiProcessController;
class vtkPointSet;

namespace meshfree
{
struct SurfaceOptions;
}

class MESHFREEFILTERS_EXPORT vtkMeshlessSurface : public vtkPolyDataAlgorithm
{
public:
  static vtkMeshlessSurface* New();
  vtkTypeMacro(vtkMeshlessSurface, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Methods
  {
    MLS = 0,
    WLS = 1,
    SPH = 2
  };

  ///@{
  /// Surface definition: MLS point-set surface (default), WLS partition of unity, or SPH colour field.
  vtkSetClampMacro(Method, int, MLS, SPH);
  vtkGetMacro(Method, int);
  void SetMethodToMLS() { this->SetMethod(MLS); }
  void SetMethodToWLS() { this->SetMethod(WLS); }
  void SetMethodToSPH() { this->SetMethod(SPH); }
  ///@}

  ///@{
  /**
   * The smallest neighbourhood of every point: its NeighborCount nearest other points (MLS, WLS), widened
   * where the noise asks for more; also the neighbours of the vertices' array approximation. Default 20.
   */
  vtkSetClampMacro(NeighborCount, int, 3, 1000);
  vtkGetMacro(NeighborCount, int);
  ///@}

  ///@{
  /**
   * When > 0, one fixed neighbourhood radius for every point (MLS, WLS) or the kernel radius H (SPH), in
   * data units. Default 0: automatic, from NeighborCount and the noise (MLS, WLS) or the particle spacing (SPH).
   */
  vtkSetClampMacro(SupportRadius, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(SupportRadius, double);
  ///@}

  ///@{
  /**
   * Spacing of the contouring lattice, in data units. Default 0: automatic (about the sample spacing for
   * MLS and WLS, half the particle spacing for SPH); enlarged, with a warning, when the lattice would be too big.
   */
  vtkSetClampMacro(CellSize, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(CellSize, double);
  ///@}

  ///@{
  /**
   * MLS, WLS: support of the implicit fits relative to the neighbourhood radius (default 2). Larger bridges
   * wider gaps of the sampling and smooths more; too small leaves holes.
   */
  vtkSetClampMacro(SupportScale, double, 1.0, 100.0);
  vtkGetMacro(SupportScale, double);
  ///@}

  ///@{
  /**
   * SPH: level of the colour field (0 outside, 1 inside the fluid) that is the surface; must lie strictly
   * between 0 and 1 (values outside give an error). Default 0.5, which encloses the particles' volume.
   */
  vtkSetClampMacro(SurfaceLevel, double, 0.0, 1.0);
  vtkGetMacro(SurfaceLevel, double);
  ///@}

  ///@{
  /// SPH: anisotropic kernels that follow the particles' local distribution (default off).
  vtkSetMacro(AnisotropicKernels, bool);
  vtkGetMacro(AnisotropicKernels, bool);
  vtkBooleanMacro(AnisotropicKernels, bool);
  ///@}

  ///@{
  /// Move the contour's vertices onto the implicit surface (default on); off leaves them on the lattice's edges.
  vtkSetMacro(ProjectVertices, bool);
  vtkGetMacro(ProjectVertices, bool);
  vtkBooleanMacro(ProjectVertices, bool);
  ///@}

  enum HoleFillingModes
  {
    HOLE_FILLING_OFF = 0,
    HOLE_FILLING_ON = 1,
    HOLE_FILLING_AUTO = 2
  };

  ///@{
  /**
   * MLS, WLS: where no sample supports a fit (the unseen underside of a scan), continue the surface from the
   * cloud's generalized winding number, a smooth, tight film blended into the fits (Barill et al. 2018;
   * Filters/Core/Surface/HoleFilling.h). Auto (default) fills when the cloud encloses a volume: its
   * area-weighted normals nearly cancel (|sum a n| / sum a < 0.45; a flat patch gives 1, a hemisphere 0.5).
   * Off, or Auto on an open cloud, leaves the surface open, its border within a few spacings of the data's.
   * The point array `DistanceToData` (every method) lets filled parts be cut away with a Threshold.
   */
  vtkSetClampMacro(HoleFilling, int, HOLE_FILLING_OFF, HOLE_FILLING_AUTO);
  vtkGetMacro(HoleFilling, int);
  ///@}

  ///@{
  /**
   * MLS, WLS: use the input's 3-component point array `Normals` when present (default on); off (or without
   * that array) estimates and orients normals from the points alone.
   */
  vtkSetMacro(UseInputNormals, bool);
  vtkGetMacro(UseInputNormals, bool);
  vtkBooleanMacro(UseInputNormals, bool);
  ///@}

protected:
  vtkMeshlessSurface();
  ~vtkMeshlessSurface() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Method = MLS;
  int NeighborCount = 20;
  double SupportRadius = 0.0;
  double CellSize = 0.0;
  double SupportScale = 2.0;
  double SurfaceLevel = 0.5;
  bool AnisotropicKernels = false;
  bool ProjectVertices = true;
  bool UseInputNormals = true;
  int HoleFilling = HOLE_FILLING_AUTO;

private:
  vtkMeshlessSurface(const vtkMeshlessSurface&) = delete;
  void operator=(const vtkMeshlessSurface&) = delete;

  struct Cloud;
  struct Result;
  struct Layout;
  void PrepareInput(vtkPointSet* input, vtkMultiProcessController* controller, Cloud& cloud, Layout& layout);
  int ReconstructDistributed(vtkPointSet* input, vtkMultiProcessController* controller, vtkPolyData* output);
  meshfree::SurfaceOptions Options() const;
  void AddFieldData(vtkPolyData* output, const Result& result);
  void ReportReconstruction(const Cloud& cloud, const Result& result, vtkIdType boundaryEdges = -1);
  void AddApproximatedArrays(const Cloud& cloud, vtkPolyData* output, Result& result, bool reporter,
    vtkMultiProcessController* controller = nullptr);
};

#endif
