// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class meshfree::ElasticSolid
 * @brief Meshless elastic solid of "phyxels" (Mueller et al. 2004; thesis ch. 4), VTK-free.
 *
 * Model (thesis equation numbers in [..]):
 * - Neighbours N(i): the NeighborCount nearest phyxels at rest (fixed for the whole run: Lagrangian).
 *   r_i = their mean distance, support h_i = SupportScale r_i, w_ij = W(|X_ij|, h_i), X_ij = X_j - X_i.
 * - Mass m_i = s r_i^3 rho [4.15], s such that sum m_i = rho * body volume. Volume v_i = m_i / rho_i [4.22]
 *   with rho_i = rho: the thesis' kernel sum over only k = 10 neighbours covers a small part of a support
 *   h = 3 r and underestimates the density about 3x, which would make the material 3x too stiff
 *   (research/elastic.md 3.7); with rho_i = rho the volumes add up to the body's volume exactly.
 * - Moment matrix A_i = sum_j w_ij X_ij X_ij^T [4.12], inverted by its symmetric eigen-decomposition
 *   (= SVD for this symmetric positive semi-definite matrix) in coordinates scaled by r_i; eigenvalues below
 *   1e-6 of the largest are dropped (pseudo-inverse) and the phyxel is counted as ill-conditioned.
 *   d_ij = A_i^+ X_ij w_ij, d_ii = -sum_j d_ij.
 * - Deformation gradient F_i = J_i = I + grad u_i^T = sum_j (x_j - x_i) d_ij^T [4.2, 4.11-4.13]
 *   (+ the identity on the null space of A_i for coplanar neighbourhoods). It reproduces affine fields exactly.
 * - GradientBasis 2 (default) fits a quadratic instead of a linear polynomial in the same MLS way (9 terms,
 *   at least 18 neighbours) and keeps its linear part. The linear fit is only first-order accurate where the
 *   neighbourhood is one-sided: at the surface of a bent beam it underestimates the bending strain by
 *   ~ curvature x spacing, which made a 4-phyxel-thick cantilever twice too soft. d_ij, the packets and all
 *   conservation properties are the same (the fit still reproduces constants and linear fields exactly).
 *   Phyxels whose quadratic moment matrix is singular fall back to the linear fit.
 * - Green-Saint-Venant strain E = (F^T F - I)/2 and Hooke S = lambda tr(E) I + 2 mu E [4.4-4.7]. The thesis
 *   writes E = F^T F - I with force -2 v F S d, which is a material 4x stiffer than E (research/elastic.md F4);
 *   with the factor 1/2 and f = -v P d, YoungModulus and PoissonRatio are the physical constants.
 * - Forces from the energy sum_i v_i [psi(E_i) + k_v/2 (det F_i - 1)^2] [4.23-4.25]: phyxel i pushes its
 *   neighbours and itself with f_j = -v_i P_i d_ij, P = F S + k_v (det F - 1) cof F. The packet sums to zero
 *   and has zero torque, so linear and angular momentum are conserved.
 * - Hourglass control: E_hg = alpha/2 E v_i / (r_i^2 sum_j w_ij) sum_j w_ij |r_ij|^2, r_ij = x_ij - c_i p(X_ij)
 *   the residual of the MLS fit c_i. The fit minimises that sum, so the force is simply -k w_ij r_ij (no
 *   derivative of c_i); zero for every motion the basis reproduces, momentum conserving (the residuals are
 *   orthogonal to the basis), and it gives the lattice's zero-energy modes a stiffness.
 * - Plasticity (Mueller 2004 sec. 5): plastic strain E_p creeps towards the elastic strain E - E_p at rate
 *   PlasticCreep (1/s) while |E - E_p| > PlasticYield, capped at |E_p| <= PlasticMaxStrain. Off by default.
 * - Contacts: Lennard-Jones repulsion [4.26] between surface phyxels that are not rest neighbours, closer than
 *   2^(1/6) alpha (alpha = the phyxel spacing; repulsive part only), strength E alpha^3 / 50, force capped at
 *   E alpha^2.
 * - Containers: box or z-aligned cylinder, with restitution and Coulomb friction; FixedBounds pins phyxels.
 * - Integrators: symplectic Euler [4.28-4.30] with an automatic step, the smaller of C r_min / c,
 *   c^2 = (lambda + 2 mu + k_v + 4 alpha E)/rho, and C 2/omega_max with omega_max from a power iteration on the
 *   linearised forces at rest (C = StableStepFactor = 0.4; the measured limit is near C = 0.75); linearised
 *   backward Euler (M - dt^2 K) v+ = M v + dt F [4.31-4.42] by matrix-free preconditioned conjugate gradients on a
 *   positive semi-definite projection of -K, with container walls as velocity constraints inside the solve.
 */
