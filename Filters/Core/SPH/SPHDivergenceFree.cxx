// SPH fluid core, part 4: the divergence-free solver (DFSPH; Bender & Koschier, "Divergence-free smoothed particle
// hydrodynamics", SCA 2015, and "Divergence-free SPH for incompressible and viscous fluids", IEEE TVCG 2017),
// selected by SPHParameters::Solver = DFSPH. CPU only (the CUDA integrator is WCSPH's).
//
// Same particles, lattice, kernels (the density kernel for rho, the pressure-force gradient for the solves), the
// same neighbour grid and lists, walls and obstacles as WCSPH (SPHFluid.h). Notation: G_ij = -m grad W_ij (the
// pressure-force gradient, lattice-corrected), P_i = kappa_i dt the velocity impulse potential of particle i:
// a solve changes the velocities by dv_i = sum_j (P_i / rho_i + P_j / rho_j) G_ij + sum_b 2 (P_i / rho_i) G_ib, and
// the density rate it controls is Drho/Dt_i = -sum_j (v_i - v_j) . G_ij - sum_b 2 v_i . G_ib (below: the adjoint).
// Per step, from (x, v):
//  1. neighbour lists at x (at the first step of an Advance() call those the last call's output computed, when the
//     state is bit for bit the one it output); density rho_i (the kernel sum, wall dummies included) and the factor
//     alpha_i = rho_i / (|sum_f G + 2 sum_b G|^2 + sum_f |G_ij|^2) (Bender & Koschier's factor with the mirrored
//     walls), the exact response of the
//     particle's own density rate to its own P, bounded below by a tenth of an interior particle's value (a
//     particle wedged in a corner could otherwise be kicked at tens of m/s; 0 for a particle without neighbours);
//  2. the step from the velocity alone: dt = lambda min(0.4 h / v_max, sqrt(h / |g|), 0.125 h^2 / nu), lambda =
//     CFLNumber (0.25 by default: 0.2 dx / v_max with h = 2 dx, SPlisHSPlasH's default; capped at 1, where no
//     particle moves more than 0.4 h a step: SPHFluid::MaximumCFLNumber), at most TimeStep. The cap was WCSPH's
//     leap-frog limit 0.4 until issue 25 measured larger steps on SPHERIC Test 2 (dx = 0.04 m, TimeStep 10 ms, one
//     thread): CFLNumber 0.4 / 0.6 / 1 took 1,446 / 1,215 / 932 steps with 3.0 / 3.6 / 5.2 density iterations a
//     step, H2 error 8.6 / 7.9 / 7.1 %, H4 2.6 / 2.5 / 2.5 %, no mass lost, and CFLNumber 1 took 0.8 of the CPU
//     time of 0.4 (results/spheric2.md); 1.5 ran as 1 does (the 10 ms cap and the 10 ms outputs set the step);
//  3. divergence solve on v: find P >= 0 that makes Drho/Dt_i = 0 where P_i > 0 (and <= 0 where P_i = 0), until
//     the average of max(Drho/Dt, 0) dt / rho0 is at most DivergenceTolerance (percent);
//  4. the non-pressure accelerations (gravity, viscosity, artificial viscosity, surface tension: the WCSPH terms
//     with zero pressure; plus the hydrostatic part of the wall pressure, below) with an explicit step: v* = v + dt a;
//  5. density solve on v*: find P >= 0 that makes rho*_i = rho0 where P_i > 0 (and rho*_i <= rho0 where P_i = 0),
//     rho*_i = rho_i + dt Drho/Dt_i(v*), until the average compression max(rho*_i - rho0, 0) / rho0 is at most
//     DensityTolerance (percent) and its RMS has fallen to 0.3 of its start ("Stopping" below); a compression
//     already present (rho_i > rho0) counts for at most rho0 sqrt(|g| h) dt / h per step, so that it is removed at
//     that speed rather than by a kick of (rho_i / rho0 - 1) h / dt;
//  6. x += dt v*, then the wall and obstacle projection of WCSPH (a guarantee; the pressure keeps particles off).
// Solver. Both solves are the same linear complementarity problem in q = P / rho: with v = v0 + B q (B the impulse
// above) the error is e(q) = e0 - A q, A = s B^T B (s = dt for the density error, 1 for the rate; the rate is -B^T
// by the adjoint wall coupling, so A is symmetric positive semi-definite, as in Bender & Koschier 2017, eqs. 9 and
// 15, and Ihmsen et al. 2014, IISPH, eq. 11, whose matrices these are), and P >= 0, e <= 0, P e = 0: the minimum of
// 1/2 q.A q - e0.q over q >= 0. It is solved by projected conjugate gradients with a Jacobi preconditioner
// (1 / (s |sum_f G + 2 sum_b G|^2 + s sum_f |G|^2), i.e. DFSPH's factor alpha_i / (rho_i s)): CG steps on the free
// set (P_i > 0 or e_i > 0); a step that would make some P negative is taken in full and projected on P >= 0, the
// velocities changed by what P actually changed and the error recomputed (an "expansion step"), then the CG
// goes on over the new free set with its direction kept there (zero off it); it restarts on z when that direction
// does not descend, and when the particles held at P = 0 have more error left than the free ones (the
// proportioning test of Dostal's MPRGP, Dostal & Schoberl 2005, with Gamma = 1; MPRGP takes the expansion with a
// fixed step length). The step length is the exact line search (d . r) / (d . A d) (for a conjugate direction
// d . r = r . z). One iteration costs two neighbour passes (B d, then A d), as a Jacobi iteration does (an
// expansion four). On SPHERIC Test 2 nearly every iteration is an expansion (some 100 of 10,850 particles of the
// density solve reach P = 0 in each); restarting after each, as before (issue 25), made the solver a projected
// steepest descent: 3,355 density iterations over the first 2.5 s at dx = 0.04 m with 10 ms steps, 2,038 with the
// direction kept (BenchSPHFront --box 1 --cfl 1 --timestep 0.01, one thread: 13.5 against 11.1 CPU s).
// It replaces relaxed Jacobi iterations P <- max(P + 0.5 alpha e / s, 0) (IISPH's relaxation; the papers' form),
// which remove the smooth part of an error about (L / h)^2 times more slowly than its particle-scale part: on the 2D column they needed 300 iterations per step at 1e-4 % to rest.
// The projection matters: CG steps truncated at the first particle reaching P = 0 (Polyak's active set) made the
// 2D dam-break front 30-45 % fast (particles at the free surface and the front, where many P are near 0, got few,
// stale corrections); with the expansion step the front is closer to the experiment than with Jacobi on the
// corrected time origin (at most 7.3 % against 10.7 %) and about as close on the raw one (TestSPHDivergenceFree).
// Stopping. The papers stop when the average error is at the tolerance, so a warm start that already meets it
// gets no correction (only the MinimumIterations = 2 below), and the smooth part of the pressure, which changes
// the density error little, never converges: at the default tolerances the hydrostatic column did not rest (e in
// "Why"). The density solve here also requires the RMS of its error (the compression max(e, 0)) to fall to
// ResidualReduction = 0.3 of its value after the warm start, unless the average error is already below a hundredth
// of the tolerance (a floor, so that a fluid at rest does not iterate on round-off); the divergence solve keeps
// the average alone. Measured on the test's columns at the default tolerances (pressure L2 mean over t sqrt(g / H)
// = 8-10, 2D / 3D) and on the 65,536-particle 3D dam break of BenchSPH (iterations per step over 0.02-0.12 s):
// relaxed Jacobi, average only (before): 0.55 / 0.28, 10.3 iterations; projected CG, average only: 0.54 (2D, not
// at rest); Jacobi with a 0.1 reduction: 0.36 (2D); CG with 0.1: 0.040 / 0.035, 45 iterations (4.0 times the
// wall-clock time, separate runs); with 0.3: 0.047 / 0.036, 17 iterations (1.8 times in the same run, 2.4 in
// separate ones); with 0.5: 0.59 / 0.37; with 0.1 and a floor of a tenth of the tolerance: 0.44 (2D). Every solve
// applies at least 2 corrections after a warm start.
//
// Walls and obstacles: the WCSPH dummy particles, used as boundary particles in the manner of Akinci et al. 2012.
// They sit on the fluid's lattice, so each one's volume is dx^d (its mass m = rho0 dx^d, like a fluid particle's);
// they count once in the kernel sum rho_i, and they mirror the fluid particle: pressure p_b = p_i, rho_b = rho_i
// (the factor 2 of the push), so that a uniform pressure exerts no net force on a particle next to a wall (with one
// P_i / rho_i term, as in Akinci's form, it pushes particles into the walls and the settled pressure is far from
// hydrostatic), and velocity -v_i in the density rate (the factor 2 there). The second makes the pressure impulse
// minus the transpose of the discrete divergence (with the mass inner product), so each solve is the orthogonal
// projection that DFSPH's derivation assumes and pressure does no work on divergence-free motion; with the
// dummies counted once in the rate it is an oblique projection, and the particles next to the walls oscillate with
// a growing amplitude (measured; "Why" a below). The hydrostatic increase of Adami et al. 2012 (eq. 27) is added
// for every dummy: p_b = p_i + rho_i g . (x_b - x_i), clamped at p_b >= 0 with p_i estimated by rho_i times the
// warm-start kappa (it is an explicit acceleration, step 4).
//
// Warm start: each particle's P summed over a solve's iterations is kept in the state as kappa = P / dt, a pressure
// over a density (SPHState::DensityStiffness, SPHState::DivergenceStiffness) and applied at the start of the next
// step's solve: the density one fully, the divergence one halved (not Shepard-averaged: the average is one-sided at
// the floor and the free surface and biases the hydrostatic field there, "Why" c). The first step starts from the
// hydrostatic kappa = |g| depth (SPHFluid::InitialState).
//
// Pressure output. The solves' P are Lagrange multipliers: the impulses that keep the density at rest over one
// step. The Pressure array is the physical pressure estimated from them in three parts (issue 25):
//  1. In time: the average over the Advance() call that produced the state (the source's output interval) of each
//     step's rho (kappa_density + kappa_divergence), weighted by dt: the pressure impulse over the interval divided
//     by its length, per particle (both solves: where the fluid is slightly expanded the density solve is idle and
//     the divergence solve carries the weight, "Why" d). One step's multiplier is not a physical pressure: at rest
//     its smooth part jitters from step to step (on the 2D column the least-squares scale of the one-step field
//     against rho0 g (H - z) went 0.89-1.30 from one sample to the next, that of the average over 50 ms 0.99-1.04
//     after t sqrt(g / H) = 2), and when water
//     hits a wall an incompressible fluid delivers a finite pressure impulse in one step, so the one-step value
//     grows as the step shrinks (SPHERIC Test 2's P1 peak was +57 % at dx = 0.04 m and +220 % at 0.03 m above the
//     experiment's; Cooker & Peregrine 1995, pressure-impulse theory of liquid impact). Without steps (the initial
//     state, a re-evaluation) it is the last step's.
//  2. Scaled by the strength of the particle's discrete gradient, gamma_i = sum_j k_ij |x_i - x_j|^2 over its fluid
//     and wall neighbours (each dummy once: it fills its lattice site; G_ij = k_ij (x_i - x_j)), relative to an
//     interior lattice particle's (SPHFluid::LatticeGradientStrength): the trace of sum_j V_j (x_i - x_j) (x)
//     grad W_ij over d, whose inverse is Bonet & Lok's (1999) gradient renormalisation. The pressure force of a
//     smooth p on the particles is gamma grad p, so gamma p is the pressure that balances the body forces. The
//     lattice correction makes gamma 1 on the starting lattice; once the particles have left it (the square lattice
//     is an unstable arrangement: on the hydrostatic column, vertical columns of particles start to slide past each
//     other, growing e-fold in about 25 ms, and the bottom rows collapse into a denser, hexagon-like packing at
//     t sqrt(g / H) = 1.1-1.3) the kernel sum still holds rho0 but gamma is 0.974 (2D) and 0.977 (3D) in the
//     interior (measured on the settled columns), so the multiplier read 2.3-2.6 % high at every depth.
//  3. Shepard-averaged over the particle and its fluid neighbours with poly6's shape (h^2 - r^2)^3 as the weight
//     (SmoothStiffness), whatever the density kernel: the spiky shape (h - r)^3 puts 8 times the nearest
//     neighbour's weight on the particle itself, so that the average hardly averaged (the per-particle scatter of
//     the settled multipliers, 6 % of rho0 g H in L2, only fell to 3.6 %; with poly6's shape to 2.0 %).
// Measured on the hydrostatic columns at the default tolerances (TestSPHDivergenceFree, pressure L2 against rho0 g
// (H - z), mean over t sqrt(g / H) = 8-10; 2D / 3D): the last step's multiplier, spiky-weighted (before): 0.047 /
// 0.036, a sample's value varying 0.035-0.062; + 1: 0.037 / 0.034; + 3: 0.020 / 0.026; + 2: 0.017 / 0.010 (with
// the tolerances at 1e-4 %: 0.042 / 0.040 before, 0.019 / 0.010 now).
//
// Every sum is a particle's own, over its CSR rows in their order; the averages are fixed-block reductions
// (ParallelReduce): the result does not depend on the number of threads.
//
// Pair list (issue 25, the cost of a step). The fields pass (step 1) writes, for every fluid pair of the CSR rows,
// the neighbour j and G_ij rounded to single precision into one array (SPHGradientPair, 16 bytes a pair; the double
// gradients it replaces took 24, and the passes read the 4-byte neighbour index from the rows besides). The
// solves' two passes per iteration (B d, A d) stream it and gather w_j or v_j: no grid walk, no distance, no kernel.
// The rounding keeps G_ji = -G_ij exact, and the own sums sum_f G are taken from the rounded G_ij, so the impulse
// and the density rate remain each other's adjoint (A symmetric). The passes are not limited by memory but by the
// additions' latency and the instruction count (a row of ~30 pairs summed into one accumulator): each component
// is summed in two interleaved partial sums (the row's even and odd entries), two components at a time with SSE2
// (RowImpulse, RowRate); d . A d and the step's limit are reduced in the A d pass, and the CG update of q, r, v in
// the preconditioning pass. Same iterations as the double, single-accumulator passes on the benchmarks (the bits
// differ); measured in results/spheric2.md, "Time to solution".
// The non-pressure accelerations (step 4) read the pair list too, with a second stream of two floats a pair
// (SPHPairShape: h - |r| for the viscosity, 1 / (k (r^2 + eps)) for the artificial viscosity, G_ij = k r), written
// by the fields pass: no positions, distances, square roots or kernels per pair, and no branch on whether a pair
// approaches; without surface tension the wall dummies are skipped there (they add nothing: their pressure is the
// solves'). On SPHERIC Test 2 (dx = 0.04 m, perf, one thread) that pass went from 19 % of a step to 11 %, the
// fields pass from 12 % to 15 %. With surface tension the pass sums over the positions as before.
//
// The hydrostatic column (TestSPHDivergenceFree; issue 25). Until a-d below were changed it never came to rest:
// its particles kept rearranging at speeds of order sqrt(g dx) and its pressure's relative L2 error against rho0 g
// (H - z) was 0.91 (2D) and 0.66 (3D). With a-d and the solves converged (tolerances 1e-4 %) it rests and the
// error is about 0.04 (the depth-binned means within 3 %; the rest is a per-particle scatter of the settled
// particles, which are no longer on their lattice); since e (the CG solver and the density solve's reduction) it
// does so at the default tolerances as well (0.047 (2D), 0.036 (3D)). With the Pressure output of "Pressure output"
// above (the multipliers averaged over time, scaled by the gradient strength, smoothed with a proper weight) the
// error is 0.017 (2D) and 0.010 (3D) at the default tolerances, within the 0.02.
// Why (measured on the test's 2D column, 20 x 40 particles, dt = 1 ms, starting from the exact hydrostatic kappa).
// Each cause was switched off alone in an experimental build; a-e are changed in this file:
//  a. The wall coupling is not the adjoint of the density rate: the solves push with the mirrored wall pressure
//     (factor 2 above) while the density rate, and the second factor of alpha's product, count each dummy once.
//     The pressure correction is then an oblique, not the mass-orthogonal, projection (the impulse operator is not
//     minus the transpose of the discrete divergence), so pressure does work on divergence-free motion: the
//     particles next to the side walls enter a wall-normal oscillation that flips sign every step and grows (0.1
//     to 1 m/s within about 300 steps), and it grows even when both solves are converged to 1e-4 %. Counting the
//     dummies twice in the rate and in alpha (a mirrored dummy moving with -v_i) removes it.
//  b. The hydrostatic wall increase only for dummies below the particle (rise > 0): one step after the hydrostatic
//     start, the particles next to a side wall fall at 8 % of g and are pushed off the wall at 5 % of g. With the
//     full Adami extrapolation p_b = p_i + rho_i g . (x_b - x_i) both are 0 (it then needs a clamp p_b >= 0 near
//     the free surface instead, where it pulls the top corner particles into the walls).
//  c. The Shepard average of the warm start is one-sided at the floor and at the surface: after one step the rows
//     within h of the floor fall at 1.4 % of g and the top row's kappa is 11 % high; without it both are 0.
//  d. The Pressure output is rho kappa of the density solve only. Where the fluid is slightly expanded (rho < rho0:
//     the density solve is idle there) the divergence solve's impulse carries the weight, so the physical pressure
//     is rho (kappa + P_div / dt), the sum of both solves' impulses over the step.
//  e. At the default tolerances the averages dilute the wall particles' errors (800 particles, 40 next to a wall):
//     the divergence solve takes 0 iterations on most steps, and it only removes compression rates, so the kick
//     that removes an existing compression (of order error h / dt: a TimeStep of 0.1 ms made it worse, up to
//     1.1 m/s) is never taken back. More precisely (measured): the divergence solve matters (a DivergenceTolerance
//     of 1e-4 % alone made the column rest, at 300 Jacobi iterations per step; 1e-2 % did not); with the divergence
//     solve converged by CG and the density solve by Jacobi, the column rested but what was left was a nearly
//     uniform offset of the pressure (the depth-binned means 1.1-1.9 times rho0 g (H - z) at rest),
//     the slowest mode of the system, set only by the free surface. Bounding the maximum error (at 1 or 10 times
//     the tolerance), the RMS, a two-sided divergence solve, or 2 minimum divergence iterations did not make it
//     rest. Changed: the solves are projected CG ("Solver"), and the density solve reduces its error's RMS
//     ("Stopping"): the column rests (kinetic energy 1.3e-6 (2D), 1.2e-5 (3D) rho0 g H V) without the divergence
//     solve iterating (0 iterations per step at rest).
// With a-d changed and the tolerances at 1e-4 % (up to 500 iterations), the 2D column comes to rest (kinetic
// energy 1.3e-6 rho0 g H V at t sqrt(g / H) = 10); without a it still blows up at t sqrt(g / H) = 1.4 (velocities
// to 0.7 m/s). What remains at those tolerances: a transient around t sqrt(g / H) = 1-2 (a roll along the side
// walls, up to 0.1 m/s, growing over tens of ms with a step of 1 or 0.5 ms alike) that leaves the particles disordered
// before it decays, hence the scatter. Neither a both-sided divergence solve, nor stopping on |error| wherever
// P > 0, nor a Shepard-averaged warm start changed that (measured). Measured since (the pressure averaged over
// windows of t sqrt(g / H) = 0.25): until t sqrt(g / H) = 0.8 the column keeps its lattice and its pressure L2 is
// 0.010-0.014 (0.003 in the bottom fifth); from 0.8 the third column of particles from each side wall slides
// down (1.5e-2 m/s at 0.8, 0.13 m/s at 1.1, the columns next to the walls rising) and the bottom rows collapse
// (L2 0.06-0.11 at 1.1-1.5, the surface 0.14 dx lower at rest: denser). That is the square lattice's instability
// (see "Pressure output", 2); the top corner particles, pulled into the side walls at 0.1 g from the first step
// (their own P is 0 at the surface, so their mirrored dummies push back with nothing while their fluid neighbours
// below push them wallwards), are not its cause: taking the dummies' pressure from the neighbours' Shepard-averaged
// kappa instead (Adami's extrapolation) cut that pull fivefold but not the collapse nor the final scatter.
#include "SPH/SPHFluid.h"

