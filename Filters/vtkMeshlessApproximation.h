/**
 * @class   vtkMeshlessApproximation
 * @brief   LS, WLS, MLS, PU-WLS and SPH approximation of a point cloud's arrays (ParaView "Meshless Approximation")
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
 * kernel sum). BasisDegree 0-3 in the cloud's own dimension. WeightFunction: a meshfree::KernelType.
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
 * @sa vtkPointInterpolator vtkSPHInterpolator vtkMeshFreeMLSKernel
 */
#ifndef vtkMeshlessApproximation_h
#define vtkMeshlessApproximation_h

#include "MeshFreeFiltersModule.h"
#include "vtkDataSetAlgorithm.h"

#include <string> // for the array selection
#include <vector> // for the array selection

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
    SPH = 4
  };

  /// The probe (optional port 1).
  void SetProbeConnection(vtkAlgorithmOutput* output);

  ///@{
  /// Approximation method, LS / WLS / MLS (default) / PU-WLS / SPH.
  vtkSetClampMacro(Method, int, LS, SPH);
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
  /// Value written where a point cannot be evaluated (default 0).
  vtkSetMacro(NullValue, double);
  vtkGetMacro(NullValue, double);
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

protected:
  vtkMeshlessApproximation();
  ~vtkMeshlessApproximation() override = default;

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
  double ModelBounds[6] = { 0, 0, 0, 0, 0, 0 };
  int SampleDimensions[3] = { 101, 101, 101 };
  std::vector<std::string> PointArrays;

private:
  vtkMeshlessApproximation(const vtkMeshlessApproximation&) = delete;
  void operator=(const vtkMeshlessApproximation&) = delete;

  bool GridGeometry(vtkInformationVector** inputVector, double origin[3], double spacing[3], int dims[3]);
};

#endif