#ifndef meshfree_ElasticSolid_h
#define meshfree_ElasticSolid_h

#include "Common/Kernels.h"
#include "Common/NeighborGrid.h"

#include <functional>
#include <string>
#include <vector>

namespace meshfree
{

/// Loops over fewer phyxels than this run on one thread: a parallel region costs more than the work, and far
/// more on a loaded machine where the other threads wait for a core.
constexpr Index kElasticParallel = 4096;

enum class ElasticContainer
{
  None,
  Box,
  Cylinder
};

struct ElasticSettings
{
  double YoungModulus = 1e5;  ///< E, Pa
  double PoissonRatio = 0.3;  ///< nu, -1 < nu < 0.5
  double Density = 1000.0;    ///< rho, kg/m^3
  double VolumeStiffness = 0; ///< k_v, Pa (adds a bulk modulus k_v)
  int NeighborCount = 10;
  double SupportScale = 3.0;
  KernelType Kernel = KernelType::Poly6;
  int GradientBasis = 2; ///< 1: linear MLS (thesis 4.11-4.13); 2: quadratic MLS (exact for quadratic fields)
  double HourglassStiffness = 0.05; ///< alpha (dimensionless, relative to E)
  double Gravity[3] = { 0.0, 0.0, -9.81 };
  double Damping = 0.0; ///< velocity damping rate, 1/s
  double PlasticYield = 0.0;      ///< 0 = elastic
  double PlasticCreep = 0.0;      ///< 1/s
  double PlasticMaxStrain = 0.0;  ///< 0 = unbounded
  ElasticContainer Container = ElasticContainer::None;
  double ContainerBounds[6] = { -1, 1, -1, 1, -1, 1 };
  double Restitution = 0.3;
  double Friction = 0.3;
  double FixedBounds[6] = { 0, -1, 0, -1, 0, -1 }; ///< empty box (min > max) pins nothing
  bool Contacts = true;           ///< Lennard-Jones self-contact between non-neighbours
  double ContactStrength = 0.0;   ///< beta of [4.26], J; 0 = automatic (E v r / 100)
  double StableStepFactor = 0.4;  ///< C of dt <= C r_min / c
};

/// Everything that evolves in time; what a checkpoint stores.
struct ElasticState
{
  double Time = 0.0;
  std::vector<double> Position;      // 3n
  std::vector<double> Velocity;      // 3n
  std::vector<double> PlasticStrain; // 6n (xx, yy, zz, xy, yz, xz), empty when plasticity is off
};

class ElasticSolid
{
public:
  /// Validates the settings and builds the model from rest positions (3n, interleaved) of a body of the given
  /// volume (<= 0: n * (mean spacing)^3). Returns false with a message for settings that cannot give a
  /// defined simulation; a true result may still carry a warning in `message`.
  bool Initialize(const std::vector<double>& rest, double bodyVolume, const ElasticSettings& settings,
    std::string& message);

  Index Size() const { return this->N; }
  const ElasticSettings& Settings() const { return this->Config; }
  const std::vector<double>& RestPositions() const { return this->Rest; }
  const std::vector<double>& Masses() const { return this->Mass; }
  const std::vector<double>& Volumes() const { return this->Volume; }
  const std::vector<double>& MeanNeighborDistances() const { return this->MeanDistance; }
  const std::vector<char>& Fixed() const { return this->IsFixed; }
  Index NumberOfIllConditioned() const { return this->IllConditioned; }
  double Lambda() const { return this->LameLambda; }
  double Mu() const { return this->LameMu; }

  ElasticState& State() { return this->Current; }
  const ElasticState& State() const { return this->Current; }
  /// Constant external forces per phyxel (3n, N), added to gravity in both integrators; empty = none.
  std::vector<double>& ExternalForce() { return this->External; }
  /// Rest positions, the given uniform velocity, time 0.
  void Reset(const double initialVelocity[3]);

  /// The automatic symplectic Euler step (see the class description), computed by Initialize.
  double StableTimeStep() const;

  /// Strain, stress etc. of the current state: F (9 per phyxel, row-major), Green strain and stress (6, xx yy
  /// zz xy yz xz, tensor components), det F.
  void ComputeDeformation(std::vector<double>& F, std::vector<double>& strain, std::vector<double>& stress,
    std::vector<double>& detF) const;
  /// Internal forces (elastic + volume + hourglass) at positions x; f is resized to 3n. Updates nothing.
  void ComputeInternalForces(const double* x, std::vector<double>& f) const;
  /// Elastic + volume + hourglass energy at positions x (for tests and diagnostics).
  double InternalEnergy(const double* x) const;