#include "Common/Parallel.h"
#include "SPH/SPHDensity.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace meshfree
{
namespace
{
constexpr Index ParallelThreshold = 4096; // as in SPHFluid.cxx
constexpr int MinimumIterations = 2;      // corrections per solve after a warm start, whatever the error
constexpr double ResidualReduction = 0.3; // the density solve reduces its error's RMS to 0.3 of its start ...
constexpr double ReductionFloor = 0.01;   // ... unless its average error is below 1 % of the tolerance
constexpr int SmoothingShape = 0;         // the Pressure output's Shepard weights: poly6's shape (h^2 - r^2)^3

using GradientPair = SPHGradientPair;

// The solves' two sums over a particle's row of fluid pairs [begin, end): sum_j w_j G_ij (RowImpulse) and
// sum_j v_j . G_ij (RowRate). They are bound by the additions' latency and the instruction count, not by memory:
// each component is summed in two interleaved partial sums (the row's even and odd entries) added at the end, two
// components at a time with SSE2 where it is there; the scalar code does the same operations in the same order.
#if defined(__SSE2__)
/// A pair's G_x, G_y widened to two doubles.
inline __m128d GradientXY(const GradientPair& p)
{
  return _mm_cvtps_pd(_mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p.Gradient))));
}
#endif

