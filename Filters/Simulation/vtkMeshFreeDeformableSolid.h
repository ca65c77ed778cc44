/**
 * @class   vtkMeshFreeDeformableSolid
 * @brief   time-dependent source: a meshless elastic (and optionally plastic) solid of "phyxels"
 *          (Mueller et al. 2004, "Point based animation of elastic, plastic and melting objects"; thesis ch. 4)
 *
 * Phyxels fill a built-in `Shape` inscribed in `ShapeBounds`, or the inside of the closed surface on the
 * optional input, on a cubic lattice of `PhyxelSpacing`. ParaView offers the two uses as two proxies, as it does
 * for its Stream Tracer: the pure source `MLSDeformableSolid` (no input property, so nothing is ever connected to
 * it behind the user's back) and `MLSDeformableSolidFromSurface`, whose required input is the surface. Their displacement gradient is an MLS fit over their
 * neighbours, strain is Green-Saint-Venant, stress Hooke's law with the physical `YoungModulus` and
 * `PoissonRatio`, and the forces conserve linear and angular momentum. Gravity, velocity damping, a box or
 * cylinder container, pinned phyxels (`FixedBounds`), Lennard-Jones self-contact, hourglass control and
 * plasticity are included. There is no container unless `Container` asks for one. Integrators: symplectic Euler (automatic stable step; a larger TimeStep is
 * sub-stepped with a warning) or linearised backward Euler solved by conjugate gradients. All numerics are in
 * the VTK-free core, meshfree::ElasticSolid (Filters/Core/ElasticSolid.h), which documents the model.
 *
 * Time: the source reports the time steps 0, OutputInterval, 2 OutputInterval, ..., EndTime and returns the
 * state at exactly the requested time (clamped to [0, EndTime]). The states at reported times are kept in a
 * bounded cache of checkpoints: revisiting a time costs nothing, and a later time is simulated from the nearest
 * earlier checkpoint. A time between two reported ones is simulated from the reported time before it and not
 * checkpointed, so a state never depends on what was requested before. Any property change (or a change of the
 * input) rebuilds the model and clears the cache.
 *
 * Output: vtkMultiBlockDataSet. Block 0 "Phyxels": vtkPolyData of vertices at the current positions with
 * Displacement, Velocity, Strain and Stress (6 components xx, yy, zz, xy, yz, xz; Green strain and the stress
 * of Hooke's law), VonMises, DetJ, Mass, Volume, Id. Block 1 "Surface" (built-in shapes and the input's
 * surface): the deformed triangle mesh with Displacement and Normals.
 *
 * Pieces (MPI: pvbatch, pvserver): every rank simulates the whole solid (the core gives the same bits whatever the
 * thread count) and block "Phyxels" holds the phyxels of the piece's contiguous share of [0, n) (UPDATE_PIECE_NUMBER
 * of UPDATE_NUMBER_OF_PIECES), so each phyxel is on exactly one rank; both blocks are present on every rank, empty
 * where there is nothing to show. The input surface, which arrives split across ranks, is gathered on every rank
 * (collective) and put in a canonical form (points that coincide up to rounding merged, points and triangles sorted,
 * exact duplicate triangles dropped), so the model does not depend on the number of ranks; each rank's "Surface" block is
 * its own input piece deformed. A built-in shape's surface is whole on piece 0.
 */
#ifndef vtkMeshFreeDeformableSolid_h
#define vtkMeshFreeDeformableSolid_h

#include "MeshFreeFiltersModule.h"
#include "vtkMultiBlockDataSetAlgorithm.h"

#include <memory>

class vtkPolyData;

