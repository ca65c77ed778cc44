"""MeshFree demo: a 3D dam break of 65,536 SPH particles (the thesis' headline scene size), as PNG frames.

Called by demo.py (dam_break(out)) or on its own:
  pvpython --no-mpi demo_dambreak.py --out DIR     (plugin from $MESHFREE_PLUGIN; renders, so run under Xvfb)
A 0.64 x 0.32 x 0.32 m block of water (spacing 1 cm) is released at the left of a 1.6 m long tank; frames every
0.05 s up to 0.35 s, coloured by speed: dambreak_NNN.png shows the particles, dambreak_surface_NNN.png the water
surface (Meshless Surface, Method 'SPH', on the same cached simulation: the fluid runs once, the surface
follows the time). About 1,300 adaptive steps: two to three minutes on two cores.
"""
import argparse
import os

from paraview import simple

from demo_common import bounds_box, load_plugin, new_view, save_frames, speed_colours


def dam_break(out, spacing=0.01, end_time=0.35, interval=0.05, size=(960, 540)):
    """Render the dam break into out/dambreak_NNN.png; returns the list of paths."""
    if "SPHFluid" not in globals():
        load_plugin(globals())  # puts the plugin's proxies (SPHFluid) into this module's namespace
    domain = [0.0, 1.6, 0.0, 0.32, 0.0, 0.5]
    fluid = SPHFluid(Dimension=3, ParticleSpacing=spacing, FluidBounds=[0.0, 0.64, 0.0, 0.32, 0.0, 0.32],  # noqa: F821
                     DomainBounds=domain, Viscosity=0.001, CFLNumber=0.25, TimeStep=0.002,
                     EndTime=end_time, OutputInterval=interval)
    tank = bounds_box(domain)
    view = new_view(size)
    outline = simple.Show(tank, view)
    outline.SetRepresentationType("Outline")
    outline.AmbientColor = outline.DiffuseColor = [0.2, 0.2, 0.2]
    display = simple.Show(fluid, view)
    display.SetRepresentationType("Points")
    display.PointSize = 3
    bar = speed_colours(display, view, 3.0)
    bar.DrawTickLabels = 1
    bar.AddRangeLabels = 1
    bar.RangeLabelFormat = "%-#.1f"
    bar.LabelFormat = "%-#.1f"
    bar.UseCustomLabels = 1
    bar.CustomLabels = [0.5, 1.0, 1.5, 2.0, 2.5]
    bar.ScalarBarLength = 0.5
    view.CameraPosition = [0.8, -1.5, 0.8]
    view.CameraFocalPoint = [0.8, 0.16, 0.12]
    view.CameraViewUp = [0, 0, 1]
    paths = save_frames(view, fluid.TimestepValues, out, "dambreak_%03d.png", size)
    # The same frames as a water surface: the fluid's cache serves every time again, only the surface is computed.
    simple.Hide(fluid, view)
    surface = MeshlessSurface(Input=fluid, Method="SPH")  # noqa: F821
    water = simple.Show(surface, view)
    simple.ColorBy(water, ("POINTS", "Velocity", "Magnitude"))
    water.Specular = 0.3
    paths += save_frames(view, fluid.TimestepValues, out, "dambreak_surface_%03d.png", size)
    simple.Delete(view)
    return paths


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default="demo", help="folder for the PNG frames")
    parser.add_argument("--spacing", type=float, default=0.01, help="particle spacing (0.01: 65,536 particles)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    for path in dam_break(args.out, spacing=args.spacing):
        print("wrote", path)


if __name__ == "__main__":
    main()