inline void RowImpulse(const GradientPair* pair, Index begin, Index end, const double* w, double out[3])
{
  Index s = begin;
#if defined(__SSE2__)
  __m128d xy0 = _mm_setzero_pd(), xy1 = _mm_setzero_pd();
  double z0 = 0.0, z1 = 0.0;
  for (; s + 1 < end; s += 2)
  {
    const GradientPair& a = pair[s];
    const GradientPair& b = pair[s + 1];
    const double wa = w[a.Neighbor], wb = w[b.Neighbor];
    xy0 = _mm_add_pd(xy0, _mm_mul_pd(_mm_set1_pd(wa), GradientXY(a)));
    z0 += wa * static_cast<double>(a.Gradient[2]);
    xy1 = _mm_add_pd(xy1, _mm_mul_pd(_mm_set1_pd(wb), GradientXY(b)));
    z1 += wb * static_cast<double>(b.Gradient[2]);
  }
  if (s < end)
  {
    const double wa = w[pair[s].Neighbor];
    xy0 = _mm_add_pd(xy0, _mm_mul_pd(_mm_set1_pd(wa), GradientXY(pair[s])));
    z0 += wa * static_cast<double>(pair[s].Gradient[2]);
  }
  alignas(16) double xy[2];
  _mm_store_pd(xy, _mm_add_pd(xy0, xy1));
  out[0] = xy[0];
  out[1] = xy[1];
  out[2] = z0 + z1;
#else
  double even[3] = { 0.0, 0.0, 0.0 }, odd[3] = { 0.0, 0.0, 0.0 };
  for (; s + 1 < end; s += 2)
  {
    const double wa = w[pair[s].Neighbor], wb = w[pair[s + 1].Neighbor];
    for (int a = 0; a < 3; ++a)
    {
      even[a] += wa * static_cast<double>(pair[s].Gradient[a]);
      odd[a] += wb * static_cast<double>(pair[s + 1].Gradient[a]);
    }
  }
  if (s < end)
  {
    const double wa = w[pair[s].Neighbor];
    for (int a = 0; a < 3; ++a)
    {
      even[a] += wa * static_cast<double>(pair[s].Gradient[a]);
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    out[a] = even[a] + odd[a];
  }
#endif
}

inline double RowRate(const GradientPair* pair, Index begin, Index end, const double* v)
{
  Index s = begin;
#if defined(__SSE2__)
  __m128d xy0 = _mm_setzero_pd(), xy1 = _mm_setzero_pd();
  double z0 = 0.0, z1 = 0.0;
  for (; s + 1 < end; s += 2)
  {
    const GradientPair& a = pair[s];
    const GradientPair& b = pair[s + 1];
    const double* va = v + 3 * static_cast<Index>(a.Neighbor);
    const double* vb = v + 3 * static_cast<Index>(b.Neighbor);
    xy0 = _mm_add_pd(xy0, _mm_mul_pd(_mm_loadu_pd(va), GradientXY(a)));
    z0 += va[2] * static_cast<double>(a.Gradient[2]);
    xy1 = _mm_add_pd(xy1, _mm_mul_pd(_mm_loadu_pd(vb), GradientXY(b)));
    z1 += vb[2] * static_cast<double>(b.Gradient[2]);
  }
  if (s < end)
  {
    const double* va = v + 3 * static_cast<Index>(pair[s].Neighbor);
    xy0 = _mm_add_pd(xy0, _mm_mul_pd(_mm_loadu_pd(va), GradientXY(pair[s])));
    z0 += va[2] * static_cast<double>(pair[s].Gradient[2]);
  }
  alignas(16) double xy[2];
  _mm_store_pd(xy, _mm_add_pd(xy0, xy1));
  return (xy[0] + xy[1]) + (z0 + z1);
#else
  double even[3] = { 0.0, 0.0, 0.0 }, odd[3] = { 0.0, 0.0, 0.0 };
  for (; s + 1 < end; s += 2)
  {
    const double* va = v + 3 * static_cast<Index>(pair[s].Neighbor);
    const double* vb = v + 3 * static_cast<Index>(pair[s + 1].Neighbor);
    for (int a = 0; a < 3; ++a)
    {
      even[a] += va[a] * static_cast<double>(pair[s].Gradient[a]);
      odd[a] += vb[a] * static_cast<double>(pair[s + 1].Gradient[a]);
    }
  }
  if (s < end)
  {
    const double* va = v + 3 * static_cast<Index>(pair[s].Neighbor);
    for (int a = 0; a < 3; ++a)
    {
      even[a] += va[a] * static_cast<double>(pair[s].Gradient[a]);
    }
  }
  return ((even[0] + odd[0]) + (even[1] + odd[1])) + (even[2] + odd[2]);
#endif
}
}

