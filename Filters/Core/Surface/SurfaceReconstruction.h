// SPDX-License-Identifier: BSD-3-Clause
/**
 * @brief Triangle mesh of the surface a point cloud (or a particle fluid) samples: the driver that chains
 *        normals, an implicit surface and the sparse contouring (research/surface.md).
 *
 * Methods
 * - MLS (default): the algebraic point-set surface (PointSetSurface.h) of the oriented cloud.
 * - WLS: a partition of unity of local weighted least-squares fits (PatchSurface.h; Ohtake's MPU idea).
 * - SPH: the colour-field surface of particles (FluidSurface.h); no normals needed.
 * For MLS and WLS, normals are taken from the input when given (unit-normalised; invalid ones make the point
 * ignored), otherwise estimated and oriented outward (SurfaceNormals.h, NormalOrientation.h).
 *
 * Scales (all automatic unless set): the neighbourhood radius R_i of every point follows its density (its
 * NeighborCount-th neighbour) and the cloud's noise (SurfaceNormals.h); the implicit fits use SupportScale x R_i
 * (wide enough to bridge the gaps of random sampling, research §4 "Support too small = holes");
 * SupportRadius > 0 fixes R_i. CellSize 0 picks the spacing of the samples (MLS, WLS) or half the particle
 * spacing (SPH), enlarged when the lattice would exceed 2^21 cells per axis.
 *
 * The mesh is closed wherever the field is defined (SparseContour.h); its vertices are then moved onto the
 * surface (Project(), at most one cell) and get the field's unit outward gradient as normal, or the mean of
 * their triangles' normals where the projection fails.
 *
 * Regions without samples (MLS, WLS; issue 23). HoleFilling On continues the fits there by the samples'
 * generalized winding number (HoleFilling.h, WindingNumber.h): the field is then defined everywhere, the
 * continuation walks across every hole and the mesh is closed. Auto (default) does so when the cloud encloses a
 * volume: OpenShare = |sum a_i n_i| / sum a_i (a_i = pi r_k^2 / k) is below ClosedBelow = 0.45. A closed surface's
 * normals cancel (0); with holes it is the holes' flat projected area over the data's; a single view of a convex
 * object gives its mean cosine of incidence, at least 0.5 (a hemisphere: 0.5), a terrain patch about 1.
 * Measured on virtual scans (Testing/Core/VirtualScan.h): four views from 35 degrees above, 0.31 (sphere), 0.43
 * (torus); one view, 0.73 / 0.69; Data/scan_torus.pcd 0.27. Off (or Auto on an open cloud) keeps the fits alone
 * and trims the mesh to the data (DataSupport.h): a vertex stays when it is within one local spacing of a sample
 * (r_k sqrt(pi / k), with 3 sigma of noise), or within TrimSpacings of them and surrounded by samples (a gap
 * that limit closes; one it bridges only part of the way is opened back to its rim).
 * Every method gives each vertex its DistanceToData; MLS and WLS drop the pieces fewer than NeighborCount
 * samples support (RemoveStrayPieces).
 */
#ifndef meshfree_SurfaceReconstruction_h
#define meshfree_SurfaceReconstruction_h

#include "Common/NeighborGrid.h"
#include "Common/Progress.h"
#include "Surface/NormalOrientation.h"
#include "Surface/SparseContour.h"
#include "Surface/SurfaceNormals.h"

#include <cmath>
#include <string>
#include <vector>

