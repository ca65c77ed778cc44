// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class meshfree::Approximator
 * @brief LS, WLS, MLS, PU-WLS and SPH approximation of scattered data (thesis ch. 2-3), VTK-free.
 *
 * SetCloud() takes the points and their values (C components per point, row-major, all arrays of a data
 * set side by side), Evaluate() approximates every component at a set of evaluation points in one pass: the
 * shape functions depend only on the geometry, so they are computed once per evaluation point and applied
 * to all C components.
 *
 * Methods (thesis equation numbers):
 * - LS (3.1-3.7): one global unweighted fit, in coordinates shifted to the cloud's centroid and scaled by
 *   its largest distance from it.
 * - WLS (3.8-3.15): one fit around Options.Center, weights theta(|x_i - Center|), support from the
 *   NeighborCount nearest points of the centre (or SupportRadius). Valid near the centre only.
 * - MLS (3.22-3.29, 2.9-2.24): the WLS fit re-centred at every evaluation point (shape functions, see
 *   LocalFit.h). Gradients are diffuse derivatives (exact for polynomials of degree <= m; for degree 0 the
 *   true derivative of Shepard's formula at fixed h).
 * - PU-WLS (3.16-3.21): WLS fits at centres blended by the partition of unity
 *   phi_c(x) = theta_c(x) / sum_k theta_k(x). Centres: the nodes of a regular lattice in the cloud's
 *   intrinsic frame whose spacing s makes the cover ball of radius R = s sqrt(d) hold about NeighborCount
 *   points; a node is kept when its fit (over the points within max(1.1 R, 1.1 d_k)) succeeds. R > s sqrt(d)/2
 *   makes every point of the lattice's box covered, by about 2^d centres. Gradients are the true derivative.
 * - SPH (2.3, 5.10): A(x) = sum_j A_j V_j W(|x - x_j|, h) with V_j = m_j / rho_j when volumes are given
 *   (Mass and Density arrays) and otherwise V_j = 1 / sum_k W(|x_j - x_k|, h_j) (the inverse number
 *   density); optional Shepard normalisation divides by sum_j V_j W. The kernel is normalised in the
 *   cloud's dimension.
 * - RBF (ApproximationRBF.h): interpolation by a polyharmonic spline with a polynomial tail (r^2 log r in 2D,
 *   r^3 in 1D and 3D; TailDegree 1), SciPy's RBFInterpolator defaults, with its Smoothing: one global fit up to
 *   RBFGlobalLimit valid points (a dense solve), above it RBF-PU, local RBF fits on the PU-WLS lattice blended
 *   by the partition of unity. Coincident points are merged (mean value); Report().MethodUsed says which ran.
 * - Auto: resolved by SetCloud from the number of valid points (over every part), the dimension and Smoothing
 *   (see ResolveAuto in ApproximationAuto.cxx); Report().MethodUsed and MethodReason say what and why.
 *
 * Support radius: with SupportRadius <= 0, h = SupportFactor * (distance to the NeighborCount-th nearest
 * point) at each evaluation point, so that exactly NeighborCount points carry weight (SupportFactor = 1.1);
 * SupportRadius > 0 fixes h. MLS uses at least kMinimumNeighborsPerTerm x the basis size neighbours (40 for
 * cubics in 3D): fewer make each moving fit nearly interpolating and ill-conditioned.
 *
 * Dimension: the cloud's intrinsic dimension (0..3) comes from a PCA of the valid points (axes with a
 * standard deviation below 3e-7 of the largest are flat); the basis uses the intrinsic axes (the coordinate
 * axes when the cloud is flat along coordinate axes), distances are always 3D.
 *
 * Fallback chain for a degenerate fit (kappa > kMaxCondition, see LocalFit.h): widen the support (twice the
 * neighbours, or twice the radius) -> lower the degree one by one -> degree 0 (Shepard) -> mask (value
 * NullValue, Valid = 0). Non-finite results are masked as well: no NaN or Inf leaves Evaluate().
 * Points with NaN/Inf coordinates or values are excluded from the cloud (and counted).
 */
#ifndef meshfree_Approximation_h
#define meshfree_Approximation_h