bool SPHFluid::FieldsMatch(const SPHState& state) const
{
  // Bit for bit (memcmp, not ==: -0 and 0 differ here as they may in the sums).
  const std::size_t n = state.Position.size();
  return !this->FieldsPosition.empty() && this->FieldsPosition.size() == n &&
    this->FieldsDensity.size() == state.Density.size() && 3 * state.Density.size() == n &&
    std::memcmp(this->FieldsPosition.data(), state.Position.data(), n * sizeof(double)) == 0 &&
    std::memcmp(this->FieldsDensity.data(), state.Density.data(), state.Density.size() * sizeof(double)) == 0;
}

void SPHFluid::DivergenceFreeFields(SPHState& state)
{
  this->InvalidateFields();
  const Index n = state.Size();
  this->Grid.SetCellsByPosition(false);
  this->Grid.Build(state.Position.data(), n, this->H);
  this->BuildNeighborLists(state, true);
  const Index* fs = this->FluidStart.data();
  const Index* bs = this->BoundaryStart.data();
  const std::int32_t* fn = this->FluidNeighbors.data();
  const std::int32_t* bn = this->BoundaryNeighbors.data();
  const double* x = state.Position.data();
  const double* bx = this->BoundaryPosition.data();
  state.Density.resize(n);
  this->InverseDensity.resize(n);
  this->Alpha.resize(n);
  this->Pairs.resize(fs[n]);
  const SPHConstants& c = this->Physics;
  const bool shapes = !c.Tension; // the non-pressure pass reads the pair list (AdvanceDivergenceFree)
  this->PairShapes.resize(shapes ? fs[n] : 0);
  this->WallCoefficient.resize(bs[n]);
  this->SelfGradient.resize(3 * n);
  this->GradientStrength.resize(n);
  const double strengthScale = this->LatticeGradientStrength > 0.0 ? 1.0 / this->LatticeGradientStrength : 0.0;
  const SPHDensityConstants dc = SPHDensityConstantsOf(c);
  const double cutoff = 1e-9 * this->LatticeFactorSum;
  double* rho = state.Density.data();
  GradientPair* pair = this->Pairs.data();
  SPHPairShape* shape = this->PairShapes.data();
  double* wall = this->WallCoefficient.data();
  double* self = this->SelfGradient.data();
  ParallelFor(
    n, 512,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        const double* xi = x + 3 * i;
        double sum[3] = { 0.0, 0.0, 0.0 }, wallSum[3] = { 0.0, 0.0, 0.0 }, squares = 0.0, strength = 0.0;
        // The density (the kernel sum over the same pairs in the same order as SPHParticleDensity: the same bits)
        // and, in the same pass, m grad W_ij = -G_ij, G_ij = coefficient (x_i - x_j), coefficient = m GradientNorm
        // shape(r) >= 0.
        SPHDensitySum density(dc);
        auto coefficient = [&](const double* xj, double* r, double& r2, double& distance) {
          for (int a = 0; a < 3; ++a)
          {
            r[a] = xi[a] - xj[a];
          }
          r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
          density.Add(r2, dc);
          double k = 0.0;
          distance = c.H;
          if (r2 < c.H2)
          {
            distance = std::sqrt(r2);
            if (r2 > 0.0)
            {
              k = c.PressureFactor * SPHGradientShape(r2, distance, c.H, c.H2, c.SpikyGradient);
            }
          }
          strength += k * r2; // each wall dummy once: it fills its lattice site
          return k;
        };
        // The fluid pairs' G_ij as the solves use them: rounded to float (the pair list), the sums from those.
        for (Index s = fs[i]; s < fs[i + 1]; ++s)
        {
          double r[3], r2, distance;
          const double k = coefficient(x + 3 * static_cast<Index>(fn[s]), r, r2, distance);
          if (shapes)
          {
            shape[s].Viscous = static_cast<float>(c.H - distance);
            shape[s].Artificial = k > 0.0 ? static_cast<float>(1.0 / (k * (r2 + c.ArtificialEpsilon))) : 0.0f;
          }
          GradientPair& out = pair[s];
          out.Neighbor = fn[s];
          double g[3];
          for (int a = 0; a < 3; ++a)
          {
            out.Gradient[a] = static_cast<float>(k * r[a]);
            g[a] = out.Gradient[a];
            sum[a] += g[a];
          }
          squares += g[0] * g[0] + g[1] * g[1] + g[2] * g[2]; // one addition a pair on the running sum
        }
        const double fluidSum[3] = { sum[0], sum[1], sum[2] };
        for (Index s = bs[i]; s < bs[i + 1]; ++s)
        {
          double r[3], r2, distance;
          const double k = coefficient(bx + 3 * static_cast<Index>(bn[s]), r, r2, distance); // static: no own term
          wall[s] = k;
          for (int a = 0; a < 3; ++a)
          {
            sum[a] += k * r[a];
          }
        }
        for (int a = 0; a < 3; ++a)
        {
          wallSum[a] = sum[a] - fluidSum[a];
        }
        rho[i] = density.Density(dc);
        this->InverseDensity[i] = 1.0 / rho[i];
        this->GradientStrength[i] = strength * strengthScale;
        // The particle's own kappa pushes it by (sum_f G + 2 sum_b G) (the mirrored wall pressure counts twice)
        // and its fluid neighbours by -G_ij; its density rate counts the mirrored dummies twice as well (below):
        // the rate changes by -dt kappa_i / rho_i (|sum_f G + 2 sum_b G|^2 + sum_f |G_ij|^2).
        const double mirrored[3] = { fluidSum[0] + 2.0 * wallSum[0], fluidSum[1] + 2.0 * wallSum[1],
          fluidSum[2] + 2.0 * wallSum[2] };
        for (int a = 0; a < 3; ++a)
        {
          self[3 * i + a] = mirrored[a];
        }
        const double total =
          mirrored[0] * mirrored[0] + mirrored[1] * mirrored[1] + mirrored[2] * mirrored[2] + squares;
        // Bounded below: the mirrored wall term can nearly cancel the first product for a particle wedged in a
        // corner or against an obstacle edge, and a tiny denominator would kick it at tens of m/s (measured in
        // SPHERIC Test 2); a tenth of an interior particle's value only slows the correction of sparse particles.
        const double bounded = std::max({ total, squares, 0.1 * this->LatticeFactorSum });
        this->Alpha[i] = total > cutoff || squares > cutoff ? rho[i] / bounded : 0.0;
      }
    },
    ParallelThreshold);
}

