"""Shared helpers of the pvpython tests: load the plugin named by $MESHFREE_PLUGIN, fetch outputs as numpy."""
import os
import sys

from paraview import servermanager as sm
from paraview import simple
from vtkmodules.numpy_interface import dataset_adapter as dsa


def plugin_path():
    path = os.environ.get("MESHFREE_PLUGIN")
    if not path or not os.path.exists(path):
        print("MESHFREE_PLUGIN is not set to the built plugin:", path)
        sys.exit(1)
    return path


def load(namespace):
    """Load the MeshFree plugin into the caller's namespace (proxies appear as functions)."""
    simple.LoadPlugin(plugin_path(), remote=False, ns=namespace)


def fetch(proxy, time=None):
    """Update the proxy (at a time if given) and return its output wrapped for numpy access."""
    if time is None:
        proxy.UpdatePipeline()
    else:
        proxy.UpdatePipeline(time)
    return dsa.WrapDataObject(sm.Fetch(proxy))


def output_dir():
    path = os.environ.get("MESHFREE_TEST_OUTPUT", ".")
    os.makedirs(path, exist_ok=True)
    return path