  /// One symplectic Euler step [4.28-4.30]: v += dt (f/m + g), damping, x += dt v, collisions, plasticity.
  void StepSymplectic(double dt);
  /// One linearised backward Euler step [4.31-4.42]; returns the CG iterations and the relative residual.
  int StepImplicit(double dt, double& residual, double tolerance = 1e-6, int maxIterations = 300);

  /// Advances the current state by `duration` with steps of at most maxStep (symplectic) or exactly
  /// ceil(duration/maxStep) equal steps (implicit). `abort` is polled between steps; returns false if it
  /// stopped the run. Statistics of the last Advance: steps taken, CG iterations.
  bool Advance(double duration, double maxStep, bool implicit, const std::function<bool()>& abort = {});
  long StepsTaken() const { return this->Steps; }
  long CGIterations() const { return this->TotalCGIterations; }
  /// Implicit steps whose conjugate gradient stopped at maxIterations above the tolerance, and the largest
  /// relative residual left (since Initialize).
  long UnconvergedCGSteps() const { return this->UnconvergedSteps; }
  double WorstCGResidual() const { return this->WorstResidual; }

private:
  // Pass 1: per phyxel the packet G_i = v_i P_i, F_i, the force phyxel i puts on itself, and the hourglass
  // forces of its neighbour slots. Pass 2 gathers f_j = self_j - sum_(i uses j) (G_i d_ij + edge_ij).
  void ComputePackets(const double* x, std::vector<double>& packet, std::vector<double>& Fout,
    std::vector<double>& self, std::vector<double>& edge) const;
  void GatherForces(const std::vector<double>& packet, const std::vector<double>& self,
    const std::vector<double>& edge, std::vector<double>& f) const;
  void DeformationGradient(const double* x, Index i, double F[9]) const;
  // Fit coefficients c_i (3 x Basis, scaled by 1/r_i) of the displacement differences x_ij; F from them.
  void Fit(const double* x, Index i, double C[27], double F[9]) const;
  // Hourglass residual forces kappa_i w_ij r_ij of phyxel i (per neighbour slot, 3 each) and their sum.
  void ResidualForces(const double* x, Index i, const double C[27], double* edge, double self[3]) const;
  void AddContactForces(const double* x, std::vector<double>& f);
  bool AreNeighbors(Index i, Index j) const;
  void ApplyContainer(double* x, double* v) const;
  void AddExternalForces(std::vector<double>& f) const;
  void EstimateStableStep();
  void WallFilter(const double* x, const double* push, std::vector<double>& S) const;
  void UpdatePlasticity(double dt);
  void ApplyHessian(const std::vector<double>& Fs, const std::vector<double>& Splus, const double* dx,
    std::vector<double>& out) const;

  ElasticSettings Config;
  Index N = 0;
  int K = 0;     // neighbours per phyxel (rows of Neighbor are K wide; -1 pads)
  int Basis = 9; // terms of the fit without the constant: 3 (linear) or 9 (quadratic)
  double LameLambda = 0, LameMu = 0;
  std::vector<double> Rest, Mass, Volume, MeanDistance, Hourglass;
  std::vector<Index> Neighbor;       // N*K
  std::vector<double> RestOffset;    // N*K*3, X_ij
  std::vector<double> Weight;        // N*K, w_ij
  std::vector<double> Shape;         // N*K*Basis, rows of the pseudo-inverse moment matrix times w_ij p(X_ij/r_i)
  std::vector<double> InvRadius;     // N, 1/r_i (the fit works in coordinates scaled by r_i)
  std::vector<double> SelfShape;     // N*3, d_ii
  std::vector<double> NullProjector; // N*9, identity on the null space of A_i (zero when well-posed)
  std::vector<Index> ReverseStart;   // N+1, CSR of (i, slot) with j = Neighbor[i*K+slot]
  std::vector<Index> ReverseEntry;   // i*K + slot
  std::vector<char> IsFixed;
  std::vector<double> External;
  Index IllConditioned = 0;
  double StableStep = 0.0;
  double ContactDistance = 0, ContactBeta = 0, ContactCap = 0;
  NeighborGrid ContactGrid;
  std::vector<Index> SurfacePhyxels; // phyxels with a one-sided rest neighbourhood
  std::vector<double> ContactPositions;
  ElasticState Current;
  mutable std::vector<double> Force, Packet, DefGrad, SelfForce, EdgeForce;
  long Steps = 0;
  long TotalCGIterations = 0;
  long UnconvergedSteps = 0;
  double WorstResidual = 0.0;
};

/// Isotropic Hooke law on the 6-vector (xx, yy, zz, xy, yz, xz) of tensor components [4.6-4.7].
void HookeStress(double lambda, double mu, const double strain[6], double stress[6]);
/// Von Mises equivalent stress of a 6-vector of tensor components.
double VonMisesStress(const double s[6]);

} // namespace meshfree

#endif