void SPHFluid::SmoothStiffness(const SPHState& state, const std::vector<double>& in, std::vector<double>& out) const
{
  // Shepard average over the fluid neighbours and the particle itself with the density kernel's shape (its
  // normalisation and the equal volumes m / rho ~ m / rho0 cancel): reproduces a constant field everywhere and,
  // where the neighbourhood is symmetric, a linear one (the hydrostatic kappa), and removes the checkerboard
  // modes that the pressure gradient does not see.
  const Index n = state.Size();
  const Index* fs = this->FluidStart.data();
  const std::int32_t* fn = this->FluidNeighbors.data();
  const double* x = state.Position.data();
  const SPHConstants& c = this->Physics;
  out.resize(n);
  ParallelFor(
    n, 512,
    [&](Index begin, Index end) {
      for (Index i = begin; i < end; ++i)
      {
        const double* xi = x + 3 * i;
        double w0 = SPHDensityShape(0.0, c.H, c.H2, SmoothingShape);
        double sw = w0, sk = w0 * in[i];
        for (Index s = fs[i]; s < fs[i + 1]; ++s)
        {
          const Index j = fn[s];
          const double* xj = x + 3 * j;
          const double r2 = (xi[0] - xj[0]) * (xi[0] - xj[0]) + (xi[1] - xj[1]) * (xi[1] - xj[1]) +
            (xi[2] - xj[2]) * (xi[2] - xj[2]);
          if (r2 < c.H2)
          {
            const double w = SPHDensityShape(r2, c.H, c.H2, SmoothingShape);
            sw += w;
            sk += w * in[j];
          }
        }
        out[i] = sk / sw;
      }
    },
    ParallelThreshold);
}

