"""What the demo scripts share (demo_scan.py, demo_dambreak.py): the plugin and a white render view."""
import os
import sys

from paraview import simple


def load_plugin(namespace):
    """Loads MeshFree from $MESHFREE_PLUGIN into `namespace` (the caller's globals())."""
    path = os.environ.get("MESHFREE_PLUGIN")
    if not path or not os.path.exists(path):
        sys.exit("set MESHFREE_PLUGIN to build/lib/paraview-5.11/plugins/MeshFree/MeshFree.so")
    simple.LoadPlugin(path, remote=False, ns=namespace)


def new_view(size):
    """A render view of `size` pixels: white background, no orientation axes."""
    view = simple.CreateRenderView()
    view.ViewSize = list(size)
    view.OrientationAxesVisibility = 0
    view.Background = [1, 1, 1]
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    return view
