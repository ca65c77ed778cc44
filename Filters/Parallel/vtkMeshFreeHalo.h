// SPDX-License-Identifier: BSD-3-Clause
/**
 * @class   vtkMeshFreeHalo
 * @brief   halo exchange for a point cloud distributed over the ranks of a vtkMultiProcessController
 *
 * A meshless method evaluated on a rank needs, besides the rank's own points, every remote point within the
 * method's reach of what the rank evaluates. Given a rank's local points, the region it evaluates (the bounding
 * box of its query points, probe points or grid sub-extent) and a radius, Exchange() returns the local cloud
 * extended with every remote point whose distance to that box is at most the radius: the halo. VTK's ghost
 * generators link pieces through shared cells and give no ghost points for vertex clouds, hence this class.
 *
 * How: the ranks AllGather their boxes and radii, then every pair of ranks swaps the points inside each other's
 * grown box (a vtkPolyData with the selected point arrays), pair by pair in the rounds of a round-robin
 * tournament, so that blocking Send/Receive never deadlock. No rank ever receives the whole cloud unless its
 * region and radius cover it. Coordinates keep their double precision.
 *
 * Output (GetOutput()): a vtkPolyData without cells. Its first GetNumberOfOwnedPoints() points are the rank's own
 * points in input order, the remote (ghost) points follow sorted by global id. Point arrays: the input's point
 * arrays (all, or none with ShipPointDataOff()), `vtkGhostType` (0 for owned points, DUPLICATEPOINT for halo
 * points) and the global point ids, set as the GlobalIds attribute. Global ids are the input's GlobalIds
 * attribute when it has one (an integer array), otherwise the point's index in the cloud concatenated rank by
 * rank (rank 0's points first): the serial index when the cloud is split by index, as a reader's pieces are.
 * Ordering neighbours by global id therefore breaks distance ties exactly as the serial run does.
 *
 * ExchangeForKNearest() sizes the halo for k-nearest-neighbour queries in at most two rounds: the first radius is
 * twice that of a ball holding k points at the cloud's mean density (over every rank); then each rank checks its
 * queries on local + halo points - a query with k points within the radius (divided by the radius factor) has
 * everything it needs, since the true k-th distance is no larger; for the others the k-th distance among local +
 * halo points bounds the true one - and a second round, agreed by all ranks, widens the halo where it fell
 * short. (A cloud without extent uses the queries' k-th distances to the rank's own points, an upper bound.)
 *
 * Every method that communicates is collective: every rank of the controller must call it, in the same order,
 * including ranks with no points. Without a controller, or with one process, no communication happens and the
 * output is the local cloud.
 *
 * Input points whose `vtkGhostType` has the DUPLICATEPOINT bit are not handled specially (not supported yet):
 * a cloud whose pieces overlap gives each shared point twice.
 *
 * @sa vtkMultiProcessController vtkMeshFreePointNeighbors
 */
#ifndef vtkMeshFreeHalo_h
#define vtkMeshFreeHalo_h

#include "MeshFreeFiltersModule.h"
#include "vtkObject.h"
#include "vtkSmartPointer.h" // for the output

#include <vector> // the exchange plan

class vtkDataArray;
class vtkIdTypeArray;
class vtkMultiProcessController;
class vtkPointSet;
class vtkPolyData;

