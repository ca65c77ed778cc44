"""Meshless Surface on the SPH Fluid: the water's surface follows the time like any filter, encloses the
particles' volume at every time, carries their velocity, and revisiting a time recomputes only the surface
(the fluid's cache serves the particles: no simulation step)."""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import meshfree_test  # noqa: E402

meshfree_test.load(globals())

spacing = 0.01
fluid = SPHFluid(Dimension=3, ParticleSpacing=spacing, FluidBounds=[0, 0.1, 0, 0.1, 0, 0.2],
                 DomainBounds=[0, 0.4, 0, 0.1, 0, 0.3], Viscosity=0.01, TimeStep=0.002, CFLNumber=0.25,
                 EndTime=0.1, OutputInterval=0.05)
surface = MeshlessSurface(Input=fluid, Method="SPH")


def steps_taken():
    fluid.UpdatePropertyInformation()
    return fluid.GetProperty("StepsTaken").GetElement(0)


def closed_volume(mesh):
    """Enclosed volume of a closed triangle mesh (divergence theorem); asserts every edge has two triangles."""
    x = np.asarray(mesh.Points)
    conn = np.asarray(mesh.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    edges = np.sort(np.vstack([conn[:, [0, 1]], conn[:, [1, 2]], conn[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2), "open surface: %d boundary edges" % np.sum(counts == 1)
    a, b, c = x[conn[:, 0]], x[conn[:, 1]], x[conn[:, 2]]
    return np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0


shapes = {}
for t in (0.0, 0.1):
    particles = meshfree_test.fetch(fluid, t)
    mesh = meshfree_test.fetch(surface, t)
    n = particles.GetNumberOfPoints()
    volume = closed_volume(mesh)
    print("t = %.2f: %d particles, %d triangles, enclosed volume %.4g (particles' %.4g)"
          % (t, n, mesh.GetNumberOfCells(), volume, n * spacing ** 3))
    # The particles' volume is N s^3 (each particle's mass is rho0 s^3); the default level encloses it.
    assert abs(volume / (n * spacing ** 3) - 1.0) < 0.05, volume
    velocity = np.asarray(mesh.PointData["Velocity"])
    normals = np.asarray(mesh.PointData["Normals"])
    assert velocity.shape == (mesh.GetNumberOfPoints(), 3) and np.all(np.isfinite(velocity))
    assert np.allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-9)
    shapes[t] = np.asarray(mesh.Points).copy()
    if t == 0.0:
        assert np.abs(velocity).max() < 1e-12  # released from rest
    else:
        # The column has started to fall and spread: faster at its front, which has left x = 0.1.
        assert shapes[t][:, 0].max() > shapes[0.0][:, 0].max() + 0.01
        assert np.linalg.norm(velocity, axis=1).max() > 0.1

# Back to t = 0: the fluid's cache serves the particles (no step), the surface is the same as before.
before = steps_taken()
mesh = meshfree_test.fetch(surface, 0.0)
assert steps_taken() == before, (steps_taken(), before)
assert np.array_equal(np.asarray(mesh.Points), shapes[0.0])
print("fluid surface OK")