int SPHFluid::DivergenceFreeSolve(SPHState& state, double dt, bool density, double& error)
{
  const SPHParameters& p = this->Params;
  const Index n = state.Size();
  const Index* fs = this->FluidStart.data();
  const double* rho = state.Density.data();
  const double* inverse = this->InverseDensity.data();
  const double* alpha = this->Alpha.data();
  const GradientPair* pair = this->Pairs.data();
  const double* self = this->SelfGradient.data();
  double* v = state.Velocity.data();
  std::vector<double>& stored = density ? state.DensityStiffness : state.DivergenceStiffness;
  stored.resize(n, 0.0);
  // q = P / rho (the symmetric form's unknown), its change, the residual e, the search direction d, the
  // preconditioned residual z, A d, and the velocity change B d.
  this->Kappa.resize(n);
  this->KappaOverRho.resize(n);
  this->SolveResidual.resize(n);
  this->SolveDirection.assign(n, 0.0);
  this->SolvePreconditioned.resize(n);
  this->SolveProduct.resize(n);
  this->SolveVelocity.resize(3 * n);
  this->SolveFree.resize(n);
  double* q = this->Kappa.data();
  double* dq = this->KappaOverRho.data();
  double* r = this->SolveResidual.data();
  double* d = this->SolveDirection.data();
  double* z = this->SolvePreconditioned.data();
  double* ad = this->SolveProduct.data();
  double* u = this->SolveVelocity.data();
  char* isFree = this->SolveFree.data();
  const double rho0 = p.RestDensity;
  const double tolerance = 0.01 * (density ? p.DensityTolerance : p.DivergenceTolerance);
  const bool flat = p.Dimension == 2;

  // out_i (+)= (B w)_i = sum_j (w_i + w_j) G_ij + sum_b 2 w_i G_ib (G = -m grad W): the velocity change of the
  // impulse potentials w = P / rho (mirrored walls: p_b = p_i, rho_b = rho_i), computed as
  // w_i (sum_j G_ij + 2 sum_b G_ib) + sum_j w_j G_ij with the pair gradients and own sums of DivergenceFreeFields
  // (the solves' passes then read no positions and no wall pairs: they were two thirds of a DFSPH step).
  auto impulse = [&](const double* w, double* out, bool add) {
    ParallelFor(
      n, 512,
      [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i)
        {
          double dv[3];
          RowImpulse(pair, fs[i], fs[i + 1], w, dv);
          const double* gi = self + 3 * i;
          dv[0] += w[i] * gi[0];
          dv[1] += w[i] * gi[1];
          dv[2] += w[i] * gi[2];
          if (flat)
          {
            dv[1] = 0.0;
          }
          for (int a = 0; a < 3; ++a)
          {
            out[3 * i + a] = add ? out[3 * i + a] + dv[a] : dv[a];
          }
        }
      },
      ParallelThreshold);
  };

  // A compression that is already there (particles placed too close, e.g. a fluid lattice not aligned with the
  // walls' one, or a splash landing) is removed over several steps: at most the compression that a correction
  // speed of sqrt(|g| h) (at least 0.1 m/s) removes in one step. The papers' form removes it in one step, which
  // kicks the particles at (compression / rho0) h / dt: tens of m/s at the start of SPHERIC Test 2 (measured).
  const double* g = this->Physics.Gravity;
  const double speed = std::max(std::sqrt(std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]) * this->H), 0.1);
  const double overlap = rho0 * speed * dt / this->H;
  // out_i = e_i: the density error min(rho_i - rho0, overlap) + dt Drho/Dt_i (density solve) or the density rate
  // Drho/Dt_i (divergence solve) of the velocities `vel`; with offset = false the part linear in vel only, so
  // that out = -(A w) for vel = B w.
  auto errorAt = [&](const double* vel, Index i, bool offset) {
    // Drho/Dt = sum_j m (v_i - v_j) . grad W_ij = -sum_j (v_i - v_j) . G_ij - sum_b 2 v_i . G_ib: the mirrored
    // dummy moves with -v_i (as its pressure is p_i), the adjoint of the push's factor 2; computed as
    // sum_j v_j . G_ij - v_i . (sum_j G_ij + 2 sum_b G_ib).
    const double* vi = vel + 3 * i;
    double rate = RowRate(pair, fs[i], fs[i + 1], vel);
    const double* gi = self + 3 * i;
    rate -= vi[0] * gi[0] + vi[1] * gi[1] + vi[2] * gi[2];
    return density ? (offset ? std::min(rho[i] - rho0, overlap) : 0.0) + dt * rate : rate;
  };
  auto errors = [&](const double* vel, double* out, bool offset) {
    ParallelFor(
      n, 512,
      [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i)
        {
          out[i] = errorAt(vel, i, offset);
        }
      },
      ParallelThreshold);
  };

  // The solve works on P = kappa dt (the velocity impulse potential: dv_i = sum_j (P_i / rho_i + P_j / rho_j) G_ij).
  // The state keeps both solves' kappa = P / dt (a pressure over a density, independent of dt). Warm start: last
  // step's total (density: fully; divergence: halved) is applied first.
  const double toP = dt;
  const double weight = density ? 1.0 : 0.5;
  bool any = false;
  for (Index i = 0; i < n; ++i)
  {
    const double start = std::isfinite(stored[i]) && alpha[i] > 0.0 ? std::max(weight * stored[i] * toP, 0.0) : 0.0;
    q[i] = start * inverse[i];
    any = any || q[i] != 0.0;
  }
  if (any)
  {
    impulse(q, v, true);
  }

  // Projected preconditioned conjugate gradients (see the header): minimise 1/2 q.A q - e0.q over q >= 0, A =
  // s B^T B (s = dt for the density solve, 1 for the divergence one), whose gradient is -e (the error at the
  // current velocities v0 + B q); Jacobi preconditioner 1 / (s |B_i|^2) >= alpha_i / (rho_i s), DFSPH's factor.
  const double scaleAd = density ? dt : 1.0;
  const double scale = density ? 1.0 / rho0 : dt / rho0;
  struct Sums
  {
    double Compression = 0.0, Squares = 0.0, Rz = 0.0, Chopped = 0.0;
  };
  auto combine = [](Sums a, const Sums& b) {
    a.Compression += b.Compression;
    a.Squares += b.Squares;
    a.Rz += b.Rz;
    a.Chopped += b.Chopped;
    return a;
  };
  // z on the free set, r . z there, the chopped gradient's size off it (particles at P = 0 that a positive
  // error would lift), and the error measures: average and squares of max(e, 0) (a fraction of rho0).
  // With step != 0 it first takes the CG step on particle i (q, r and v along d, A d and B d: the update fused
  // into this pass).
  auto precondition = [&](bool choose, double step) {
    return ParallelReduce(
      n, 4096, Sums(),
      [&](Index begin, Index end) {
        Sums sum;
        for (Index i = begin; i < end; ++i)
        {
          if (step != 0.0)
          {
            q[i] = std::max(q[i] + step * d[i], 0.0);
            r[i] -= step * ad[i];
            for (int a = 0; a < 3; ++a)
            {
              v[3 * i + a] += step * u[3 * i + a];
            }
          }
          const double c = std::max(r[i], 0.0) * scale;
          sum.Compression += c;
          sum.Squares += c * c;
          if (choose)
          {
            isFree[i] = alpha[i] > 0.0 && (q[i] > 0.0 || r[i] > 0.0);
          }
          const double dinv = alpha[i] * inverse[i] / scaleAd;
          if (isFree[i])
          {
            z[i] = dinv * r[i];
            sum.Rz += r[i] * z[i];
          }
          else
          {
            z[i] = 0.0;
            if (alpha[i] > 0.0 && r[i] > 0.0)
            {
              sum.Chopped += dinv * r[i] * r[i];
            }
          }
        }
        return sum;
      },
      combine, ParallelThreshold);
  };
  // d = z + beta d (beta = 0: restart on z).
  auto direction = [&](double beta) {
    ParallelFor(
      n, 4096,
      [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i)
        {
          d[i] = beta == 0.0 ? z[i] : (isFree[i] ? z[i] + beta * d[i] : 0.0);
        }
      },
      ParallelThreshold);
  };
  errors(v, r, true);
  Sums sums = precondition(true, 0.0);
  const double startSquares = sums.Squares;
  double rz = sums.Rz;
  direction(0.0);
  int iterations = 0;
  const double count = static_cast<double>(std::max<Index>(n, 1));
  for (;;)
  {
    error = sums.Compression / count;
    // Converged: the average error at the tolerance and, for the density solve, the error's RMS reduced to
    // ResidualReduction of its value after the warm start (or the average a hundredth of the tolerance): see
    // "Stopping" in the header.
    const bool reduced = !density || sums.Squares <= ResidualReduction * ResidualReduction * startSquares ||
      error <= ReductionFloor * tolerance;
    if (!std::isfinite(error) || iterations >= p.MaximumIterations ||
      (error <= tolerance && reduced && (iterations >= MinimumIterations || !any)))
    {
      break;
    }
    if (!(rz > 0.0))
    {
      break; // no free particle has an error left to correct (the rest have alpha = 0)
    }
    impulse(d, u, false);
    // A d = -(the error's linear part at u = B d), with d . A d and the largest step that keeps q >= 0 reduced in
    // the same pass.
    struct Step
    {
      double DAd = 0.0, Dr = 0.0, Limit = std::numeric_limits<double>::infinity();
    };
    const Step st = ParallelReduce(
      n, 1024, Step(),
      [&](Index begin, Index end) {
        Step s;
        for (Index i = begin; i < end; ++i)
        {
          ad[i] = -errorAt(u, i, false);
          s.DAd += d[i] * ad[i];
          s.Dr += d[i] * r[i];
          if (d[i] < 0.0)
          {
            s.Limit = std::min(s.Limit, q[i] / -d[i]);
          }
        }
        return s;
      },
      [](Step a, const Step& b) {
        a.DAd += b.DAd;
        a.Dr += b.Dr;
        a.Limit = std::min(a.Limit, b.Limit);
        return a;
      },
      ParallelThreshold);
    if (!(st.DAd > 0.0) || !std::isfinite(st.DAd))
    {
      break;
    }
    ++iterations;
    if (!(st.Dr > 0.0))
    {
      // After an expansion the direction kept its conjugate part (below) and need not descend: restart on z.
      sums = precondition(true, 0.0);
      rz = sums.Rz;
      direction(0.0);
      continue;
    }
    const double step = st.Dr / st.DAd; // the exact line search (d . r = r . z for a conjugate direction)
    bool restart = false;
    if (step > st.Limit)
    {
      // Expansion: the whole step projected on q >= 0, the velocities changed by what q actually changed, the
      // error recomputed; then the CG restarts on the new free set.
      ParallelFor(
        n, 2048,
        [&](Index begin, Index end) {
          for (Index i = begin; i < end; ++i)
          {
            const double next = std::max(q[i] + step * d[i], 0.0);
            dq[i] = next - q[i];
            q[i] = next;
          }
        },
        ParallelThreshold);
      impulse(dq, v, true);
      errors(v, r, true);
      sums = precondition(true, 0.0);
    }
    else
    {
      sums = precondition(false, step);
    }
    // Proportioning (Dostal's criterion with Gamma = 1): when the particles held at P = 0 have more error to
    // correct than the free ones, restart with them freed.
    restart = restart || sums.Chopped > sums.Rz;
    if (restart)
    {
      sums = precondition(true, 0.0);
      rz = sums.Rz;
      direction(0.0);
    }
    else
    {
      const double beta = sums.Rz / rz;
      rz = sums.Rz;
      direction(beta);
    }
  }
  for (Index i = 0; i < n; ++i)
  {
    stored[i] = q[i] * rho[i] / toP;
  }
  return iterations;
}

