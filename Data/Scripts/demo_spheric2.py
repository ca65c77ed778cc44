"""MeshFree demo: a short, coarse SPHERIC Test 2 (the dam break onto a box; Kleefsman et al. 2005), as PNG frames.

Called by ./run.sh demo, or on its own:
  pvpython --no-mpi demo_spheric2.py --out DIR     (plugin from $MESHFREE_PLUGIN; renders, so run under Xvfb)
The scene of spheric_test2.py (a 3.22 x 1 x 1 m tank, the water column at its far end, a 0.161 x 0.403 x 0.161 m box
in the flow) at dx = 0.05 m (5,500 particles: the specification's 0.55 m column exactly), solved with DFSPH at its
fast setting (CFLNumber 1, TimeStep 10 ms: the setting that met the validation targets at dx = 0.02 m too), to 1 s.
spheric2_NNN.png show the water surface (Meshless Surface, Method 'SPH', on the source's cached states: the fluid
runs once, the surface follows the time) coloured by speed, with the box, at t = 0.25, 0.5, 0.75 and 1 s: the
front hits the box at about 0.4 s and runs up its face. About 10 s on two cores.
"""
import argparse
import os
import sys

from paraview import simple

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import spheric_test2  # noqa: E402  (the scene: tank, column, box)
from demo_common import bounds_box, new_view, save_frames, speed_colours  # noqa: E402


def spheric2(out, dx=0.05, end_time=1.0, interval=0.25, size=(960, 540)):
    """Render the coarse Test 2 into out/spheric2_NNN.png; returns the list of paths."""
    namespace = globals()
    spheric_test2.load_plugin(namespace)
    fluid = spheric_test2.make_scene(namespace, dx, end_time, interval, "DFSPH",
                                     properties={"CFLNumber": 1.0, "TimeStep": 0.01})
    fluid.CacheSize = 8  # every frame's state stays: the surface re-reads them
    fluid.UpdatePipelineInformation()  # the output times of the interval set above
    view = new_view(size)
    outline = simple.Show(bounds_box(spheric_test2.TANK), view)
    outline.SetRepresentationType("Outline")
    outline.AmbientColor = outline.DiffuseColor = [0.2, 0.2, 0.2]
    obstacle = simple.Show(bounds_box(spheric_test2.BOX), view)
    obstacle.AmbientColor = obstacle.DiffuseColor = [0.55, 0.45, 0.35]
    surface = namespace.get("MeshlessSurface", getattr(simple, "MeshlessSurface", None))(Input=fluid, Method="SPH")
    water = simple.Show(surface, view)
    water.Specular = 0.3
    bar = speed_colours(water, view, 4.0)
    bar.ScalarBarLength = 0.5
    bar.WindowLocation = "Upper Left Corner"
    view.CameraPosition = [0.9, -2.2, 1.9]
    view.CameraFocalPoint = [1.61, 0.5, 0.25]
    view.CameraViewUp = [0, 0, 1]
    simple.ResetCamera(view)  # the tank's outline fills the view ...
    simple.GetActiveCamera().Dolly(1.6)  # ... then closer
    paths = save_frames(view, [t for t in fluid.TimestepValues if t > 0.0], out, "spheric2_%03d.png", size)
    simple.Delete(view)
    return paths


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="demo", help="folder for the PNG frames")
    parser.add_argument("--dx", type=float, default=0.05, help="particle spacing (0.05 m: 5,500 particles)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    for path in spheric2(args.out, dx=args.dx):
        print("wrote", path)


if __name__ == "__main__":
    main()
