/**
 * @class   vtkMeshFreeMLSKernel
 * @brief   moving-least-squares shape functions as a VTK interpolation kernel
 *
 * Drop-in kernel for vtkPointInterpolator (and vtkPointInterpolator2D): at each probe point, the
 * NeighborCount nearest source points (found with MeshFree's neighbour grid, built in Initialize(); at least
 * 2 per basis term, as in the MeshlessApproximation filter), or those within SupportRadius when it is > 0, get
 * the MLS shape functions
 * phi_j(x) = w_j b(xi_j)^T M^-1 b(0) of a polynomial basis of degree BasisDegree in coordinates shifted to x
 * and scaled by the support h (thesis 2.20, 3.26; see Filters/Core/LocalFit.h). They reproduce polynomials
 * of degree <= BasisDegree exactly, sum to 1 and may be negative; unlike VTK's own kernels they are not
 * "normalised positive weights". A degenerate fit falls back to lower degrees down to Shepard; when even
 * that fails, ComputeBasis() returns 0 and the interpolator applies its null-point strategy.
 *
 * The weights depend on the source geometry only; the interpolator applies them to every array.
 * Thread-safe as vtkInterpolationKernel requires (per-thread scratch).
 *
 * @sa vtkMeshlessApproximation vtkPointInterpolator vtkGeneralizedKernel
 */
#ifndef vtkMeshFreeMLSKernel_h
#define vtkMeshFreeMLSKernel_h

#include "MeshFreeFiltersModule.h"
#include "vtkInterpolationKernel.h"

#include <memory> // for the core state

class MESHFREEFILTERS_EXPORT vtkMeshFreeMLSKernel : public vtkInterpolationKernel
{
public:
  static vtkMeshFreeMLSKernel* New();
  vtkTypeMacro(vtkMeshFreeMLSKernel, vtkInterpolationKernel);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  void Initialize(vtkAbstractPointLocator* loc, vtkDataSet* ds, vtkPointData* pd) override;
  vtkIdType ComputeBasis(double x[3], vtkIdList* pIds, vtkIdType ptId = 0) override;
  vtkIdType ComputeWeights(double x[3], vtkIdList* pIds, vtkDoubleArray* weights) override;

  ///@{
  /// Total degree of the basis, 0-3 (default 2).
  vtkSetClampMacro(BasisDegree, int, 0, 3);
  vtkGetMacro(BasisDegree, int);
  ///@}

  ///@{
  /// Weight function, a meshfree::KernelType value (default 1, Wendland).
  vtkSetClampMacro(WeightFunction, int, 0, 11);
  vtkGetMacro(WeightFunction, int);
  ///@}

  ///@{
  /// Nearest source points used per probe point (default 20); h = 1.1 x the farthest of them.
  vtkSetClampMacro(NeighborCount, int, 1, 10000);
  vtkGetMacro(NeighborCount, int);
  ///@}

  ///@{
  /// Fixed support radius when > 0 (default 0: from NeighborCount).
  vtkSetClampMacro(SupportRadius, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(SupportRadius, double);
  ///@}

  ///@{
  /// Epsilon of the InverseDistance weight, relative to h (default 1e-3).
  vtkSetClampMacro(Epsilon, double, 1e-300, VTK_DOUBLE_MAX);
  vtkGetMacro(Epsilon, double);
  ///@}

protected:
  vtkMeshFreeMLSKernel();
  ~vtkMeshFreeMLSKernel() override;
  void FreeStructures() override;

  int BasisDegree = 2;
  int WeightFunction = 1;
  int NeighborCount = 20;
  double SupportRadius = 0.0;
  double Epsilon = 1e-3;

private:
  vtkMeshFreeMLSKernel(const vtkMeshFreeMLSKernel&) = delete;
  void operator=(const vtkMeshFreeMLSKernel&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Core;
};

#endif
