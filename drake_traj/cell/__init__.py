"""The robot's cell and the checks that keep every motion clear of it: the cell as a scenario
describes it (:mod:`.cell`: mounting, obstacles, directives, tool) and its geometry in a plant,
its obstacle shapes and the geometry of Drake's shapes (:mod:`.shapes`), the user's own models
(:mod:`.directives`), the check of a planned motion (:mod:`.clearance`) and its travel bounds
(:mod:`.reach`), the guard that every
route into a station passes (:mod:`.guard`), the picture of a refused configuration
(:mod:`.refusal`) and the compiled collision model of the free-motion search (:mod:`.compiled_model`,
its kernels :mod:`.collision_kernels` and :mod:`.convex_distance`)."""

from drake_traj.cell.cell import (Cell, DEFAULT_CLEARANCE, NoMounting, Pedestal, Table, Tool, add_cell)
from drake_traj.cell.clearance import (CellChecker, CollisionError, Contact, JointRangeError, MotionCheck, geometry_owner, planner_target_word)
from drake_traj.cell.reach import joint_reach, link_reach
from drake_traj.cell.compiled_model import (CompiledCollisionModel, UnsupportedShapeError)
from drake_traj.cell.directives import (refuse_free_bodies)
from drake_traj.cell.guard import (ClearanceWatch, MotionGuard, UncheckedMotionError)
from drake_traj.cell.refusal import (refusal_figure)
from drake_traj.cell.shapes import (Box, Cylinder, Obstacle, ObstacleShape, Sphere, shape_outline, shape_radius)

__all__ = ['Box', 'Cell', 'CellChecker', 'ClearanceWatch', 'CollisionError', 'CompiledCollisionModel', 'Contact', 'Cylinder', 'DEFAULT_CLEARANCE', 'JointRangeError', 'MotionCheck', 'MotionGuard', 'NoMounting', 'Obstacle', 'ObstacleShape', 'Pedestal', 'Sphere', 'Table', 'Tool', 'UncheckedMotionError', 'UnsupportedShapeError', 'add_cell', 'geometry_owner', 'joint_reach', 'link_reach', 'planner_target_word', 'refusal_figure', 'refuse_free_bodies', 'shape_outline', 'shape_radius']