namespace meshfree
{

enum class SurfaceMethod
{
  MLS = 0,
  WLS = 1,
  SPH = 2
};

/// "MLS", "WLS", "SPH".
const char* SurfaceMethodName(SurfaceMethod method);

/// MLS/WLS: whether the regions without samples are closed (HoleFilling.h).
enum class HoleFillingMode
{
  Off = 0,
  On = 1,
  Auto = 2 // on when the cloud encloses a volume (OpenShare below ClosedBelow)
};

struct SurfaceOptions
{
  SurfaceMethod Method = SurfaceMethod::MLS;
  int NeighborCount = 20;      // MLS/WLS: the smallest neighbourhood (see SurfaceNormals.h)
  double SupportRadius = 0.0;  // > 0: MLS/WLS neighbourhood radius R, SPH kernel radius H
  double SupportScale = 2.0;   // MLS/WLS: the fits' support relative to r_k (or to SupportRadius)
  double NoiseScale = 2.0;     // MLS/WLS: ... and at least this times the radius the noise asks for
  double CellSize = 0.0;       // 0: automatic
  double Level = 0.5;          // SPH: colour level of the surface
  bool Anisotropic = false;    // SPH: Yu & Turk's anisotropic kernels
  bool ProjectVertices = true; // move the contour's vertices onto the surface
  int MaximumRounds = 512;     // continuation rounds of the contouring
  HoleFillingMode HoleFilling = HoleFillingMode::Auto; // MLS/WLS
  double ClosedBelow = 0.45;   // Auto: the cloud encloses a volume when its OpenShare is below this
  double TrimSpacings = 2.5;   // MLS/WLS, holes left open: the border stays within this many local spacings
  bool RemoveStrayPieces = true; // drop pieces fewer than NeighborCount samples support (DataSupport.h)
  // Distributed (Common/Distribution.h): the input is this process' points and their halo; the grid is framed by
  // the whole cloud (FrameBounds: the bounds of its valid points, FramePoints: their number; NeighborGrid::SetFrame);
  // each process contours the lattice cells whose centre it owns (Distribution::OwnsPosition) and the mesh is
  // their triangles; normals, fits and statistics are the whole cloud's. Every step is collective: a progress
  // callback given with it must not abort (an abort would leave the other processes waiting). Null: serial.
  const Distribution* Processes = nullptr;
  bool Framed = false;
  double FrameBounds[6] = { 0.0, 0.0, 0.0, 0.0, 0.0, 0.0 };
  Index FramePoints = 0;
};

struct SurfaceInput
{
  const double* Points = nullptr;  // 3 per point
  Index Count = 0;
  const double* Normals = nullptr; // 3 per point, outward (MLS/WLS), optional
  const double* Volumes = nullptr; // V_j = m_j / rho_j (SPH), optional
};

struct SurfaceReport
{
  Index InputPoints = 0;
  Index InvalidPoints = 0;      // NaN/Inf coordinates
  Index Duplicates = 0;         // MLS/WLS: exact duplicates merged (UniqueCloud.h)
  Index PointsWithoutNormal = 0; // MLS/WLS: no valid normal (given or estimated); ignored by the fits
  bool NormalsEstimated = false;
  Index Outliers = 0;           // MLS/WLS: points left out of the fits (see SurfaceNormals.h)
  OrientationReport Orientation;
  CloudScale Scale;             // MLS/WLS: spacing, noise, noise radius
  double CellSize = 0.0;        // used
  bool CellSizeEnlarged = false; // the requested or automatic size needed more lattice cells than exist
  double SupportRadius = 0.0;   // median fit support (MLS/WLS) or kernel radius H (SPH)
  double ParticleVolume = 0.0;  // SPH: total volume of the particles
  ContourReport Contour;
  Index ProjectedVertices = 0;
  // MLS/WLS: |sum a_i n_i| / sum a_i of the oriented samples (areas a_i, HoleFilling.h): 0 for a closed
  // surface (its normals cancel), 1 for a flat patch; the area of the holes' flat projection over the data's.
  double OpenShare = 0.0;
  bool HolesFilled = false;        // the winding number continued the fits (HoleFilling On, or Auto and closed)
  Index TrimmedTriangles = 0;      // open surface: triangles beyond the data's border
  Index Pieces = 0;                // connected pieces before the stray ones were removed
  Index RemovedPieces = 0;         // pieces too few samples support
  Index RemovedTriangles = 0;      // their triangles
  double FillSeconds = 0.0;        // OpenShare (the winding number's tree is built on first use, while contouring)
  // Wall-clock seconds of the stages: neighbourhoods, normals and the field's set-up; contouring; projection.
  double SetupSeconds = 0.0;
  double ContourSeconds = 0.0;
  double ProjectionSeconds = 0.0;
  // Distributed: how far beyond the complete part of the local cloud a computation reached (Distribution.h's
  // Shortfall; > 0: widen the halo by it and rerun); -infinity when serial.
  double Shortfall = -HUGE_VAL;
  bool Aborted = false;
};

/// The surface: triangles, and per vertex a unit outward normal and the distance to the nearest sample.
struct SurfaceMesh : TriangleMesh
{
  std::vector<double> Normals;
  std::vector<double> DistanceToData;
};

/// Reconstructs the surface of the input. Returns false with `error` set for invalid options, and false
/// (empty mesh, report.Aborted) when aborted. An input without valid points gives an empty mesh and true.
bool ReconstructSurface(const SurfaceInput& input, const SurfaceOptions& options, SurfaceMesh& mesh,
  SurfaceReport& report, std::string& error, const ProgressCallback& progress = ProgressCallback());

} // namespace meshfree

#endif
