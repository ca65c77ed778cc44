// MeshFree core: weakly compressible SPH fluid after Mueller, Charypar & Gross 2003 (thesis ch. 5), VTK-free.
//
// Model (equation numbers of the thesis, DIGEST.md ch. 5):
//  * density    rho_i = sum_j m W(r_ij) over fluid and boundary particles                     [5.32]
//  * pressure   'Ideal' p = k (rho - rho0) [5.40]; 'Tait' p = B ((rho/rho0)^7 - 1), B = rho0 k / 7, k = c0^2
//               (Becker & Teschner 2007). Negative pressures are clamped to 0: a free-surface particle misses
//               neighbours, so its density is underestimated; a negative pressure would pull it into its
//               neighbours (clumping, tensile instability). Clamping removes the spurious attraction.
//  * pressure force, symmetric [5.37, the thesis' stray factor p_i removed]:
//               a_i = -sum_j m (p_i/rho_i^2 + p_j/rho_j^2) grad W(r_ij)
//  * viscosity  [5.46]: a_i = (mu / rho_i) sum_j m (v_j - v_i) / rho_j lap W_visc(r_ij), lap W_visc = L (h - r)
//               (5.49; in 2D L = 40/(pi h^5), the constant that makes the estimate exact for quadratic fields,
//               as 45/(pi h^6) does in 3D)
//  * artificial viscosity (Monaghan 1992), ArtificialViscosity = alpha (default 0.02, DualSPHysics' value for
//               its dam break; peers use 0.01-0.1):
//               Pi_ij = -alpha c0 hs (v_ij . r_ij) / (rho_bar (r^2 + 0.01 hs^2)) for approaching fluid pairs
//               (v_ij . r_ij < 0), else 0, hs = h / 2, added to the pressure term p_i/rho_i^2 + p_j/rho_j^2.
//               It damps the acoustic noise of the weakly compressible fluid; on the dam-break front its effect
//               is small (TestSPHDamBreak, T = 2.3-3.3: the front leads Martin & Moyce by 7.3-10.5 % with
//               alpha = 0, 7.5-10.5 % with 0.02, 7-10 % with 0.05). Antisymmetric, so momentum is kept. Not
//               applied against wall dummies: a particle sliding along a wall approaches the dummies ahead of
//               it and leaves those behind, so the term would act as wall friction (measured: it slowed the
//               dam-break front by 4-5 % of Z, which is not free slip). Its diffusion number is far below the
//               acoustic limit for alpha <= 1 (nu_AV ~ alpha c0 h / 16), so the CFL step needs no extra term.
//               Density diffusion (delta-SPH) is not offered: it is a term of the continuity equation, and the
//               density here is the kernel sum [5.32].
//  * surface tension from the poly6 colour field c = sum m/rho W: a_i = -sigma lap(c) n/|n| / rho_i where
//    |n| = |grad c| > 0.25 / h (Mueller 2003, 5.3.4); walls count as fluid in c (neutral wetting)
//  * gravity.
// Kernels (SPHKernelPair): Mueller 2003 computes the density with poly6 and the pressure force with the spiky
// gradient. That pair is not the gradient of an energy: at the stiffness that keeps water within 1 % of rho0
// (k = 100 g H) an inviscid block in free space gains energy without bound (TestSPHFluid shows it), and the
// dam break explodes. The default, 'Spiky', uses the spiky kernel [5.41] for both (grad W = -3 s (h - r)^2 r/|r|):
// the inviscid system is then Hamiltonian and, the spiky gradient growing up to r = 0, free of particle pairing.
// 'Poly6' uses poly6 for both; 'Mueller' keeps the thesis' pair for comparison.
// With equal masses the pressure and viscosity terms are antisymmetric pair forces: linear momentum is conserved.
//
// Kernel constants (h = support radius, the only length) are the continuous normalisations corrected once on
// the initial lattice of spacing dx (Bonet & Lok 1999 consistency conditions, applied as global factors so the
// pair forces stay antisymmetric): sum_j V W = 1, sum_j V (x_j - x_i) (x) grad W = -I and sum_j V r^2 L = 2d.
// Without them the spiky gradient of a 2D lattice with h = 2 dx is 11 % weak and the hydrostatic pressure
// gradient 11 % too steep.
//
// Boundaries: dummy particles (SPHBoundary.h) on the fluid's lattice, filling a shell of the support's thickness
// behind the container walls and inside obstacles. They count in the density sum like fluid particles, and their
// pressure is extrapolated from the fluid next to them with the hydrostatic increase (Adami, Hu & Adams 2012,
// eq. 27 for static walls); the fluid-dummy force is the symmetric pair force. With p >= 0 walls only repel, so
// the fluid does not stick to them (free slip). As a guarantee on top of that, every drift is followed by a
// projection: a particle that would cross a wall is put back a small margin inside and loses its outward normal
// velocity; an obstacle crossing is detected by the nearest obstacle surface sample's outward normal and
// projected back the same way.
//
// Initial state: the block on its lattice, compressed along gravity as a column at rest would be (with the
// lattice's own density response to a uniaxial strain), so that the release starts without a pressure wave.
//
// Time integration: kick-drift-kick leap-frog (velocity Verlet), one force evaluation per step; the viscous
// force uses the half-step velocity. Step (CFL): dt = lambda min(h / (c + v_max), sqrt(h / a_max), 0.125 h^2/nu),
// capped by TimeStep (lambda above 0.4 is reduced to 0.4, with a warning); with CFLNumber = 0 the step is
// TimeStep unless it exceeds the stability limit (lambda = 0.4), in which case it is reduced and the reduction
// counted (the VTK layer warns). Steps land exactly on the
// requested times (the last two steps before a target share the remaining time rather than leave a sliver).
//
// Storage is structure of arrays: one array per attribute (position and velocity are xyz triplets, the layout
// the shared NeighborGrid reads). Neighbour lists are rebuilt every step from the grid with its batched query
// (NeighborGrid::FindWithinRadiusForAllPoints: cell by cell, the candidate cells gathered once for all the
// particles of a cell; rows identical to per-particle queries), then every pass streams through the lists. Every
// ReorderInterval steps the particle arrays are permuted into the grid's Z-order so that neighbours are close in
// memory. Everything the future depends on is in SPHState, so a state restored from a cache continues bit-identically,
// whatever the number of threads.
//
// Back ends (SetBackend): the per-particle arithmetic is shared MESHFREE_HD code (SPH/SPHPhysics.h,
// SPH/SPHDensity.h); the CPU loops (SPHFluid.cxx) feed it CSR neighbour rows, the CUDA integrator
// (cuda/SPHDevice.h, driven by SPHFluidDevice.cxx) the same neighbours in the same order from a grid rebuilt on the
// device, so both give the same bits.
#ifndef meshfree_SPHFluid_h
#define meshfree_SPHFluid_h