bool SPHFluid::ChooseDivergenceFreeStep(
  const SPHState& state, double time, double targetTime, long steps, double& dt, bool& last)
{
  const SPHParameters& p = this->Params;
  const Index n = state.Size();
  struct Maximum
  {
    double V2 = 0.0;
    bool Finite = true;
  };
  const Maximum m = ParallelReduce(
    n, 4096, Maximum(),
    [&](Index begin, Index end) {
      Maximum r;
      for (Index i = begin; i < end; ++i)
      {
        const double* v = &state.Velocity[3 * i];
        const double* x = &state.Position[3 * i];
        const double v2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        r.Finite = r.Finite && std::isfinite(v2) && std::isfinite(x[0] + x[1] + x[2]);
        r.V2 = std::max(r.V2, v2);
      }
      return r;
    },
    [](Maximum a, const Maximum& b) {
      a.V2 = std::max(a.V2, b.V2);
      a.Finite = a.Finite && b.Finite;
      return a;
    },
    ParallelThreshold);
  if (!m.Finite)
  {
    std::ostringstream s;
    s << "the DFSPH simulation became unstable (non-finite velocity or position) at t = " << time;
    this->Error = s.str();
    return false;
  }
  const double* g = this->Physics.Gravity;
  const double gNorm = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
  auto stable = [&](double lambda) {
    double limit = std::numeric_limits<double>::infinity();
    const double vmax = std::sqrt(m.V2);
    if (vmax > 0.0)
    {
      limit = std::min(limit, 0.4 * this->H / vmax);
    }
    if (gNorm > 0.0)
    {
      limit = std::min(limit, std::sqrt(this->H / gNorm));
    }
    if (this->Nu > 0.0)
    {
      limit = std::min(limit, 0.125 * this->H2 / this->Nu);
    }
    return lambda * limit;
  };
  if (p.CFLNumber > 0.0)
  {
    dt = std::min(p.TimeStep, stable(std::min(p.CFLNumber, MaximumCFLNumber(SPHSolver::DFSPH))));
  }
  else
  {
    dt = p.TimeStep;
    const double limit = stable(MaximumCFLNumber(SPHSolver::DFSPH));
    if (dt > limit)
    {
      dt = limit;
      ++this->ReducedStepCount;
    }
  }
  return this->LandStep(time, targetTime, steps, dt, last);
}

void SPHFluid::DivergenceFreeOutput(SPHState& state)
{
  const Index n = state.Size();
  state.DensityStiffness.resize(n, 0.0);
  state.DivergenceStiffness.resize(n, 0.0);
  state.Acceleration.resize(3 * n, 0.0);
  state.Pressure.resize(n);
  if (n == 0)
  {
    state.Density.clear();
    return;
  }
  this->DivergenceFreeFields(state);
  this->FieldsPosition = state.Position; // the next Advance()'s first step starts from these fields
  this->FieldsDensity = state.Density;
  // The pressure the fluid felt over the Advance() call that produced the state (the source's output interval):
  // each particle's pressure impulse over those steps, sum of dt rho (kappa_density + kappa_divergence), over their
  // time span, Shepard-averaged over the neighbourhood ("Pressure output" in the header). Without steps (the
  // initial state, a re-evaluation) the last step's: rho (kappa_density + kappa_divergence), Shepard-averaged.
  const bool averaged =
    this->PressureImpulseTime > 0.0 && static_cast<Index>(this->PressureImpulse.size()) == n;
  this->Kappa.resize(n);
  for (Index i = 0; i < n; ++i)
  {
    this->Kappa[i] = this->GradientStrength[i] *
      (averaged ? this->PressureImpulse[i] / this->PressureImpulseTime
                : state.Density[i] * (state.DensityStiffness[i] + state.DivergenceStiffness[i]));
  }
  this->PressureImpulseTime = 0.0;
  this->SmoothStiffness(state, this->Kappa, this->Smoothed);
  for (Index i = 0; i < n; ++i)
  {
    state.Pressure[i] = std::max(0.0, this->Smoothed[i]);
  }
}

