/**
 * @class   vtkMeshlessApproximation
 * @brief   LS, WLS, MLS, PU-WLS, SPH and RBF approximation of a point cloud's arrays (ParaView "Meshless Approximation")
 *
 * Input port 0 (`Input`) is a point cloud (vtkPointSet): every numeric point array, every component, is
 * approximated (or only those named with AddPointArray()). Optional port 1 (`Probe`, any vtkDataSet): the
 * output is the probe with the approximated arrays at its points. Without a probe the output is a
 * vtkImageData over ModelBounds (default: the input's bounds) with SampleDimensions samples; an axis of zero
 * extent gets one sample (so a cloud flat in z gives 101 x 101 x 1 by default). With HeightField on, the
 * input's z is approximated as z = f(x, y) from the x-y positions and the output is the surface z = f(x, y)
 * (a vtkStructuredGrid over the x-y grid, or the probe with moved points) with point array `Elevation`.
 *
 * Methods (thesis ch. 2-3; details in Filters/Core/Approximation.h): LS (one global fit), WLS (one fit
 * around Center, valid near it), MLS (the fit re-centred at every output point; default), PU-WLS (local fits
 * at lattice centres blended by a partition of unity), SPH (sum_j A_j m_j/rho_j W, with volumes from the
 * `Mass` and `Density` arrays when both exist, otherwise estimated; ShepardNormalization divides by the
 * kernel sum), RBF (radial basis function interpolation: a polyharmonic spline - thin-plate r^2 log r in 2D, r^3
 * in 1D and 3D - with a linear polynomial tail, SciPy's RBFInterpolator defaults; one global fit up to
 * RBFGlobalLimit valid points, above it a partition of unity of local RBF fits on the PU-WLS lattice, RBF-PU;
 * Smoothing > 0 makes it a smoothing spline, with SciPy's `smoothing` meaning), Auto (a measured choice: 2D
 * clouds up to 150 points the global thin-plate spline or PU-WLS of degree 3 by their leave-one-out errors, larger
 * ones PU-WLS of degree 3; 3D clouds RBF (r^3) or PU-WLS of degree 3 over 40 neighbours by their leave-one-out
 * errors at 32 sampled neighbourhoods; 1D clouds RBF; with Smoothing > 0 the smoothing spline up to
 * RBFGlobalLimit points, MLS above; see ResolveAuto in Filters/Core/Approximation/ApproximationAuto.cxx). BasisDegree 0-3
 * in the cloud's own dimension (not used by RBF, whose tail is linear). WeightFunction: a meshfree::KernelType
 * (for RBF-PU, the blending weight of the partition of unity). With RBF or Auto the output's field data hold
 * `ApproximationMethod` (what ran, e.g. "RBF (global)", "RBF-PU", "PU-WLS degree 3") and
 * `ApproximationMethodReason` (why).
 *
 * Support: the NeighborCount nearest points of each output point carry weight (h = 1.1 x distance to the
 * NeighborCount-th one), unless SupportRadius > 0 fixes h. Fallbacks for a degenerate fit: twice the
 * support, then lower degrees down to Shepard, then `NullValue` and `vtkValidPointMask` = 0. No NaN/Inf is
 * ever written.
 *
 * Outputs: the arrays (as double), `<name>_gradient` (ComputeGradients: MLS diffuse derivative, exact for
 * polynomials of degree <= BasisDegree; true derivative for LS/WLS/PU-WLS/SPH), `NeighborCount` and
 * `ConditionNumber` of the equilibrated moment matrix (Diagnostics), `vtkValidPointMask` (always).
 *
 * Distributed (MPI, e.g. `mpiexec -n N pvbatch` or pvserver): when the controller has several processes and
 * the output is requested in several pieces, each rank keeps its piece of the cloud as it arrives and
 * evaluates only its own part of the output - its piece of the probe, or its sub-extent of the grid
 * (CAN_PRODUCE_SUB_EXTENT; the grid's bounds are agreed over all ranks). What is global is computed over all
 * ranks (bounds, the PCA frame and intrinsic dimension, the LS moment sums, the PU-WLS lattice, the largest
 * SPH volume), and a halo exchange (vtkMeshFreeHalo) brings each rank every cloud point its evaluation reads:
 * within the widest support after the fallbacks (twice the radius, or the 2 x NeighborCount nearest), for
 * PU-WLS around the lattice centres that blend into the rank's points, for SPH volumes estimated from the
 * number density also the neighbours of those points (a second round). LS needs no halo. Halo points are
 * ordered by global id (the GlobalIds attribute, or the index in the cloud concatenated rank by rank), so that
 * distance ties break as in the serial run. Every rank takes part in every collective step, also with an
 * empty piece. The output's field array `HaloPoints` says how many points this rank received. Requested as
 * one piece (or without a controller), the filter runs serially on its input.
 *
 * @sa vtkPointInterpolator vtkSPHInterpolator vtkMeshFreeMLSKernel vtkMeshFreeHalo
 */