class MESHFREEFILTERS_EXPORT vtkMeshFreeDeformableSolid : public vtkMultiBlockDataSetAlgorithm
{
public:
  static vtkMeshFreeDeformableSolid* New();
  vtkTypeMacro(vtkMeshFreeDeformableSolid, vtkMultiBlockDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum ShapeType
  {
    OCTAHEDRON = 0,
    ELLIPSOID = 1,
    BOX = 2,
    SPHERE = 3
  };
  enum IntegratorType
  {
    SYMPLECTIC_EULER = 0,
    IMPLICIT = 1
  };
  enum ContainerType
  {
    NO_CONTAINER = 0,
    BOX_CONTAINER = 1,
    CYLINDER_CONTAINER = 2
  };

  ///@{
  /** Geometry without an input: the shape, inscribed in ShapeBounds, and the lattice spacing of phyxels. */
  vtkSetClampMacro(Shape, int, OCTAHEDRON, SPHERE);
  vtkGetMacro(Shape, int);
  vtkSetVector6Macro(ShapeBounds, double);
  vtkGetVector6Macro(ShapeBounds, double);
  vtkSetMacro(PhyxelSpacing, double);
  vtkGetMacro(PhyxelSpacing, double);
  /** Segments around the built-in surfaces (38: the thesis' 990-vertex, 1976-triangle ellipsoid). */
  vtkSetClampMacro(SurfaceResolution, int, 4, 1024);
  vtkGetMacro(SurfaceResolution, int);
  ///@}

  ///@{
  /** Material: E (Pa), nu, rho (kg/m^3), k_v (Pa, an added bulk modulus penalising volume change). */
  vtkSetMacro(YoungModulus, double);
  vtkGetMacro(YoungModulus, double);
  vtkSetMacro(PoissonRatio, double);
  vtkGetMacro(PoissonRatio, double);
  vtkSetMacro(Density, double);
  vtkGetMacro(Density, double);
  vtkSetMacro(VolumeStiffness, double);
  vtkGetMacro(VolumeStiffness, double);
  ///@}

  ///@{
  /** MLS: neighbours per phyxel, support h = SupportScale * mean neighbour distance, weight function (a
   *  meshfree::KernelType value), basis of the gradient fit (1 linear as in the thesis, 2 quadratic),
   *  hourglass stiffness alpha (relative to E). */
  vtkSetClampMacro(NeighborCount, int, 4, 64);
  vtkGetMacro(NeighborCount, int);
  vtkSetMacro(SupportScale, double);
  vtkGetMacro(SupportScale, double);
  vtkSetClampMacro(WeightFunction, int, 0, 11);
  vtkGetMacro(WeightFunction, int);
  vtkSetClampMacro(GradientBasis, int, 1, 2);
  vtkGetMacro(GradientBasis, int);
  vtkSetMacro(HourglassStiffness, double);
  vtkGetMacro(HourglassStiffness, double);
  ///@}

  ///@{
  /** Plasticity (Mueller 2004 sec. 5): yield strain (0 = elastic), creep rate (1/s), maximum plastic strain. */
  vtkSetMacro(PlasticYield, double);
  vtkGetMacro(PlasticYield, double);
  vtkSetMacro(PlasticCreep, double);
  vtkGetMacro(PlasticCreep, double);
  vtkSetMacro(PlasticMaxStrain, double);
  vtkGetMacro(PlasticMaxStrain, double);
  ///@}

  ///@{
  /** Dynamics: integrator, time step (0 = automatic), damping rate (1/s), gravity, initial velocity. */
  vtkSetClampMacro(Integrator, int, SYMPLECTIC_EULER, IMPLICIT);
  vtkGetMacro(Integrator, int);
  vtkSetMacro(TimeStep, double);
  vtkGetMacro(TimeStep, double);
  vtkSetMacro(Damping, double);
  vtkGetMacro(Damping, double);
  vtkSetVector3Macro(Gravity, double);
  vtkGetVector3Macro(Gravity, double);
  vtkSetVector3Macro(InitialVelocity, double);
  vtkGetVector3Macro(InitialVelocity, double);
  ///@}

  ///@{
  /** Collisions: container (default NO_CONTAINER: no walls, whatever the body's bounds), its bounds (used only
   *  with a container), restitution and friction; Lennard-Jones self-contact; pinned box. */
  vtkSetClampMacro(Container, int, NO_CONTAINER, CYLINDER_CONTAINER);
  vtkGetMacro(Container, int);
  vtkSetVector6Macro(ContainerBounds, double);
  vtkGetVector6Macro(ContainerBounds, double);
  vtkSetClampMacro(Restitution, double, 0.0, 1.0);
  vtkGetMacro(Restitution, double);
  vtkSetClampMacro(Friction, double, 0.0, 10.0);
  vtkGetMacro(Friction, double);
  vtkSetMacro(SelfContact, vtkTypeBool);
  vtkGetMacro(SelfContact, vtkTypeBool);
  vtkBooleanMacro(SelfContact, vtkTypeBool);
  vtkSetVector6Macro(FixedBounds, double);
  vtkGetVector6Macro(FixedBounds, double);
  ///@}

  ///@{
  /** Reported time steps 0, OutputInterval, ..., EndTime. */
  vtkSetMacro(EndTime, double);
  vtkGetMacro(EndTime, double);
  vtkSetMacro(OutputInterval, double);
  vtkGetMacro(OutputInterval, double);
  /** Checkpoints kept in the state cache (at least 2). */
  vtkSetClampMacro(CacheSize, int, 2, 100000);
  vtkGetMacro(CacheSize, int);
  ///@}

  ///@{
  /** Diagnostics of the last update: output steps simulated (not restored from the cache), phyxel count,
   *  stable symplectic step of the current model, total CG iterations of the implicit integrator. */
  vtkGetMacro(SimulatedSteps, int);
  vtkGetMacro(NumberOfPhyxels, int);
  vtkGetMacro(StableTimeStep, double);
  vtkGetMacro(ConjugateGradientIterations, int);
  ///@}

  /**
   * Called by the hidden `Input` property of ParaView's pure source `MLSDeformableSolid`, left for scripts written
   * when that proxy had an input: reports, as an error, that a surface to fill is the input of
   * `MLSDeformableSolidFromSurface`. The argument is not connected (connect the surface to input port 0).
   * Nothing happens for nullptr.
   */
  void ReportInputWithoutPort(vtkObject* surface);

protected:
  vtkMeshFreeDeformableSolid();
  ~vtkMeshFreeDeformableSolid() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Shape = ELLIPSOID;
  double ShapeBounds[6] = { -0.2, 0.2, -0.15, 0.15, 0.35, 0.65 };
  double PhyxelSpacing = 0.04;
  int SurfaceResolution = 38;
  double YoungModulus = 1e5;
  double PoissonRatio = 0.3;
  double Density = 1000.0;
  double VolumeStiffness = 0.0;
  int NeighborCount = 10;
  double SupportScale = 3.0;
  int WeightFunction = 3; // Poly6 (= W1 of the thesis)
  int GradientBasis = 2;
  double HourglassStiffness = 0.05;
  double PlasticYield = 0.0;
  double PlasticCreep = 0.0;
  double PlasticMaxStrain = 0.0;
  int Integrator = SYMPLECTIC_EULER;
  double TimeStep = 0.0;
  double Damping = 0.0;
  double Gravity[3] = { 0.0, 0.0, -9.81 };
  double InitialVelocity[3] = { 0.0, 0.0, 0.0 };
  int Container = NO_CONTAINER;
  double ContainerBounds[6] = { -0.5, 0.5, -0.5, 0.5, 0.0, 1.0 };
  double Restitution = 0.3;
  double Friction = 0.3;
  vtkTypeBool SelfContact = 1;
  double FixedBounds[6] = { 0.0, -1.0, 0.0, -1.0, 0.0, -1.0 };
  double EndTime = 2.0;
  double OutputInterval = 0.02;
  int CacheSize = 16;

  int SimulatedSteps = 0;
  int NumberOfPhyxels = 0;
  double StableTimeStep = 0.0;
  int ConjugateGradientIterations = 0;

private:
  vtkMeshFreeDeformableSolid(const vtkMeshFreeDeformableSolid&) = delete;
  void operator=(const vtkMeshFreeDeformableSolid&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
  bool BuildModel(bool fromInput);
  void GatherInputSurface(vtkPolyData* input, bool distributed);
};

#endif
