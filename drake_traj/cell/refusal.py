"""A picture of a refused motion: the arm, its tool and its cell at the colliding configuration,
the two bodies in red and their closest points marked (matplotlib, two views)."""

import numpy as np
from matplotlib.figure import Figure
from pydrake.geometry import Role

from drake_traj.cell.cell import TOOL_BODY
from drake_traj.cell.clearance import CellChecker, CollisionError
from drake_traj.cell.shapes import shape_outline

__all__ = ["refusal_figure"]


def _outline(checker: CellChecker, geometry) -> list[np.ndarray]:
    """Polylines (k, 3) [m] in the frame of the collision geometry ``geometry`` of ``checker``'s
    plant that outline it: a cell obstacle's (on the world) or a tool shape's (on the tool body)
    own :meth:`~drake_traj.cell.shapes.Obstacle.outline`, any other's that of its Drake shape
    (:func:`~drake_traj.cell.shapes.shape_outline`)."""
    inspector, plant = checker.scene_graph.model_inspector(), checker.plant
    body, name = plant.GetBodyFromFrameId(inspector.GetFrameId(geometry)), inspector.GetName(geometry)
    if body.index() == plant.world_body().index():
        field = checker.cell_fields.get(name, ())  # the world's geometry names are not scoped
        if field[:2] == ("cell", "obstacles"):
            return checker.cell.obstacles[field[2]].outline()
    elif body.name() == TOOL_BODY and body.model_instance() == checker.instance:
        field = checker.cell_fields.get(name.removeprefix(f"{plant.GetModelInstanceName(checker.instance)}::"), ())
        if field[:3] == ("cell", "tool", "shapes"):
            return checker.cell.tool.shapes[field[3]].outline()
    return shape_outline(inspector.GetShape(geometry))


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
        outlines = [pose.multiply(line.T).T for line in _outline(checker, geometry)]
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