#ifndef vtkMeshlessApproximation_h
#define vtkMeshlessApproximation_h

#include "MeshFreeFiltersModule.h"
#include "vtkDataSetAlgorithm.h"

#include <string> // for the array selection
#include <vector> // for the array selection

class vtkMultiProcessController;

class MESHFREEFILTERS_EXPORT vtkMeshlessApproximation : public vtkDataSetAlgorithm
{
public:
  static vtkMeshlessApproximation* New();
  vtkTypeMacro(vtkMeshlessApproximation, vtkDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Methods
  {
    LS = 0,
    WLS = 1,
    MLS = 2,
    PU_WLS = 3,
    SPH = 4,
    RBF = 5,
    AUTO = 6
  };

  /// The probe (optional port 1).
  void SetProbeConnection(vtkAlgorithmOutput* output);

  ///@{
  /// Approximation method, LS / WLS / MLS (default) / PU-WLS / SPH / RBF / Auto.
  vtkSetClampMacro(Method, int, LS, AUTO);
  vtkGetMacro(Method, int);
  ///@}

  ///@{
  /// Total degree of the polynomial basis, 0-3 (default 2). Not used by SPH.
  vtkSetClampMacro(BasisDegree, int, 0, 3);
  vtkGetMacro(BasisDegree, int);
  ///@}

  ///@{
  /// Weight function, a meshfree::KernelType value (default 1, Wendland).
  vtkSetClampMacro(WeightFunction, int, 0, 11);
  vtkGetMacro(WeightFunction, int);
  ///@}

  ///@{
  /// Points carrying weight at each output point (default 20); used when SupportRadius <= 0.
  vtkSetClampMacro(NeighborCount, int, 1, 10000);
  vtkGetMacro(NeighborCount, int);
  ///@}

  ///@{
  /// Fixed support radius h when > 0 (default 0: from NeighborCount).
  vtkSetClampMacro(SupportRadius, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(SupportRadius, double);
  ///@}

  ///@{
  /// epsilon of InverseDistance, relative to h (default 1e-3); smaller interpolates more closely.
  vtkSetClampMacro(Epsilon, double, 1e-300, VTK_DOUBLE_MAX);
  vtkGetMacro(Epsilon, double);
  ///@}

  ///@{
  /// Centre of the WLS fit. Any NaN component (the default) means the centre of the input's bounds.
  vtkSetVector3Macro(Center, double);
  vtkGetVector3Macro(Center, double);
  ///@}

  ///@{
  /// Output arrays switched on or off (all default off).
  vtkSetMacro(ComputeGradients, bool);
  vtkGetMacro(ComputeGradients, bool);
  vtkBooleanMacro(ComputeGradients, bool);
  vtkSetMacro(Diagnostics, bool);
  vtkGetMacro(Diagnostics, bool);
  vtkBooleanMacro(Diagnostics, bool);
  vtkSetMacro(HeightField, bool);
  vtkGetMacro(HeightField, bool);
  vtkBooleanMacro(HeightField, bool);
  ///@}

  ///@{
  /// SPH: divide by the kernel sum sum_j V_j W_j (default on).
  vtkSetMacro(ShepardNormalization, bool);
  vtkGetMacro(ShepardNormalization, bool);
  vtkBooleanMacro(ShepardNormalization, bool);
  ///@}

  ///@{
  /// RBF: lambda added to the kernel matrix's diagonal, the kernel in data units (SciPy's RBFInterpolator
  /// `smoothing`); 0 (default) interpolates the data, larger values smooth noisy data (towards the linear
  /// least-squares fit as it grows). Auto: > 0 says the data are noisy.
  vtkSetClampMacro(Smoothing, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(Smoothing, double);
  ///@}

  ///@{
  /// RBF: the largest number of valid input points solved as one global fit (a dense O(N^3) solve; default
  /// 1000); larger clouds use RBF-PU.
  vtkSetClampMacro(RBFGlobalLimit, int, 0, 20000);
  vtkGetMacro(RBFGlobalLimit, int);
  ///@}

  ///@{
  /// RBF-PU: the points each local RBF fit takes (about; a ball around each lattice node holding this many),
  /// 0 (default) for the measured default of the cloud's dimension (12 in 1D, 40 in 2D, 160 in 3D). More points
  /// per patch: closer to the global fit's accuracy, at a cubic cost per patch.
  vtkSetClampMacro(RBFPatchPoints, int, 0, 2000);
  vtkGetMacro(RBFPatchPoints, int);
  ///@}

  ///@{
  /// RBF: the kernel, RBF_POLYHARMONIC (default: thin-plate spline in 2D, r^3 in 1D/3D) or RBF_WENDLAND_C2
  /// (compactly supported, support SupportRadius or SupportFactor x the RBF-PU cover radius; see
  /// meshfree::ApproximationOptions::RBFKernel). Auto uses the polyharmonic kernel.
  enum RBFKernels
  {
    RBF_POLYHARMONIC = 0,
    RBF_WENDLAND_C2 = 1
  };
  vtkSetClampMacro(RBFKernel, int, RBF_POLYHARMONIC, RBF_WENDLAND_C2);
  vtkGetMacro(RBFKernel, int);
  ///@}

  ///@{
  /// Value written where a point cannot be evaluated (default 0).
  vtkSetMacro(NullValue, double);
  vtkGetMacro(NullValue, double);
  ///@}

  ///@{
  /**
   * Which implementation evaluates: 0 Auto (default), 1 CPU, 2 CUDA. Only MLS has a device path: k nearest
   * (SupportRadius 0), a cloud of intrinsic dimension 2 or 3, BasisDegree 1-2 (3 in 2D), a weight without exp
   * (Wendland, Poly6, W3-W5, Lucy, Spiky, CubicSpline) and Diagnostics off; the device finishes the points whose
   * fast path succeeds (the CPU's bits: same neighbours, same arithmetic) and the CPU the others with its robust
   * chain. Everything else runs on the CPU whatever the choice. Auto takes the device only when MeshFree was
   * built with CUDA, a device is usable and the job reaches 10^6 (output points x neighbours per fit), a guess
   * until measured on a GPU. CUDA where the device cannot run gives a warning with the reason and the CPU
   * result, never an error. The output's field data array `Backend` (one string) says what ran: "CPU (oneTBB, 2
   * threads)" or "CUDA (NVIDIA H200)". Distributed, every rank chooses for its own part (device per rank).
   */
  enum BackendType
  {
    BACKEND_AUTO = 0,
    BACKEND_CPU = 1,
    BACKEND_CUDA = 2
  };
  vtkSetClampMacro(Backend, int, BACKEND_AUTO, BACKEND_CUDA);
  vtkGetMacro(Backend, int);
  ///@}

  ///@{
  /// Output grid without a probe: bounds (default all 0 = the input's bounds) and samples per axis.
  vtkSetVector6Macro(ModelBounds, double);
  vtkGetVector6Macro(ModelBounds, double);
  vtkSetVector3Macro(SampleDimensions, int);
  vtkGetVector3Macro(SampleDimensions, int);
  ///@}

  ///@{
  /// Arrays to approximate; none added (the default) means every numeric point array.
  void AddPointArray(const char* name);
  void ClearPointArrays();
  int GetNumberOfPointArrays() const { return static_cast<int>(this->PointArrays.size()); }
  ///@}

  ///@{
  /// The ranks a distributed cloud is split over (default: the global controller; none or one process:
  /// serial).
  void SetController(vtkMultiProcessController* controller);
  vtkGetObjectMacro(Controller, vtkMultiProcessController);
  ///@}

  /// Points of other ranks this rank received in the last distributed run (0 when serial); also the output's
  /// one-value field array `HaloPoints` in a distributed run.
  vtkIdType GetNumberOfHaloPoints() const { return this->HaloPoints; }

protected:
  vtkMeshlessApproximation();
  ~vtkMeshlessApproximation() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestDataObject(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Method = MLS;
  int BasisDegree = 2;
  int WeightFunction = 1;
  int NeighborCount = 20;
  double SupportRadius = 0.0;
  double Epsilon = 1e-3;
  double Center[3];
  bool ComputeGradients = false;
  bool Diagnostics = false;
  bool HeightField = false;
  bool ShepardNormalization = true;
  double NullValue = 0.0;
  double Smoothing = 0.0;
  int RBFGlobalLimit = 1000;
  int RBFPatchPoints = 0;
  int RBFKernel = RBF_POLYHARMONIC;
  int Backend = BACKEND_AUTO;
  double ModelBounds[6] = { 0, 0, 0, 0, 0, 0 };
  int SampleDimensions[3] = { 101, 101, 101 };
  std::vector<std::string> PointArrays;
  vtkMultiProcessController* Controller = nullptr;

private:
  vtkMeshlessApproximation(const vtkMeshlessApproximation&) = delete;
  void operator=(const vtkMeshlessApproximation&) = delete;

  /// The output grid from the input's bounds (over every rank when `distributed`; collective then).
  bool GridGeometry(
    vtkInformationVector** inputVector, bool distributed, double origin[3], double spacing[3], int dims[3]);
  /// Whether the cloud is split over the controller's ranks: several processes, several pieces requested.
  bool IsDistributed(vtkInformation* outInfo) const;

  // The grid announced by RequestInformation (grid mode), produced (or its piece) by RequestData.
  double GridOrigin[3] = { 0, 0, 0 };
  double GridSpacing[3] = { 1, 1, 1 };
  int GridDimensions[3] = { 1, 1, 1 };
  vtkIdType HaloPoints = 0;
};

#endif
