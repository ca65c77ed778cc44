#!/bin/sh
# The README's client/server commands: `mpiexec -n RANKS pvserver --server-port=P &` then a `pvpython --no-mpi`
# client (pvserver_client.py) that connects, loads the plugin on the server and checks the simulations' pieces.
# pvserver_test.sh MPIEXEC PVSERVER PVPYTHON RANKS TIMEOUT CLIENT; exit 77 only when a program is missing.
mpiexec=$1 pvserver=$2 pvpython=$3 ranks=$4 timeout=$5 client=$6
for tool in "$mpiexec" "$pvserver" "$pvpython"; do
  if ! command -v "$tool" >/dev/null 2>&1; then
    echo "SKIP: $tool not found"
    exit 77
  fi
done
port=$((20000 + $$ % 20000))
limit=$((timeout > 40 ? timeout - 20 : timeout))
extra=
if "$mpiexec" --version 2>/dev/null | grep -Eqi "open ?mpi|openrte"; then
  extra="--oversubscribe --timeout $limit"
fi
echo "$mpiexec $extra -n $ranks $pvserver --server-port=$port &"
# shellcheck disable=SC2086
"$mpiexec" $extra -n "$ranks" "$pvserver" --server-port="$port" &
server=$!
"$pvpython" --no-mpi "$client" "$port" "$ranks"
status=$?
# pvserver exits when its client disconnects; stop it if the client failed before connecting.
sleep 2
if kill -0 "$server" 2>/dev/null; then
  kill "$server"
fi
wait "$server" 2>/dev/null
exit $status
