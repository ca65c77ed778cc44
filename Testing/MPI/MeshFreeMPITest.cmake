# meshfree_add_mpi_test(NAME name [SCRIPT script] RANKS n [TIMEOUT s] [ARGS a...] [ENVIRONMENT VAR=value...]
#                       [SERIAL_REFERENCE])
# Test mpi.<name> (label mpi): `mpiexec --oversubscribe -n <n> pvbatch --symmetric <script> [ARGS]`, the script
# (default <name>.py, relative to the calling directory) running on every rank. OpenMPI is allowed to run as root,
# each rank uses MESHFREE_NUM_THREADS=1 (override with ENVIRONMENT), and mpiexec itself stops the job 20 s before the
# ctest TIMEOUT (default 300), so a hang never stalls the suite or leaves ranks behind. The test is skipped (exit 77)
# only when mpiexec or pvbatch cannot be found. A traceback or a VTK error fails it.
# SERIAL_REFERENCE also adds mpi.<name>.serial, `pvpython --no-mpi <script> --write-reference F` (default threads),
# as a fixture of the MPI test, which gets `--reference F` to compare with that independent serial run.
# The script's environment: MESHFREE_PLUGIN, MESHFREE_SOURCE_DIR, MESHFREE_TEST_OUTPUT as for the pvpython tests.
find_program(MESHFREE_MPIEXEC NAMES mpiexec mpirun)
find_program(MESHFREE_PVBATCH NAMES pvbatch)
set(MESHFREE_MPI_DRIVER "${CMAKE_CURRENT_LIST_DIR}/mpi_test.sh")

function(meshfree_add_mpi_test)
  cmake_parse_arguments(arg "SERIAL_REFERENCE" "NAME;SCRIPT;RANKS;TIMEOUT" "ARGS;ENVIRONMENT" ${ARGN})
  if (NOT arg_NAME OR NOT arg_RANKS)
    message(FATAL_ERROR "meshfree_add_mpi_test: NAME and RANKS are required")
  endif ()
  if (NOT arg_SCRIPT)
    set(arg_SCRIPT "${arg_NAME}.py")
  endif ()
  if (NOT arg_TIMEOUT)
    set(arg_TIMEOUT 300)
  endif ()
  get_filename_component(script "${arg_SCRIPT}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  set(mpiexec "${MESHFREE_MPIEXEC}")
  set(pvbatch "${MESHFREE_PVBATCH}")
  if (NOT mpiexec)
    set(mpiexec mpiexec) # not found now: the driver looks again and skips if it is still missing
  endif ()
  if (NOT pvbatch)
    set(pvbatch pvbatch)
  endif ()
  set(env "MESHFREE_PLUGIN=$<TARGET_FILE:MeshFree>" "MESHFREE_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
    "MESHFREE_TEST_OUTPUT=${MESHFREE_TEST_OUTPUT_DIR}" "OMPI_ALLOW_RUN_AS_ROOT=1" "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1"
    ${MESHFREE_PARAVIEW_TEST_ENV})
  set(fail "Traceback;(\n|^)ERROR: ;ERR\\|")
  set(extra ${arg_ARGS})
  set(test mpi.${arg_NAME})
  if (arg_SERIAL_REFERENCE)
    set(reference "${MESHFREE_TEST_OUTPUT_DIR}/mpi_${arg_NAME}_serial.npz")
    add_test(NAME ${test}.serial
      COMMAND "${PVPYTHON_EXECUTABLE}" --no-mpi "${script}" --write-reference "${reference}" ${arg_ARGS})
    set_tests_properties(${test}.serial PROPERTIES LABELS mpi TIMEOUT ${arg_TIMEOUT} ENVIRONMENT "${env}"
      FIXTURES_SETUP ${test}.reference FAIL_REGULAR_EXPRESSION "${fail}")
    list(APPEND extra --reference "${reference}")
  endif ()
  list(APPEND env MESHFREE_NUM_THREADS=1 ${arg_ENVIRONMENT})
  add_test(NAME ${test}
    COMMAND sh "${MESHFREE_MPI_DRIVER}" "${mpiexec}" "${pvbatch}" ${arg_RANKS} ${arg_TIMEOUT} "${script}" ${extra})
  set_tests_properties(${test} PROPERTIES LABELS mpi TIMEOUT ${arg_TIMEOUT} PROCESSORS ${arg_RANKS}
    ENVIRONMENT "${env}"
    FAIL_REGULAR_EXPRESSION "${fail}" SKIP_RETURN_CODE 77)
  if (arg_SERIAL_REFERENCE)
    set_tests_properties(${test} PROPERTIES FIXTURES_REQUIRED ${test}.reference)
  endif ()
endfunction ()
