/**
 * @class   vtkMeshFreeSPHFluid
 * @brief   time-dependent SPH fluid source (Müller, Charypar & Gross 2003; thesis ch. 5)
 *
 * Fills `FluidBounds` with particles on a lattice of `ParticleSpacing` (mass `RestDensity`·spacing^dim) inside
 * the closed container `DomainBounds` and simulates them with the VTK-free core (meshfree::SPHFluid, see
 * Filters/Core/SPHFluid.h for the model, kernels, walls and time stepping). `Dimension` 2 simulates the x–z plane.
 *
 * Time: the source reports the time steps 0, OutputInterval, …, EndTime, and the output is the state at exactly
 * the requested time (clamped to [0, EndTime]): the time steps land on it. The states at the reported times are
 * kept in a bounded cache (`CacheSize` states, meshfree::StateCache): a request restores the nearest earlier
 * cached state and simulates forward from there, so revisiting a time or stepping backwards never restarts from
 * t = 0. A time between two reported ones (ParaView's "Sequence" or "Real Time" animation) is simulated from the
 * reported time before it and not cached, so a state never depends on what was requested before. Any change of
 * a property that affects the simulation, or of the `Obstacles` input, empties the cache.
 *
 * Optional input port 0, `Obstacles`: closed polygonal surfaces (polygons and triangle strips are triangulated)
 * that the fluid flows around. ParaView offers the two uses as two proxies, as it does for its Stream Tracer: the
 * pure source `SPHFluid` (no input property, so nothing is ever connected to it behind the user's back) and
 * `SPHFluidWithObstacles`, whose required input is this port.
 *
 * Output: vtkPolyData, one vertex per particle, point arrays `Velocity` (3), `Density`, `Pressure`, `Id`
 * (stable across time), and on request `Acceleration` (3) and `NeighborCount`. Field data: `Backend` (what ran),
 * `Solver` ("WCSPH" or "DFSPH"), and for the output interval that ended at this state `DensityIterations` and
 * `DivergenceIterations` (2 values each: the last step's, and the mean per step), `AverageDensityError` (2 values:
 * the last step's and the largest over the interval; DFSPH: the density solve's average compression, a fraction of
 * ρ0; WCSPH: the mean of max(ρ/ρ0 − 1, 0) over the particles, iterations 0).
 *
 * Pieces (MPI: pvbatch, pvserver): every rank simulates the whole fluid (the core gives the same bits whatever the
 * thread count) and outputs only the particles whose index lies in its contiguous share of [0, n), chosen by
 * UPDATE_PIECE_NUMBER of UPDATE_NUMBER_OF_PIECES, so that each particle is on exactly one rank. The Obstacles,
 * which arrive split across ranks, are gathered on every rank (a collective call: every rank takes part) and put
 * in a canonical order, so the simulation does not depend on the number of ranks. The cache is per rank and
 * identical on all of them.
 */
#ifndef vtkMeshFreeSPHFluid_h
#define vtkMeshFreeSPHFluid_h

#include "MeshFreeFiltersModule.h"
#include "vtkPolyDataAlgorithm.h"

#include <memory>
#include <string>