#include "Common/ImageProbes.h"
#include "Common/Kernels.h"
#include "Common/LocalFit.h"
#include "Common/NeighborGrid.h"
#include "Common/Progress.h"

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace meshfree
{
namespace cuda
{
class MLSDevice;
}

enum class ApproximationMethod
{
  LS = 0,
  WLS = 1,
  MLS = 2,
  PUWLS = 3,
  SPH = 4,
  RBF = 5,
  Auto = 6
};

/// "LS", "WLS", "MLS", "PU-WLS", "SPH", "RBF", "Auto".
const char* ApproximationMethodName(ApproximationMethod method);
bool ApproximationMethodFromName(const std::string& name, ApproximationMethod& out);

/// Which implementation evaluates. Only MLS has a device path (cuda/ApproximationDevice.h): k-nearest support,
/// intrinsic dimension 2 or 3, degree 1-2 (3 in 2D), a plain-arithmetic weight, no exact condition numbers
/// (Diagnostics); everything else runs on the CPU whatever the choice. CUDA where the device cannot run gives
/// the CPU result and says why (ApproximationReport::BackendNote), never an error. Auto takes the device only
/// when the build has CUDA, a device is usable and the job is large (kAutoDeviceWork).
enum class ApproximationBackend
{
  Auto = 0,
  CPU = 1,
  CUDA = 2
};

/// Auto uses the device from this many (evaluation points x neighbours per fit) on: 10^4 points at 20 neighbours.
/// Measured on an H200 (Testing/Benchmarks/results/gpu.md): MLS degree 2 on 10^4 points takes 0.3-0.6 ms on the
/// device (1 ms with the cloud's upload) against 4-5 ms on 16 CPU threads and 16-27 ms on 2; at 10^3 points both
/// take about a millisecond. The first device call of a process also creates the context (about 0.1 s), once.
constexpr double kAutoDeviceWork = 2e5;

/// Method RBF's kernel (ApproximationOptions::RBFKernel).
enum class RBFKernelType
{
  Polyharmonic = 0,
  WendlandC2 = 1
};

struct ApproximationOptions
{
  ApproximationMethod Method = ApproximationMethod::MLS;
  int Degree = 2; // 0..3
  KernelType Weight = KernelType::Wendland;
  int NeighborCount = 20;
  double SupportRadius = 0.0; // > 0: fixed support radius
  double SupportFactor = 1.1; // h = SupportFactor * d_k
  double Epsilon = 1e-3;      // InverseDistance, relative to h
  bool CenterSet = false;     // WLS centre; false: centre of the cloud's bounds
  double Center[3] = { 0.0, 0.0, 0.0 };
  bool ShepardNormalization = true; // SPH
  bool ComputeGradients = false;
  bool Diagnostics = false;
  double NullValue = 0.0;
  ApproximationBackend Backend = ApproximationBackend::Auto;
  // RBF (ApproximationRBF.h): SciPy's `smoothing` (lambda added to the kernel matrix's diagonal, the kernel in
  // data units; 0 interpolates), the tail's degree (1: SciPy's default), the largest cloud solved globally
  // (larger ones: RBF-PU) and the points per RBF-PU patch (0: kRBFPatchPoints for the cloud's dimension).
  double Smoothing = 0.0;
  int TailDegree = 1;
  Index RBFGlobalLimit = 1000;
  int PatchPoints = 0;
  // The RBF kernel: polyharmonic (no shape parameter) or Wendland's C2 function (1 - r/rho)^4 (4 r/rho + 1),
  // compactly supported, positive definite in 1 to 3 dimensions; rho = SupportRadius when set, else
  // SupportFactor x the RBF-PU cover radius (a ball holding about PatchPoints points) for the global fit, and
  // each RBF-PU patch's support radius for its fit.
  RBFKernelType RBFKernel = RBFKernelType::Polyharmonic;
};

/// Where the results go (m evaluation points, C components). Null pointers switch outputs off.
struct ApproximationOutput
{
  double* Values = nullptr;        // m * C
  double* Gradients = nullptr;     // m * C * 3 (d/dx, d/dy, d/dz per component)
  unsigned char* Valid = nullptr;  // m
  double* NeighborCounts = nullptr; // m: points with a nonzero weight in the fit that was used
  double* Conditions = nullptr;    // m: condition number of the equilibrated moment matrix (1 for SPH)
};

/// A cloud split over several processes (the VTK layer's MPI ranks). Sum and Max combine n values over every
/// part, in place, with the same result on every part; Owned (one flag per point given to SetCloud, null: all)
/// marks the part's own points, the others being copies of other parts' points (a halo) that take part in the
/// fits but not in the cloud's global statistics. With a partition, SetCloud() computes everything global over
/// all parts (bounds, valid count, PCA frame, the LS moment sums, the PU-WLS lattice box, the largest SPH
/// volume) and is collective: every part must call it, in the same order, whatever its number of points.
/// Evaluate() never communicates.
struct CloudPartition
{
  std::function<void(double* values, int n)> Sum;
  std::function<void(double* values, int n)> Max;
  const unsigned char* Owned = nullptr;
  /// Every part's `mine` appended in part order to `all`, the same on every part (an all-gather). Auto gathers
  /// the few points of a small 2D cloud with it for its leave-one-out choice; null: Auto chooses by size alone.
  std::function<void(const std::vector<double>& mine, std::vector<double>& all)> Gather;
};

/// What the evaluation at a set of points reads of the cloud (Approximator::Reach): the neighbourhoods of
/// Queries - the K nearest points of each (K = 0: none), every point within max(Radius, KFactor x the
/// distance to the K-th nearest). With SecondLevel, every point so found also needs its own K nearest (or
/// those within Radius2): SPH volumes estimated from the number density. Global: the evaluation reads nothing
/// of the cloud but its global statistics (LS).
struct ApproximationReach
{
  std::vector<double> Queries;
  int K = 0;
  double Radius = 0.0;
  double KFactor = 1.0;
  bool SecondLevel = false;
  int K2 = 0;
  double Radius2 = 0.0;
  bool Global = false;
};

/// What happened during the last SetCloud()/Evaluate().
struct ApproximationReport
{
  Index CloudPoints = 0;     // points given
  Index ExcludedPoints = 0;  // NaN/Inf coordinates or values, non-positive volumes
  int CloudDimension = 0;
  Index Evaluated = 0;
  Index Masked = 0;          // no support or degenerate after every fallback
  Index Widened = 0;         // needed a wider support
  Index DegreeLowered = 0;   // needed a lower degree (degree 0 included)
  Index Centers = 0;         // PU-WLS centres kept
  int DegreeUsed = 0;        // LS/WLS: degree of the global fit; RBF: of the polynomial tail (global fit)
  std::string MethodUsed;    // the method that ran ("RBF (global)", "RBF-PU" or Auto's choice)
  std::string MethodReason;  // Auto: why; RBF: global or PU and why
  Index MergedPoints = 0;    // RBF: points merged into a coincident one (duplicates, values averaged)
  Index Regularized = 0;     // RBF: fits solved by the least-squares fallback (singular or ill-conditioned)
  bool Aborted = false;
  std::string Backend;              // what evaluated: "CPU (oneTBB, 2 threads)" or "CUDA (NVIDIA H200)"
  std::string BackendNote;          // why the CPU ran where the device was asked for (or, Auto, could have run)
  Index DeviceEvaluated = 0;        // points finished on the device
  Index DeviceToCPU = 0;            // points the device handed to the CPU (robust path, fallbacks, far queries)
  double DeviceKernelSeconds = 0.0; // time in the device kernels (CUDA events)
};


class Approximator
{
public:
  Approximator();
  ~Approximator();
  Approximator(const Approximator&) = delete;
  Approximator& operator=(const Approximator&) = delete;

  /// Returns false (Error()) for invalid options: degree outside 0..3, NeighborCount < 1, bad epsilon.
  bool SetOptions(const ApproximationOptions& options);
  const ApproximationOptions& Options() const { return this->Opts; }

  /// The cloud: n points (x, y, z interleaved), values (n * components, row-major; may be null when
  /// components == 0) and, for SPH, optional volumes V_j = m_j / rho_j. The data are copied.
  /// Returns false (Error()) when no point is valid; Evaluate() then masks everything.
  /// With a partition (see CloudPartition) the cloud is this part's points plus a halo, and the call is
  /// collective.
  bool SetCloud(const double* xyz, Index n, const double* values, int components, const double* volumes = nullptr,
    const CloudPartition* partition = nullptr);

  /// What Evaluate() at the m points xyz will read of the cloud, for a distributed cloud's halo exchange
  /// (after SetCloud, which may be given this part's own points only). Returns false when there is nothing
  /// to evaluate.
  bool Reach(const double* xyz, Index m, ApproximationReach& reach) const;

  /// Approximates at m points (x, y, z interleaved). Returns false when aborted or nothing could be done;
  /// every output is defined in any case (masked points get NullValue and Valid = 0).
  bool Evaluate(const double* xyz, Index m, const ApproximationOutput& out,
    const ProgressCallback& progress = ProgressCallback());
  /// The same at the points of an image (ImagePoint order, x fastest), generated where they are used (on the
  /// device for the device MLS) instead of stored.
  bool EvaluateImage(
    const ImageGeometry& image, const ApproximationOutput& out, const ProgressCallback& progress = ProgressCallback());

  const ApproximationReport& Report() const { return this->Rep; }
  const std::string& Error() const { return this->Err; }
  int Components() const { return this->NumberOfComponents; }
  int CloudDimension() const { return this->Frame.Dimension; }
  const LocalFrame& Frame3() const { return this->Frame; }
  const NeighborGrid& Grid() const { return this->Points; }
  /// Bounds of the valid points (of every part's own points when distributed).
  const double* CloudBounds() const { return this->Bounds; }

  /// MLS shape functions at one point (for the VTK interpolation kernel): the ids and phi of the points
  /// carrying weight. Returns false when the point is masked. Thread-safe after SetCloud() and
  /// PrepareShapeFunctions().
  bool PrepareShapeFunctions();
  bool ShapeFunctions(const double x[3], std::vector<Index>& ids, std::vector<double>& phi,
    FitScratch& scratch) const;
  /// MLS shape functions at x over the caller's neighbours ids[0..n) (phi[j] for ids[j]; support
  /// SupportRadius or 1.1 x the farthest of them; degenerate: lower degrees down to Shepard). Returns
  /// false (phi all 0) when no fit exists. Thread-safe after SetCloud() and PrepareShapeFunctions().
  bool ShapeFunctionsFor(const double x[3], const Index* ids, int n, std::vector<double>& phi,
    FitScratch& scratch) const;

private:
  struct PUData;
  struct RBFData;
  struct PointResult
  {
    bool Valid;
    int Neighbors;
    double Condition;
    bool Widened;
    bool Lowered;
  };

  /// Evaluate()/EvaluateImage(): m points from xyz, or from image when xyz is null.
  bool EvaluateAt(const double* xyz, const ImageGeometry* image, Index m, const ApproximationOutput& out,
    const ProgressCallback& progress);
  enum class DeviceRun
  {
    NotUsed,
    Ran,
    Aborted
  };
  /// Applies Options.Backend to an MLS evaluation (see ApproximationBackend): runs the device path when chosen
  /// and possible, fills the outputs of the points it finished and lists the others (ascending) in cpuPoints.
  /// Sets Report().Backend and BackendNote.
  DeviceRun MLSOnDevice(const double* xyz, const ImageGeometry* image, Index m, const ApproximationOutput& out,
    const ProgressCallback& progress, std::vector<Index>& cpuPoints);
  bool PrepareGlobalFit();
  bool PreparePU(const double* xyz, Index m);
  /// The PU-WLS lattice's origin: the centre of the cloud's bounds.
  void PUOrigin(double origin[3]) const;
  /// The PU-WLS lattice: the box (umin, umax) of the cloud in its frame relative to PUOrigin, spacing,
  /// node counts and cover radius R.
  void PULattice(double umin[3], double& spacing, double& cover, Index counts[3]) const;
  /// The lattice centres within the cover radius R of the box of the m points xyz (in lattice order, 3 per
  /// centre, appended to `centers` after clearing it); returns R.
  double PUCentresNear(const double* xyz, Index m, std::vector<double>& centers) const;
  /// Position of lattice node `node` (x fastest).
  void PUNode(const double umin[3], double spacing, const Index counts[3], Index node, double x[3]) const;
  /// Sum / Max over the parts of a distributed cloud (no-ops without a partition).
  void PartitionSum(double* values, int n) const;
  void PartitionMax(double* values, int n) const;
  /// The LS moment sums of one degree (moments, then right-hand sides) over the valid points at the sorted
  /// positions listed (null: all), about GlobalOrigin scaled by GlobalInvScale.
  std::vector<double> LSMomentSums(int degree, const std::vector<Index>* sortedPositions) const;
  bool PrepareSPHVolumes();
  int MLSShape(const double x[3], FitScratch& s, bool gradient, bool exact, double& h,
    PointResult& result) const;
  PointResult MLSPoint(const double x[3], FitScratch& s, const ApproximationOutput& out, Index i) const;
  PointResult SPHPoint(const double x[3], FitScratch& s, const ApproximationOutput& out, Index i) const;
  PointResult PUPoint(const double x[3], FitScratch& s, const ApproximationOutput& out, Index i) const;
  /// One PU-WLS centre's fit at x (cover radius R): support SupportRadius, or max(SupportFactor d_k,
  /// SupportFactor R), the fit over the points within it at Options.Degree, then at twice the support from
  /// Options.Degree down to 0. Returns the degree used (coefficients, condition, the support h and the number m of
  /// weighted points, which are s.Ids / s.Xi / s.Weights [0, m)), or -1: no fit, or no point within R (the centre
  /// blends nothing).
  int FitPUCentre(const double x[3], double R, FitScratch& s, double* coefficients, double& condition, double& h,
    int& m) const;
  /// The partition of unity at x, shared by PU-WLS and RBF-PU (ApproximationPU.h): the centres (positions xyz,
  /// found in grid) within R weighted by theta(|x - x_c| / R), each centre's local fit given by
  /// local(c, dx, values, gradients) - values (C) and, when gradients is not null, their gradients (D x C, per
  /// unit length along the frame's axes) at dx = x - x_c -, blended by WriteBlend; info(c, result) fills
  /// Neighbors, Condition and Lowered from the centre of largest weight.
  template <class Local, class Info>
  PointResult BlendCentres(const double x[3], const NeighborGrid& grid, const double* xyz, double R, FitScratch& s,
    const ApproximationOutput& out, Index i, const Local& local, const Info& info) const;
  PointResult GlobalPoint(const double x[3], const ApproximationOutput& out, Index i) const;
  /// The partition of unity's last step (3.16-3.21), shared by PU-WLS and RBF-PU: the blended values
  /// sum(theta L) / sum(theta) and gradients of output point i from the sums (sumGrad and sumDTheta in the
  /// frame's local coordinates); false when one is not finite. sumTheta must be > 0.
  bool WriteBlend(Index i, const double* sumValues, const double* sumGrad, const double* sumDTheta, double sumTheta,
    const ApproximationOutput& out) const;
  /// RBF (ApproximationRBF.cxx): Auto's choice for the cloud (SetCloud), the duplicates' merge and the global
  /// fit or the RBF-PU patches that blend into the m points xyz; the evaluation at one point.
  void ResolveAuto(Index globalValid, int dimension, const CloudPartition* partition);
  /// Auto's estimate for a small 2D cloud (ApproximationRBF.cxx): the leave-one-out errors of the global
  /// thin-plate spline and of PU-WLS over the valid points (every part's, gathered); false when either is not
  /// defined (no component, a singular system, ...). errors[0]: spline, errors[1]: PU-WLS, each the rms over the
  /// points of the residuals relative to the values' standard deviation, over the components.
  bool AutoLeaveOneOut(const CloudPartition* partition, double errors[2]) const;
  /// Auto's estimate for a 3D cloud (ApproximationAuto.cxx): at about kAutoSamples positions of a coarse lattice
  /// over the cloud's box, the leave-one-out residuals at the position's nearest points of a polyharmonic fit
  /// over its rbfPoints nearest (an RBF-PU patch) and of a weighted polynomial fit of degree puDegree over its
  /// puPoints nearest (a PU-WLS centre); the neighbourhoods are gathered over every part, so every part (and a
  /// serial run) computes the same estimate whatever the points' order. errors[0]: the spline, errors[1]:
  /// PU-WLS, each the rms residual relative to the values' standard deviation, over the components. False when
  /// fewer than kAutoMinimumSamples positions had a full, well-posed neighbourhood.
  bool AutoSampledLeaveOneOut(
    const CloudPartition* partition, int rbfPoints, int puPoints, int puDegree, double errors[2]) const;
  /// Leave-one-out residuals (f - the fit without that point) of every valid point (by id, n x C, NaN where
  /// not defined) of this cloud (not distributed): the global polyharmonic spline (Rippa's formula, see
  /// SolvePolyharmonic), PU-WLS (each patch's weighted fit without the point, from its hat matrix's diagonal:
  /// r / (1 - h_jj); the patches and supports as the full cloud's).
  bool LeaveOneOutRBF(std::vector<double>& residuals);
  bool LeaveOneOutPU(std::vector<double>& residuals) const;
  bool RBFIsGlobal() const;
  int PatchSize() const;
  bool PrepareRBF(const double* xyz, Index m);
  bool PrepareRBFFits(const double* xyz, Index m);
  PointResult RBFPoint(const double x[3], FitScratch& s, const ApproximationOutput& out, Index i) const;
  /// The k nearest points of x (radius <= 0; h = SupportFactor x the k-th distance) or those within radius
  /// (h = radius), in s.Ids / s.Dist2 in the grid's neighbour order (distance, then position): the fits'
  /// sums then do not depend on how the neighbours were found (warm start or not, which points a distributed
  /// part holds) nor on the input's order, only on the points.
  int Neighbors(const double x[3], int k, double radius, FitScratch& s, double& h) const;
  /// Orders the first n of s.Ids / s.Dist2 by index.
  static void SortById(FitScratch& s, size_t n);
  /// Orders the first n of s.Ids / s.Dist2 (cloud points) in NeighborGrid's neighbour order.
  void SortNeighbors(FitScratch& s, size_t n) const;
  /// That order on (squared distance, index) pairs of cloud points.
  auto NeighborOrder() const
  {
    const double* xyz = this->Coordinates.data();
    return [xyz](const std::pair<double, Index>& a, const std::pair<double, Index>& b) {
      return NeighborGrid::NeighborBefore(a.first, xyz + 3 * a.second, a.second, b.first, xyz + 3 * b.second, b.second);
    };
  }
  /// Keeps those of the n neighbours s.Ids/s.Dist2 of x with a positive, finite weight W(r / h)^2, packed at
  /// the front of s.Ids and s.Weights, with their local coordinates (x_j - x) / h in the frame in s.Xi;
  /// returns how many. s must hold room for n (FitScratch::Reserve).
  int GatherWeighted(const double x[3], int n, double h, FitScratch& s) const;
  /// Least-squares fit of every component over the m gathered neighbours of s, from the requested degree
  /// down to `lowest` (the first that succeeds); returns the degree used, -1 when none does.
  int FitDescending(int lowest, const FitScratch& s, int m, double* coefficients, double& condition) const;
  void Mask(const ApproximationOutput& out, Index i) const;

  ApproximationOptions Opts;
  ApproximationReport Rep;
  std::string Err;
  NeighborGrid Points;
  LocalFrame Frame;
  Kernel UnitKernel; // support 1: weights from q = r / h
  std::vector<double> Coordinates;
  std::vector<double> Values;
  std::vector<double> Volumes;    // given V_j = m_j / rho_j (SPH)
  std::vector<double> SphVolumes; // the volumes SPH uses (given or estimated), in units of SphUnitLength^d
  double SphUnitLength = 1.0;     // so that neither h^d nor 1/h^d over- or underflows for extreme scales
  int NumberOfComponents = 0;
  double Bounds[6] = { 0, 0, 0, 0, 0, 0 };
  double CloudCenter[3] = { 0, 0, 0 };
  // LS / WLS: one global fit.
  std::vector<double> GlobalCoefficients;
  double GlobalOrigin[3] = { 0, 0, 0 };
  double GlobalInvScale = 1.0;
  int GlobalDegree = -1;
  int GlobalNeighbors = 0;
  double GlobalCondition = 0.0;
  std::unique_ptr<PUData> PU;
  std::unique_ptr<RBFData> RBFFits;
  bool RBFLeaveOneOut = false; // PrepareRBF also computes the global fit's leave-one-out residuals (Auto)
  ApproximationMethod Requested = ApproximationMethod::MLS; // Opts.Method before Auto was resolved
  std::unique_ptr<cuda::MLSDevice> Device; // the cloud on the CUDA device (uploaded on first use)
  bool DeviceUploaded = false;
  std::vector<double> DeviceKey; // the options the device copy was uploaded with
  // A distributed cloud (SetCloud with a partition): the combine functions, the global valid count, the LS
  // moment sums per degree, the PU-WLS box and the largest given SPH volume, all over every part.
  bool Partitioned = false;
  std::function<void(double*, int)> SumParts, MaxParts;
  Index GlobalValidPoints = 0;
  std::vector<std::vector<double>> PartitionLSSums;
  double PartitionBox[6] = { 0, 0, 0, 0, 0, 0 };
  double PartitionLargestVolume = 0.0;
};

} // namespace meshfree

#endif