SPHFluid::Status SPHFluid::AdvanceDivergenceFree(SPHState& state, double targetTime, const ProgressFunction& progress)
{
  const SPHParameters& p = this->Params;
  const double start = state.Time;
  const Index n = state.Size();
  state.Report = SPHSolverReport();
  state.DensityStiffness.resize(n, 0.0);
  state.DivergenceStiffness.resize(n, 0.0);
  state.Acceleration.resize(3 * n, 0.0);
  const SPHConstants& c = this->Physics;
  this->PressureImpulse.assign(n, 0.0);
  this->PressureImpulseTime = 0.0;
  long steps = 0;
  while (state.Time < targetTime)
  {
    if (n == 0)
    {
      state.Time = targetTime;
      break;
    }
    if (state.Steps % p.ReorderInterval == 0)
    {
      this->Reorder(state);
    }
    // The first step of a call starts where the last call's output left the fields, unless the state differs (a
    // state restored from a cache, a reorder above): computed once, not twice, per output interval.
    if (steps > 0 || !this->FieldsMatch(state))
    {
      this->DivergenceFreeFields(state);
    }
    double dt;
    bool last;
    if (!this->ChooseDivergenceFreeStep(state, state.Time, targetTime, steps, dt, last))
    {
      return Status::Failed;
    }
    // The velocities made divergence-free at the positions they move from.
    double divergenceError = 0.0, densityError = 0.0;
    const int divergenceIterations = this->DivergenceFreeSolve(state, dt, false, divergenceError);
    // Non-pressure accelerations (SPHAcceleration with zero pressure terms), explicit.
    this->OldVelocity = state.Velocity;
    {
      const double* x = state.Position.data();
      const double* v = this->OldVelocity.data();
      const double* rho = state.Density.data();
      const double* inverse = this->InverseDensity.data();
      const double* bx = this->BoundaryPosition.data();
      const Index* fs = this->FluidStart.data();
      const Index* bs = this->BoundaryStart.data();
      const std::int32_t* fn = this->FluidNeighbors.data();
      const std::int32_t* bn = this->BoundaryNeighbors.data();
      double* acc = state.Acceleration.data();
      double* vNew = state.Velocity.data();
      const double* kappa = state.DensityStiffness.data();
      const SPHGradientPair* pairs = this->Pairs.data();
      const SPHPairShape* shapes = this->PairShapes.empty() ? nullptr : this->PairShapes.data();
      ParallelFor(
        n, 256,
        [&](Index begin, Index end) {
          for (Index i = begin; i < end; ++i)
          {
            SPHAcceleration a(x + 3 * i, v + 3 * i, rho[i], inverse[i], 0.0);
            if (shapes != nullptr)
            {
              // From the pair list (no surface tension): a wall dummy adds nothing here (its pressure term is the
              // solves', and there is no artificial viscosity against walls).
              for (Index s = fs[i]; s < fs[i + 1]; ++s)
              {
                const SPHGradientPair& e = pairs[s];
                const Index j = e.Neighbor;
                const double g[3] = { e.Gradient[0], e.Gradient[1], e.Gradient[2] };
                a.NonPressure(g, shapes[s].Viscous, shapes[s].Artificial, v + 3 * j, rho[j], inverse[j], c);
              }
            }
            else
            {
              for (Index s = fs[i]; s < fs[i + 1]; ++s)
              {
                const Index j = fn[s];
                a.Fluid(x + 3 * j, v + 3 * j, rho[j], inverse[j], 0.0, c);
              }
              for (Index s = bs[i]; s < bs[i + 1]; ++s)
              {
                a.Wall(bx + 3 * static_cast<Index>(bn[s]), 0.0, c);
              }
            }
            a.Finish(acc + 3 * i, c);
            // The hydrostatic part of the mirrored wall pressure (Adami et al. 2012, eq. 27): p_b = p_i + rho_i g .
            // (x_b - x_i) for every dummy (below the particle it adds, above it subtracts: with both, a particle
            // next to a side wall feels the hydrostatic gradient exactly), its p_i part the solves'; clamped at
            // p_b >= 0 with p_i estimated by the warm start rho_i kappa_i (near the free surface the dummies above
            // would otherwise pull the particles into the wall).
            {
              const double* xi = x + 3 * i;
              const double floor = -std::max(kappa[i], 0.0); // rise >= -p_i / rho_i
              for (Index s = bs[i]; s < bs[i + 1]; ++s)
              {
                const double* xb = bx + 3 * static_cast<Index>(bn[s]);
                const double r[3] = { xi[0] - xb[0], xi[1] - xb[1], xi[2] - xb[2] };
                const double rise =
                  std::max(-(c.Gravity[0] * r[0] + c.Gravity[1] * r[1] + c.Gravity[2] * r[2]), floor);
                // (no branch on rise = 0, a dummy level with the particle: it adds +-0, leaving acc as it is)
                const double k = this->WallCoefficient[s] * rise * inverse[i];
                acc[3 * i] += k * r[0];
                acc[3 * i + 1] += c.Dimension == 2 ? 0.0 : k * r[1];
                acc[3 * i + 2] += k * r[2];
              }
            }
            for (int k = 0; k < 3; ++k)
            {
              vNew[3 * i + k] = v[3 * i + k] + dt * acc[3 * i + k];
            }
          }
        },
        ParallelThreshold);
    }
    const int densityIterations = this->DivergenceFreeSolve(state, dt, true, densityError);
    if (!std::isfinite(densityError) || !std::isfinite(divergenceError))
    {
      std::ostringstream s;
      s << "the DFSPH pressure solve diverged (non-finite error) at t = " << state.Time;
      this->Error = s.str();
      return Status::Failed;
    }
    // The step's acceleration (for output) and the drift with the wall and obstacle projection.
    const double invDt = 1.0 / dt;
    ParallelFor(
      n, 2048,
      [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i)
        {
          for (int k = 0; k < 3; ++k)
          {
            state.Acceleration[3 * i + k] = (state.Velocity[3 * i + k] - this->OldVelocity[3 * i + k]) * invDt;
            state.Position[3 * i + k] += dt * state.Velocity[3 * i + k];
          }
          this->PressureImpulse[i] +=
            dt * state.Density[i] * (state.DensityStiffness[i] + state.DivergenceStiffness[i]);
        }
        this->Enforce(state, begin, end);
      },
      ParallelThreshold);
    SPHSolverReport& r = state.Report;
    ++r.Steps;
    r.DensityIterations += densityIterations;
    r.DivergenceIterations += divergenceIterations;
    r.LastDensityIterations = densityIterations;
    r.LastDivergenceIterations = divergenceIterations;
    r.AverageDensityError = densityError;
    r.MaxAverageDensityError = std::max(r.MaxAverageDensityError, densityError);
    const bool unconverged = (densityIterations >= p.MaximumIterations && densityError > 0.01 * p.DensityTolerance) ||
      (divergenceIterations >= p.MaximumIterations && divergenceError > 0.01 * p.DivergenceTolerance);
    if (unconverged)
    {
      ++r.UnconvergedSteps;
      ++this->UnconvergedStepCount;
    }
    this->PressureImpulseTime += dt;
    state.Time = last ? targetTime : state.Time + dt;
    ++state.Steps;
    ++steps;
    if (progress && (steps & 15) == 0 && !progress((state.Time - start) / (targetTime - start)))
    {
      this->DivergenceFreeOutput(state);
      return Status::Aborted;
    }
  }
  this->DivergenceFreeOutput(state);
  return Status::Ok;
}

} // namespace meshfree