class MESHFREEFILTERS_EXPORT vtkMeshFreeSPHFluid : public vtkPolyDataAlgorithm
{
public:
  static vtkMeshFreeSPHFluid* New();
  vtkTypeMacro(vtkMeshFreeSPHFluid, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /** Initial block of fluid [x0,x1,y0,y1,z0,z1], filled on the lattice of ParticleSpacing. */
  vtkSetVector6Macro(FluidBounds, double);
  vtkGetVector6Macro(FluidBounds, double);
  ///@}

  ///@{
  /** The closed container [x0,x1,y0,y1,z0,z1]: walls on every side. */
  vtkSetVector6Macro(DomainBounds, double);
  vtkGetVector6Macro(DomainBounds, double);
  ///@}

  ///@{
  /** 3 (default) or 2: the x–z plane (y ignored, gravity on z). */
  vtkSetClampMacro(Dimension, int, 2, 3);
  vtkGetMacro(Dimension, int);
  ///@}

  ///@{
  /** Lattice spacing of the initial particles (m). Default 0.02. */
  vtkSetMacro(ParticleSpacing, double);
  vtkGetMacro(ParticleSpacing, double);
  ///@}

  ///@{
  /** Kernel support radius h (m); 0 (default): 2·ParticleSpacing. */
  vtkSetMacro(SmoothingLength, double);
  vtkGetMacro(SmoothingLength, double);
  ///@}

  ///@{
  /** ρ0 (kg/m³). Default 1000. */
  vtkSetMacro(RestDensity, double);
  vtkGetMacro(RestDensity, double);
  ///@}

  ///@{
  /** k (m²/s²): Ideal p = k(ρ − ρ0); Tait B = ρ0 k / 7 (k = c0²). 0 (default): 100 g H (≤ 1 % compression). */
  vtkSetMacro(GasStiffness, double);
  vtkGetMacro(GasStiffness, double);
  ///@}

  ///@{
  /** 0: 'Ideal' p = k(ρ − ρ0) (thesis 5.40, default); 1: 'Tait' (γ = 7). */
  vtkSetClampMacro(EquationOfState, int, 0, 1);
  vtkGetMacro(EquationOfState, int);
  ///@}

  ///@{
  /** Kernels of density and pressure force: 0 'Spiky' (default), 1 'Poly6', 2 'Mueller' (see SPHFluid.h). */
  vtkSetClampMacro(KernelPair, int, 0, 2);
  vtkGetMacro(KernelPair, int);
  ///@}

  ///@{
  /** Dynamic viscosity μ (Pa·s). Default 0.01. */
  vtkSetMacro(Viscosity, double);
  vtkGetMacro(Viscosity, double);
  ///@}

  ///@{
  /** Monaghan's artificial viscosity α (dimensionless, acts only between approaching particles; 0: off).
   * Default 0.02. */
  vtkSetMacro(ArtificialViscosity, double);
  vtkGetMacro(ArtificialViscosity, double);
  ///@}

  ///@{
  /** Surface tension σ (N/m). Default 0. */
  vtkSetMacro(SurfaceTension, double);
  vtkGetMacro(SurfaceTension, double);
  ///@}

  ///@{
  /** Gravity (m/s²). Default (0, 0, −9.81). */
  vtkSetVector3Macro(Gravity, double);
  vtkGetVector3Macro(Gravity, double);
  ///@}

  ///@{
  /** Largest time step (s). Default 0.002. */
  vtkSetMacro(TimeStep, double);
  vtkGetMacro(TimeStep, double);
  ///@}

  ///@{
  /** CFL factor λ of the adaptive step; 0: fixed TimeStep (reduced, with a warning, when unstable). Default 0.25. */
  vtkSetMacro(CFLNumber, double);
  vtkGetMacro(CFLNumber, double);
  ///@}

  ///@{
  /** Last reported time (s). Default 1. */
  vtkSetMacro(EndTime, double);
  vtkGetMacro(EndTime, double);
  ///@}

  ///@{
  /** Interval between reported times (s). Default 0.02. */
  vtkSetMacro(OutputInterval, double);
  vtkGetMacro(OutputInterval, double);
  ///@}

  ///@{
  /** Extra output arrays: `Acceleration` and `NeighborCount`. Default off. */
  vtkSetMacro(ComputeAcceleration, bool);
  vtkGetMacro(ComputeAcceleration, bool);
  vtkBooleanMacro(ComputeAcceleration, bool);
  vtkSetMacro(ComputeNeighborCount, bool);
  vtkGetMacro(ComputeNeighborCount, bool);
  vtkBooleanMacro(ComputeNeighborCount, bool);
  ///@}

  ///@{
  /**
   * The pressure solver: 0 'WCSPH' (default; weakly compressible, the equation of state above), 1 'DFSPH'
   * (divergence-free SPH, Bender & Koschier 2015/2017: incompressible, a density and a divergence solve per step,
   * the step from the velocity alone; see Filters/Core/SPH/SPHDivergenceFree.cxx). DFSPH runs on the CPU only: with
   * Backend CUDA it warns and the CPU runs. EquationOfState and GasStiffness do not apply to DFSPH (GasStiffness
   * still sets the sound speed of the artificial viscosity).
   */
  enum SolverType
  {
    SOLVER_WCSPH = 0,
    SOLVER_DFSPH = 1
  };
  vtkSetClampMacro(Solver, int, SOLVER_WCSPH, SOLVER_DFSPH);
  vtkGetMacro(Solver, int);
  ///@}

  ///@{
  /** DFSPH: the average compression allowed after the density solve, in percent of ρ0. Default 0.01. */
  vtkSetMacro(DensityTolerance, double);
  vtkGetMacro(DensityTolerance, double);
  ///@}

  ///@{
  /** DFSPH: the average (dρ/dt)·dt/ρ0 allowed after the divergence solve, in percent. Default 0.1. */
  vtkSetMacro(DivergenceTolerance, double);
  vtkGetMacro(DivergenceTolerance, double);
  ///@}

  ///@{
  /** DFSPH: the most iterations of each solve per step. Default 100. */
  vtkSetMacro(MaximumIterations, int);
  vtkGetMacro(MaximumIterations, int);
  ///@}

  ///@{
  /** Number of simulation states kept in the time cache (≥ 2). Default 16. */
  vtkSetClampMacro(CacheSize, int, 2, 100000);
  vtkGetMacro(CacheSize, int);
  ///@}

  ///@{
  /**
   * Which implementation runs the simulation: 0 Auto (default), 1 CPU, 2 CUDA. CUDA runs the integrator on
   * the CUDA device (the particles stay there for each output interval; see meshfree::SPHFluid::SetBackend)
   * whenever it can: a build with CUDA, a usable device, no obstacles; otherwise a warning with the reason and
   * the CPU result, never an error. Auto chooses the device for jobs of at least GetAutoDeviceParticles()
   * particles when it can run them, the CPU otherwise. The threshold was measured on an H200
   * (Testing/Benchmarks/results/gpu.md): the device won from 2,000 particles (6 times 2 or 16 CPU threads), 24
   * times 2 threads at 16,000 and 83 times at 65,536, upload and download included; 16,000 leaves room for a
   * GPU ten times slower. The field data array `Backend` (one string) says what ran, e.g. "CPU (oneTBB, 2 threads)" or
   * "CUDA (NVIDIA H200)". The results do not depend on it (bit for bit): changing it keeps the cached
   * states.
   */
  enum BackendType
  {
    BACKEND_AUTO = 0,
    BACKEND_CPU = 1,
    BACKEND_CUDA = 2
  };
  vtkSetClampMacro(Backend, int, BACKEND_AUTO, BACKEND_CUDA);
  vtkGetMacro(Backend, int);
  static vtkIdType GetAutoDeviceParticles() { return 16000; }
  ///@}

  /** Number of simulation steps taken by this object since its creation (for tests of the cache). */
  vtkGetMacro(StepsTaken, long);

  /** Whether OutputInterval and EndTime are usable (finite, > 0 and >= 0). */
  bool ValidTimes() const;

  /** The output times reported by RequestInformation (for tests). */
  int GetNumberOfOutputTimes();

  /**
   * Called by the hidden `Obstacles` property of ParaView's pure source `SPHFluid`, left for scripts written when
   * that proxy had an input: reports, as an error, that obstacles are the input of `SPHFluidWithObstacles`. The
   * argument is not connected (connect obstacles to input port 0). Nothing happens for nullptr.
   */
  void ReportObstaclesWithoutPort(vtkObject* obstacles);

protected:
  vtkMeshFreeSPHFluid();
  ~vtkMeshFreeSPHFluid() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double FluidBounds[6] = { 0.0, 0.2, 0.0, 0.2, 0.0, 0.4 };
  double DomainBounds[6] = { 0.0, 0.8, 0.0, 0.2, 0.0, 0.5 };
  int Dimension = 3;
  double ParticleSpacing = 0.02;
  double SmoothingLength = 0.0;
  double RestDensity = 1000.0;
  double GasStiffness = 0.0;
  int EquationOfState = 0;
  int KernelPair = 0;
  double Viscosity = 0.01;
  double SurfaceTension = 0.0;
  double ArtificialViscosity = 0.02;
  double Gravity[3] = { 0.0, 0.0, -9.81 };
  double TimeStep = 0.002;
  double CFLNumber = 0.25;
  double EndTime = 1.0;
  double OutputInterval = 0.02;
  bool ComputeAcceleration = false;
  bool ComputeNeighborCount = false;
  int CacheSize = 16;
  int Backend = BACKEND_AUTO;
  int Solver = SOLVER_WCSPH;
  double DensityTolerance = 0.01;
  double DivergenceTolerance = 0.1;
  int MaximumIterations = 100;
  long StepsTaken = 0;

private:
  /** Applies Backend for a job of `particles` (warning when CUDA cannot run); returns what runs, for the field data. */
  std::string SelectBackend(vtkIdType particles);
  /** Warns (once per reason) that Backend CUDA did not run on the device; an empty reason resets. */
  void WarnBackend(const std::string& reason);
  vtkMeshFreeSPHFluid(const vtkMeshFreeSPHFluid&) = delete;
  void operator=(const vtkMeshFreeSPHFluid&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
