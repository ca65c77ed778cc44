"""The plugin auto-loads from PV_PLUGIN_PATH in a fresh pvpython (no LoadPlugin call)."""
import os
import shutil
import subprocess
import sys

plugin_dir = os.environ["MESHFREE_PLUGIN_DIR"]
env = dict(os.environ, PV_PLUGIN_PATH=plugin_dir)
code = (
    "from paraview.simple import *\n"
    "k = MeshFreeKernel(Kernel='Wendland', Dimension=2, Resolution=11)\n"
    "k.UpdatePipeline()\n"
    "print('OK', k.GetDataInformation().GetNumberOfPoints())\n"
)
pvpython = shutil.which("pvpython") or "/usr/bin/pvpython"
result = subprocess.run([pvpython, "--no-mpi", "-c", code], env=env, capture_output=True, text=True,
                        timeout=300)
print(result.stdout, result.stderr)
assert result.returncode == 0, result.returncode
assert "OK 121" in result.stdout
