"""A picture of a refused motion: the arm, its tool and its cell at the colliding configuration,
the two bodies in red and their closest points marked (matplotlib, two views)."""

import numpy as np
from matplotlib.figure import Figure
from pydrake.geometry import Box, Capsule, Cylinder, Role, Sphere

from drake_traj.cell.clearance import CellChecker, CollisionError

__all__ = ["refusal_figure"]

_CIRCLE = np.linspace(0.0, 2.0 * np.pi, 33)


def _outline(shape) -> list[np.ndarray]:
    """Polylines (k, 3) [m] in the shape's frame that outline it: a box's edges, a cylinder's
    or capsule's end circles and four sides, a sphere's three great circles."""
    ring = np.column_stack([np.cos(_CIRCLE), np.sin(_CIRCLE), np.zeros_like(_CIRCLE)])
    if isinstance(shape, Box):
        half = 0.5 * np.array([shape.width(), shape.depth(), shape.height()])
        corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * half
        edges = [(a, b) for a in range(8) for b in range(a + 1, 8) if np.sum(np.abs(corners[a] - corners[b]) > 0) == 1]
        return [corners[[a, b]] for a, b in edges]
    if isinstance(shape, (Cylinder, Capsule)):
        radius, half = shape.radius(), 0.5 * shape.length()
        lines = [ring * radius + [0, 0, z] for z in (-half, half)]
        lines += [np.array([[radius * np.cos(a), radius * np.sin(a), -half], [radius * np.cos(a), radius * np.sin(a), half]])
                  for a in (0, 0.5 * np.pi, np.pi, 1.5 * np.pi)]
        if isinstance(shape, Capsule):
            lines += [ring * radius + [0, 0, z] for z in (-half - radius, half + radius)]
        return lines
    if isinstance(shape, Sphere):
        return [ring[:, order] * shape.radius() for order in ([0, 1, 2], [0, 2, 1], [2, 0, 1])]
    return []


def refusal_figure(checker: CellChecker, error: CollisionError) -> Figure:
    """The configuration of ``error`` in ``checker``'s cell: every collision geometry outlined
    (the two bodies of the error in red, the rest grey) and the two bodies' closest points
    joined in black, seen from the front (x-z) and from above (x-y), base frame [m]."""
    inspector = checker.scene_graph.model_inspector()
    query = checker.pose_query(error.configuration)
    lines, arm = [], []
    for geometry in inspector.GetAllGeometryIds(Role.kProximity):
        body, _ = checker.owner(geometry)
        pose = query.GetPoseInWorld(geometry)
        outlines = [pose.multiply(line.T).T for line in _outline(inspector.GetShape(geometry))]
        lines += [(points, body in error.bodies) for points in outlines]
        if checker.plant.HasBodyNamed(body, checker.instance):
            arm += outlines
    closest = [contact for contact in checker.contacts(error.configuration) if set(contact.bodies) == set(error.bodies)]
    # the view: the arm and the closest points, 0.25 m around (a table would fill it)
    extent = np.vstack(arm + [contact.points for contact in closest[:1]])
    low, high = extent.min(axis=0) - 0.25, extent.max(axis=0) + 0.25
    figure = Figure(figsize=(11, 5.2), layout="constrained")
    for axes, (u, v), title in zip(figure.subplots(1, 2), ((0, 2), (0, 1)), ("front (x-z)", "top (x-y)")):
        for points, hit in lines:
            axes.plot(points[:, u], points[:, v], color="tab:red" if hit else "0.65", linewidth=1.6 if hit else 0.7)
        for contact in closest[:1]:
            axes.plot(contact.points[:, u], contact.points[:, v], "k.-", markersize=8, linewidth=1.5,
                      label="closest points")
            axes.legend(loc="upper right")
        axes.set_xlim(low[u], high[u])
        axes.set_ylim(low[v], high[v])
        axes.set_aspect("equal")
        axes.set_xlabel(f"{'xyz'[u]} [m]")
        axes.set_ylabel(f"{'xyz'[v]} [m]")
        axes.set_title(title)
    a, b = error.bodies
    depth = f"{-error.distance * 1000:.1f} mm deep" if error.distance < 0 else f"{error.distance * 1000:.1f} mm apart"
    figure.suptitle(f"refused: {a} and {b} at t = {error.time:.3f} s, {depth} (clearance {error.clearance * 1000:g} mm)")
    return figure