#include "Common/NeighborGrid.h"
#include "SPH/SPHDensity.h"
#include "SPH/SPHPhysics.h"

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace meshfree
{
namespace cuda
{
class SPHDevice;
}

/// Which implementation runs Advance().
enum class SPHBackend
{
  CPU = 0, ///< the oneTBB loops of SPHFluid.cxx
  CUDA = 1 ///< the CUDA device (cuda/SPHDevice.h), where usable; otherwise the CPU (see BackendNote())
};

enum class SPHEquationOfState
{
  Ideal = 0, ///< p = k (rho - rho0), the thesis [5.40]
  Tait = 1   ///< p = B ((rho/rho0)^7 - 1), Becker & Teschner 2007
};

/// Which pressure solver advances the fluid.
enum class SPHSolver
{
  WCSPH = 0, ///< weakly compressible: equation of state, explicit leap-frog (the model above)
  DFSPH = 1  ///< divergence-free SPH (Bender & Koschier 2015/2017): SPH/SPHDivergenceFree.cxx, CPU only
};

/// Which kernels give the density and the pressure force's gradient.
enum class SPHKernelPair
{
  Spiky = 0,  ///< spiky density and the spiky gradient [5.41]: energy-conserving, no particle pairing
  Poly6 = 1,  ///< poly6 density [5.32] and its gradient: energy-conserving
  Mueller = 2 ///< poly6 density, spiky gradient (Mueller 2003, the thesis): not energy-conserving
};

struct SPHParameters
{
  int Dimension = 3;                                          ///< 3, or 2 (x-z plane, y ignored)
  double FluidBounds[6] = { 0.0, 0.1, 0.0, 0.1, 0.0, 0.2 };   ///< initial block, filled on the lattice
  double DomainBounds[6] = { 0.0, 0.4, 0.0, 0.1, 0.0, 0.25 }; ///< closed container
  bool Walls = true;                 ///< false: free space (no container; for tests)
  double ParticleSpacing = 0.01;     ///< dx; mass = RestDensity dx^Dimension
  double SmoothingLength = 0.0;      ///< kernel support radius h; 0: 2 dx
  double RestDensity = 1000.0;       ///< rho0
  double GasStiffness = 0.0;         ///< k (Ideal, m^2/s^2) or c0^2 (Tait); 0: automatic (see AutoStiffness)
  SPHEquationOfState EquationOfState = SPHEquationOfState::Ideal;
  SPHKernelPair Kernels = SPHKernelPair::Spiky;
  double Viscosity = 0.0;            ///< dynamic viscosity mu, Pa s
  double SurfaceTension = 0.0;       ///< sigma, N/m
  double ArtificialViscosity = 0.02; ///< Monaghan's alpha (0: off); see the header comment
  double Gravity[3] = { 0.0, 0.0, -9.81 };
  double TimeStep = 1e-3;            ///< largest step, s
  double CFLNumber = 0.25;           ///< lambda; 0: fixed step
  double BoundarySpacingFactor = 0.5; ///< obstacle surface sampling spacing / dx (inside test)
  int ReorderInterval = 25;           ///< steps between Z-order permutations of the particle arrays
  long MaximumStepsPerInterval = 2000000; ///< a call to Advance() fails rather than take more steps
  SPHSolver Solver = SPHSolver::WCSPH;
  double DensityTolerance = 0.01;   ///< DFSPH: average compression allowed after the density solve, in percent
  double DivergenceTolerance = 0.1; ///< DFSPH: average (drho/dt) dt / rho0 allowed after the divergence solve, percent
  int MaximumIterations = 100;      ///< DFSPH: iterations per solve (each solve also stops at its tolerance)
};

/// What the DFSPH solves did in the Advance() call that produced a state (all zero for WCSPH).
struct SPHSolverReport
{
  long Steps = 0;                  ///< steps of that call
  long DensityIterations = 0;      ///< summed over its steps
  long DivergenceIterations = 0;   ///< summed over its steps
  long UnconvergedSteps = 0;       ///< steps where a solve stopped at MaximumIterations above its tolerance
  int LastDensityIterations = 0;   ///< of the last step
  int LastDivergenceIterations = 0;
  double AverageDensityError = 0.0;    ///< the last density solve's average compression (fraction of rho0)
  double MaxAverageDensityError = 0.0; ///< the largest of those over the call's steps
};

/// Everything the future of a simulation depends on (positions, velocities, the last acceleration), plus the
/// derived fields at the same instant for output.
struct SPHState
{
  double Time = 0.0;
  long Steps = 0;
  std::vector<double> Position;     ///< 3n, x y z (y = 0 in 2D)
  std::vector<double> Velocity;     ///< 3n
  std::vector<double> Acceleration; ///< 3n, a(x_n) used by the next kick
  std::vector<double> Density;      ///< n
  std::vector<double> Pressure;     ///< n; DFSPH: averaged over the Advance() call (SPHDivergenceFree.cxx)
  std::vector<std::int64_t> Id;     ///< n, stable across time
  /// DFSPH only (empty for WCSPH): the accumulated stiffness kappa (m^2/s^2, P / dt) of each particle's last density
  /// solve and divergence solve: the warm start of the next step; the step's pressure multiplier is rho (the sum
  /// of both), and Pressure their average over the steps of the Advance() call (SPHDivergenceFree.cxx).
  std::vector<double> DensityStiffness, DivergenceStiffness;
  SPHSolverReport Report; ///< DFSPH: what the Advance() call that produced this state did

  Index Size() const { return static_cast<Index>(this->Id.size()); }
};

/// Whole-fluid statistics of a state (tests, diagnostics).
struct SPHStatistics
{
  double Momentum[3] = { 0.0, 0.0, 0.0 };
  double KineticEnergy = 0.0;
  double MaxSpeed = 0.0;
  double MinDensity = 0.0;
  double MaxDensity = 0.0;
  bool Finite = true;
};

/// DFSPH's pair list entry (SPHDivergenceFree.cxx): a fluid neighbour j of particle i and G_ij = -m grad W_ij in
/// single precision, 16 bytes.
struct SPHGradientPair
{
  float Gradient[3];
  std::int32_t Neighbor;
};

/// DFSPH's second pair stream, beside SPHGradientPair: what the non-pressure accelerations need of the pair besides
/// G_ij = k (x_i - x_j) (SPHAcceleration::NonPressure): h - |r| (viscosity) and 1 / (k (|r|^2 + eps)) (artificial
/// viscosity; 0 where k = 0), in single precision, 8 bytes.
struct SPHPairShape
{
  float Viscous;
  float Artificial;
};

class SPHFluid
{
public:
  enum class Status
  {
    Ok,
    Aborted, ///< the progress callback returned false
    Failed   ///< see ErrorMessage()
  };

  /// fraction in [0, 1] of the current Advance(); return false to abort.
  using ProgressFunction = std::function<bool(double fraction)>;

  /// Validates the parameters and prepares kernels, stiffness and boundary particles. `obstacleTriangles`
  /// holds 9 doubles per triangle of closed surfaces the fluid flows around (their orientation is fixed
  /// here: normals are made to point outwards). Throws std::invalid_argument with a clear message for
  /// unusable settings; recoverable problems are listed in Warnings().
  void Setup(const SPHParameters& parameters, const std::vector<double>& obstacleTriangles = {});

  /// The state at t = 0: the fluid block on its lattice (particles outside the container or inside an
  /// obstacle are left out, with a warning), at rest, with density, pressure and acceleration evaluated.
  SPHState InitialState();

  /// Advances `state` to exactly `targetTime` (>= state.Time).
  Status Advance(SPHState& state, double targetTime, const ProgressFunction& progress = nullptr);

  ///@{
  /// The implementation Advance() asks for (default CPU). With CUDA, Advance() keeps the particles on the
  /// device from its start to its end and gives the same bits as the CPU (SPH/SPHPhysics.h). The device
  /// declines, and the CPU runs, when it cannot: a build without CUDA, no usable device, a scene with obstacles
  /// (their projection is CPU code), 2^31 particles or more, or a CUDA failure during the call (the CPU then
  /// redoes the whole call from its start). UsedBackend() says what ran the last Advance(), BackendNote() why the
  /// device declined it (empty when it ran or was not asked for).
  void SetBackend(SPHBackend backend) { this->RequestedBackend = backend; }
  SPHBackend Backend() const { return this->RequestedBackend; }
  SPHBackend UsedBackend() const { return this->LastBackend; }
  const std::string& BackendNote() const { return this->DeviceNote; }
  /// Why the device cannot run this setup (after Setup()), or empty when it can (a device is present, no
  /// obstacles). Probes the CUDA runtime once per process.
  std::string DeviceDeclineReason() const;
  ///@}

  /// Recomputes the density, pressure and acceleration of `state` at its positions and velocities (the force
  /// evaluation of a step, on the CPU; WCSPH).
  void UpdateDerived(SPHState& state) { this->ComputeAccelerations(state); }

  ///@{
  /// What the per-particle passes use (after Setup()): the shared constants and the static wall dummies with their
  /// grid (cell size h). For the device integrator and tests that replay its passes.
  const SPHConstants& Constants() const { return this->Physics; }
  const std::vector<double>& BoundaryPositions() const { return this->BoundaryPosition; }
  const NeighborGrid& BoundaryNeighborGrid() const { return this->BoundaryGrid; }
  ///@}

  /// Number of fluid neighbours (within h, itself excluded) of every particle of `state`.
  std::vector<int> NeighborCounts(const SPHState& state);

  static SPHStatistics Statistics(const SPHState& state, double particleMass);

  const std::vector<std::string>& Warnings() const { return this->WarningList; }
  const std::string& ErrorMessage() const { return this->Error; }
  /// Steps whose fixed TimeStep was above the stability limit and was reduced (since Setup()).
  long ReducedSteps() const { return this->ReducedStepCount; }
  /// DFSPH steps where a solve stopped at MaximumIterations before reaching its tolerance (since Setup()).
  long UnconvergedSteps() const { return this->UnconvergedStepCount; }

  const SPHParameters& Parameters() const { return this->Params; }
  double SupportRadius() const { return this->H; }
  double ParticleMass() const { return this->Mass; }
  /// k of the Ideal EOS (m^2/s^2), or c0^2 of Tait, as used (after the automatic choice).
  double Stiffness() const { return this->K; }
  double SoundSpeed() const { return this->C0; }
  Index NumberOfBoundaryParticles() const { return this->BoundaryCount; }
  /// Kernel factors applied by the lattice correction (poly6, spiky gradient, viscosity Laplacian).
  void GetLatticeCorrections(double c[3]) const;

  /// The k rule of the issue: Ideal k = 100 g H, Tait c0 = 10 sqrt(g H) (c0^2 returned), H = fluid height
  /// along gravity (standard gravity when |g| = 0).
  static double AutoStiffness(const SPHParameters& parameters);

  /// Largest stable step for the current state and CFL factor lambda (see the header comment).
  double StableTimeStep(const SPHState& state, double lambda) const;

  /// The largest CFLNumber a solver uses (larger values are reduced to it, with a warning): WCSPH 0.4, the
  /// leap-frog's stability limit; DFSPH 1, where its step 0.4 lambda h / v_max lets no particle move more than
  /// 0.4 h (0.8 dx with h = 2 dx) a step (SPHDivergenceFree.cxx, step 2).
  static double MaximumCFLNumber(SPHSolver solver) { return solver == SPHSolver::DFSPH ? 1.0 : 0.4; }

private:
  /// The step of the state whose CFL maxima are `e` at `time` towards `targetTime`, `steps` already taken in
  /// this call (TimeStep, CFL, the stability reduction, the landing on targetTime); false with Error set when the
  /// step collapsed or the state is unstable.
  bool ChooseStep(const SPHExtremes& e, double time, double targetTime, long steps, double& dt, bool& last);
  SPHExtremes Extremes(const SPHState& state) const;
  /// Advance() on the device (SPHFluidDevice.cxx); declined = true (state untouched) when the CPU must run it.
  Status AdvanceOnDevice(SPHState& state, double targetTime, const ProgressFunction& progress, bool& declined);
  void ComputeAccelerations(SPHState& state);
  void BuildNeighborLists(const SPHState& state, bool withBoundary);
  void Reorder(SPHState& state);
  void Enforce(SPHState& state, Index begin, Index end) const;
  bool NearBoundary(const double* x) const;
  bool NearObstacle(const double* x) const;
  /// The obstacle sample whose tangent plane decides whether x is inside an obstacle: among the samples nearest
  /// to x (all those equally near, up to 8: at an edge or corner samples of several faces tie, some at the same
  /// position), the one that puts x farthest outside (largest (x - s) . n, in `depth`). It depends on the positions
  /// and normals only, never on the order of the samples (of the obstacle's triangles). -1 when there is none.
  Index ObstacleSample(const double* x, std::vector<Index>& ids, std::vector<double>& d2, double& depth) const;
  void FillConstants(); // Physics from the members below, at the end of Setup()
  /// Cuts the step dt to land on targetTime (the last two steps share what remains); false with Error set when
  /// the step is not finite or would need more than MaximumStepsPerInterval steps.
  bool LandStep(double time, double targetTime, long steps, double& dt, bool& last);

  // DFSPH (SPHDivergenceFree.cxx).
  Status AdvanceDivergenceFree(SPHState& state, double targetTime, const ProgressFunction& progress);
  /// Grid, neighbour lists, density, the pair gradient coefficients and the factors alpha at the state's positions.
  void DivergenceFreeFields(SPHState& state);
  /// Density (correct = false: divergence) solve on the velocities of `state`; returns the iterations, sets error.
  int DivergenceFreeSolve(SPHState& state, double dt, bool density, double& error);
  /// The DFSPH output fields of a state: density at its positions, pressure rho kappa, its stiffness arrays sized.
  void DivergenceFreeOutput(SPHState& state);
  bool ChooseDivergenceFreeStep(const SPHState& state, double time, double targetTime, long steps, double& dt,
    bool& last);
  // Every fluid pair of the CSR rows, in their order: the neighbour j and G_ij = m GradientNorm shape(r) (x_i - x_j)
  // rounded to single precision (16 bytes a pair, one stream: the solves' passes read nothing else per pair; the
  // rounding keeps G_ji = -G_ij exact). The wall pairs' coefficients m GradientNorm shape(r), and each particle's own
  // sum_f G + 2 sum_b G (3 per particle, the fluid part summed from the rounded G_ij).
  std::vector<SPHGradientPair> Pairs;
  // The same pairs' SPHPairShape: the non-pressure pass reads the pair list instead of the positions (no distance,
  // no square root, no kernel per pair); filled only when that pass uses it (no surface tension).
  std::vector<SPHPairShape> PairShapes;
  std::vector<double> WallCoefficient, SelfGradient;
  std::vector<double> Alpha, Kappa, KappaOverRho, OldVelocity, Smoothed;
  // DFSPH: each particle's pressure impulse, sum over the steps of the current Advance() call of dt rho (kappa_density
  // + kappa_divergence) (permuted with the particles by Reorder), and the time those steps span: the Pressure output
  // is its time average (SPHDivergenceFree.cxx, "Pressure output").
  std::vector<double> PressureImpulse;
  // DFSPH: each particle's gradient strength gamma_i = tr(sum_j V_j (x_i - x_j) (x) m grad W_ij) / (d m) over fluid
  // and wall neighbours, relative to the lattice's (DivergenceFreeFields): the Pressure output is gamma p.
  std::vector<double> GradientStrength;
  double PressureImpulseTime = 0.0;
  // DFSPH: the positions and densities at which DivergenceFreeOutput last computed the per-step fields (grid,
  // neighbour lists, density, pair gradients, alpha, gradient strength); empty once anything else has rebuilt the
  // grid or the lists. The first step of the next Advance() reuses those fields when the state it starts from has
  // the same bits (the fields are a function of the positions alone), instead of computing them a second time.
  std::vector<double> FieldsPosition, FieldsDensity;
  void InvalidateFields()
  {
    this->FieldsPosition.clear();
    this->FieldsDensity.clear();
  }
  bool FieldsMatch(const SPHState& state) const;
  std::vector<double> SolveResidual, SolveDirection, SolvePreconditioned, SolveProduct, SolveVelocity; // the CG's
  std::vector<char> SolveFree;
  void SmoothStiffness(const SPHState& state, const std::vector<double>& in, std::vector<double>& out) const;
  double LatticeGradientStrength = 0.0; // sum_j m GradientNorm shape(r) r^2 of that lattice particle (gamma's scale)
  double LatticeFactorSum = 0.0; // |sum G|^2 + sum |G|^2 of a lattice particle far from walls, for the alpha cutoff
  long UnconvergedStepCount = 0;

  SPHParameters Params;
  std::vector<std::string> WarningList;
  std::string Error;
  long ReducedStepCount = 0;
  double H = 0.02, H2 = 4e-4;
  double Mass = 1.0;
  double K = 0.0, C0 = 0.0, TaitB = 0.0;
  double Nu = 0.0;
  // Density W = DensityNorm DensityShape(r^2); grad W = -GradientNorm GradientShape(r^2, r) r_vec.
  double DensityShape(double r2) const { return SPHDensityShape(r2, this->H, this->H2, this->SpikyDensity ? 1 : 0); }
  double GradientShape(double r2, double r) const
  {
    return SPHGradientShape(r2, r, this->H, this->H2, this->SpikyGradient ? 1 : 0);
  }
  bool SpikyDensity = false, SpikyGradient = false;
  double DensityNorm = 0.0, DensityCorrection = 1.0, CompressionResponse = 1.0;
  double GradientNorm = 0.0, GradientCorrection = 1.0;
  double Poly6 = 0.0;                         // colour field, lattice-normalised
  double ViscLap = 0.0, ViscCorrection = 1.0; // lap W = ViscLap (h - r)
  double WallMargin = 0.0;
  SPHConstants Physics; // the above as the shared per-particle functions (SPH/SPHPhysics.h) take them

  // Boundary (dummy) particles, static; obstacle surface samples with outward normals; their grids.
  std::vector<double> BoundaryPosition;
  Index BoundaryCount = 0;
  std::vector<double> BoundaryPressureTerm; // p / rho^2 of the pressure extrapolated each step to the dummies
  std::vector<char> BoundaryActive;
  NeighborGrid BoundaryGrid;
  std::vector<double> ObstaclePosition, ObstacleNormal;
  NeighborGrid ObstacleGrid;
  double ObstacleBox[6] = { 0, -1, 0, -1, 0, -1 };

  // Back end: asked for, used by the last Advance(), why the device declined; the device state (shared_ptr:
  // a copy of the solver shares it, and re-uploads its own state on every Advance()).
  SPHBackend RequestedBackend = SPHBackend::CPU;
  SPHBackend LastBackend = SPHBackend::CPU;
  std::string DeviceNote;
  std::shared_ptr<cuda::SPHDevice> Device;

  // Per-step scratch.
  NeighborGrid Grid;
  std::vector<Index> FluidStart, BoundaryStart;
  std::vector<std::int32_t> FluidNeighbors, BoundaryNeighbors;
  std::vector<std::vector<std::int32_t>> ThreadBoundary;
  std::vector<Index> BoundaryRowStart;           // where particle i's wall row lies in its thread's buffer
  std::vector<std::int32_t> BoundaryRowThread;   // and which thread's
  std::vector<double> PressureTerm, InverseDensity; // p / rho^2 and 1 / rho of each particle
};

} // namespace meshfree

#endif
