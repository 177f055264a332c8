"""Travel bounds of a serial arm's collision geometry, from its model: how far any point of the
geometry outboard of a joint can move per unit of that joint's motion (:func:`joint_reach`, per
joint; :func:`link_reach`, per link and joint), which space the cell check's samples and size the
free-motion search's conservative advancement. Lengths in m, turns in rad, shifts in m."""

import numpy as np

from drake_traj.cell.shapes import shape_radius

__all__ = ["joint_reach", "link_reach"]


def joint_reach(plant, scene_graph, plant_context, instance, joint_names) -> np.ndarray:
    """R_j [m] per joint of a serial chain: a bound on the distance of any collision geometry
    outboard of joint j (on its child link or on bodies welded to it, such as the tool) from
    joint j's origin, which lies on its axis; 1 for a prismatic joint (a point moves at |q̇_j|).
    Poses are fixed in each link, so any ``plant_context`` gives them."""
    inspector = scene_graph.model_inspector()
    joints = [plant.GetJointByName(name, instance) for name in joint_names]
    reach = np.zeros(len(joints))
    outboard = 0.0  # R_{j+1}, added to the offset from joint j to joint j+1
    for j in reversed(range(len(joints))):
        joint = joints[j]
        origin = joint.frame_on_child().CalcPoseInWorld(plant_context)
        link = joint.child_body()
        bound = 0.0
        for body in plant.GetBodiesWeldedTo(link):
            X_OB = origin.InvertAndCompose(body.body_frame().CalcPoseInWorld(plant_context))
            for geometry in plant.GetCollisionGeometriesForBody(body):
                X_OG = X_OB @ inspector.GetPoseInFrame(geometry)
                bound = max(bound, float(np.linalg.norm(X_OG.translation())) + shape_radius(inspector.GetShape(geometry)))
        if j + 1 < len(joints):
            following = joints[j + 1]
            offset = origin.InvertAndCompose(following.frame_on_parent().CalcPoseInWorld(plant_context)).translation()
            stroke = (max(abs(following.position_lower_limits()[0]), abs(following.position_upper_limits()[0]))
                      if following.type_name() == "prismatic" else 0.0)
            bound = max(bound, float(np.linalg.norm(offset)) + stroke + outboard)
        reach[j] = 1.0 if joint.type_name() == "prismatic" else bound
        outboard = bound
    return reach


def link_reach(plant, scene_graph, instance, joint_names) -> tuple[np.ndarray, dict]:
    """Per-link travel bounds of a serial arm: (R [m/rad] (n + 1, n), the link of every
    collision geometry: {GeometryId: link}, 0 for the base and everything fixed in the world).

    R[i, j] bounds the distance of link i's collision geometry (the bodies welded to it, the tool
    on the last link, included) from joint j's origin on its axis, for every joint j that moves
    link i (j < i; joints from 0, link 0 the base): a turn Δq_j moves each of its points at most
    R[i, j] |Δq_j|; a prismatic joint j moves them by |Δq_j| (R[i, j] = 1 [m/m]), and its stroke
    (the larger |limit|) lengthens the distances of the joints before it. From the link's own
    geometry about its joint and the joint-to-joint offsets (the triangle inequality, as
    :func:`joint_reach`, which is the most of these over the links)."""
    inspector = scene_graph.model_inspector()
    context = plant.CreateDefaultContext()
    joints = [plant.GetJointByName(name, instance) for name in joint_names]
    n = len(joints)
    origins = [joint.frame_on_child().CalcPoseInWorld(context) for joint in joints]
    reach = np.zeros((n + 1, n))
    links = {}
    for j, joint in enumerate(joints):
        bound = 0.0
        for body in plant.GetBodiesWeldedTo(joint.child_body()):
            X_OB = origins[j].InvertAndCompose(body.body_frame().CalcPoseInWorld(context))
            for geometry in plant.GetCollisionGeometriesForBody(body):
                links[geometry] = j + 1
                X_OG = X_OB @ inspector.GetPoseInFrame(geometry)
                bound = max(bound, float(np.linalg.norm(X_OG.translation())) + shape_radius(inspector.GetShape(geometry)))
        reach[j + 1, j] = 1.0 if joints[j].type_name() == "prismatic" else bound
        distance = bound  # [m] of link j + 1's geometry from joint k's origin, k from j down
        for k in reversed(range(j)):  # the joints before it: its origin's offset to the next joint's, and on
            offset = origins[k].InvertAndCompose(joints[k + 1].frame_on_parent().CalcPoseInWorld(context)).translation()
            following = joints[k + 1]
            stroke = (max(abs(following.position_lower_limits()[0]), abs(following.position_upper_limits()[0]))
                      if following.type_name() == "prismatic" else 0.0)
            distance += float(np.linalg.norm(offset)) + stroke
            reach[j + 1, k] = 1.0 if joints[k].type_name() == "prismatic" else distance
    return reach, links
