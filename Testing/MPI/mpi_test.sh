#!/bin/sh
# Driver of the mpi tests (see MeshFreeMPITest.cmake): mpi_test.sh MPIEXEC PVBATCH RANKS TIMEOUT SCRIPT [ARGS...]
# Exit 77 (skip) only when mpiexec or pvbatch is not there; anything else is the job's own exit status.
mpiexec=$1 pvbatch=$2 ranks=$3 timeout=$4 script=$5
shift 5
for tool in "$mpiexec" "$pvbatch"; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool not found (install openmpi-bin and paraview)"
    exit 77
  fi
done
set --  -n "$ranks" "$pvbatch" --symmetric "$script" "$@"
if "$mpiexec" --version 2>/dev/null | grep -Eqi "open ?mpi|openrte"; then
  # More ranks than cores, and the job stopped by mpiexec itself before ctest's timeout (a killed mpiexec could
  # leave its ranks spinning).
  limit=$((timeout > 40 ? timeout - 20 : timeout))
  set -- --oversubscribe --timeout "$limit" "$@"
fi
echo "$mpiexec $*"
exec "$mpiexec" "$@"