class MESHFREEFILTERS_EXPORT vtkMeshFreeHalo : public vtkObject
{
public:
  static vtkMeshFreeHalo* New();
  vtkTypeMacro(vtkMeshFreeHalo, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The controller the ranks communicate through. Default: vtkMultiProcessController::GetGlobalController()
   * (none in a plain VTK program: then nothing is exchanged).
   */
  void SetController(vtkMultiProcessController* controller);
  vtkGetObjectMacro(Controller, vtkMultiProcessController);
  ///@}

  ///@{
  /**
   * Whether the input's point arrays travel with the halo points (default on). Off: only coordinates,
   * global ids and vtkGhostType.
   */
  vtkSetMacro(ShipPointData, bool);
  vtkGetMacro(ShipPointData, bool);
  vtkBooleanMacro(ShipPointData, bool);
  ///@}

  /**
   * Collective. Extends `local` with every remote point whose distance to this rank's `region` (xmin, xmax,
   * ymin, ymax, zmin, zmax; an empty box, min > max, asks for nothing) is at most `radius` (+inf: every remote
   * point). Points with NaN or infinite coordinates are never sent. Returns 0 on bad input (after taking part
   * in every communication, so that the other ranks do not hang).
   */
  int Exchange(vtkPointSet* local, const double region[6], double radius);

  /**
   * Collective. Extends `local` so that each of this rank's `numberOfQueries` query positions (interleaved
   * x, y, z) finds, among the output points, the same k nearest points as in the whole distributed cloud
   * (all of them when the cloud has fewer), every point within `minimumRadius`, and every point within
   * `radiusFactor` (>= 1) times the distance to its k-th nearest. The region is the bounding
   * box of the finite queries. One round when every rank holds at least k valid points, at most two otherwise.
   */
  int ExchangeForKNearest(vtkPointSet* local, const double* queries, vtkIdType numberOfQueries, int k,
    double minimumRadius = 0.0, double radiusFactor = 1.0);

  /**
   * Collective. After an Exchange(): `values` has one tuple per output point (owned points first, then the halo);
   * every halo point's tuple is replaced by its owner's tuple of the owner's own `values` (what the owner
   * computed for it), through the same pairs of ranks as the exchange. A point array that the ranks update for
   * their own points this way reads the same everywhere. Double arrays only. Returns 0 on bad input (after
   * taking part in every communication).
   */
  int UpdateHalo(vtkDataArray* values);

  ///@{
  /**
   * Results of the last exchange: the local + halo cloud, how many of its points are this rank's own (the
   * first ones), their global ids (also in the output's point data), this rank's halo radius (after the
   * second round if there was one), the number of rounds, and the number of points in the whole cloud.
   */
  vtkPolyData* GetOutput();
  vtkIdType GetNumberOfOwnedPoints() const { return this->NumberOfOwnedPoints; }
  vtkIdTypeArray* GetGlobalIds();
  /// A new cloud of this rank's own points (the output's first ones) with the output's point arrays but its ghost
  /// marks, the global ids as its GlobalIds: what a retry with a wider radius exchanges again.
  vtkSmartPointer<vtkPolyData> CopyOwnedPoints();
  double GetRadius() const { return this->Radius; }
  int GetNumberOfRounds() const { return this->NumberOfRounds; }
  vtkIdType GetNumberOfGlobalPoints() const { return this->NumberOfGlobalPoints; }
  ///@}

  ///@{
  /**
   * Collective helpers over all ranks of `controller` (nullptr or one process: the local values).
   * GlobalBounds: the union of the ranks' bounds (an empty box, min > max, where no rank has any).
   * GlobalSum / GlobalMax: the sum or maximum of one value per rank.
   */
  static void GlobalBounds(vtkMultiProcessController* controller, const double local[6], double global[6]);
  static vtkIdType GlobalSum(vtkMultiProcessController* controller, vtkIdType value);
  static double GlobalMax(vtkMultiProcessController* controller, double value);
  ///@}

  /// Whether the controller has more than one process (otherwise every method here is local).
  static bool IsDistributed(vtkMultiProcessController* controller);

  /// Bounds of the finite positions among n interleaved x, y, z (an empty box, min > max, when none is).
  static void FiniteBounds(const double* xyz, vtkIdType n, double bounds[6]);

  /// The median distance from up to 256 of the n points to their k-th nearest among them (a rank's own points: an
  /// upper bound of the whole cloud's); 0 when there are too few. A halo's first radius is a multiple of it.
  static double LocalNeighborDistance(const double* xyz, vtkIdType n, int k);

protected:
  vtkMeshFreeHalo();
  ~vtkMeshFreeHalo() override;

private:
  vtkMeshFreeHalo(const vtkMeshFreeHalo&) = delete;
  void operator=(const vtkMeshFreeHalo&) = delete;

  vtkSmartPointer<vtkPolyData> OwnedCloud(vtkPointSet* local);

  vtkMultiProcessController* Controller = nullptr;
  bool ShipPointData = true;
  vtkSmartPointer<vtkPolyData> Output;
  vtkIdType NumberOfOwnedPoints = 0;
  vtkIdType NumberOfGlobalPoints = 0;
  double Radius = 0.0;
  int NumberOfRounds = 0;
  // The last exchange's plan, per partner rank: the owned points sent, and the output positions of the points
  // received (in the message's order).
  std::vector<std::vector<vtkIdType>> Sent;
  std::vector<std::vector<vtkIdType>> Received;
};

#endif
