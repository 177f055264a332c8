"""The cell: scenario data, geometry in the plant, the payload, and its bad input (each refused
naming its field, with nothing run)."""

import textwrap
from dataclasses import dataclass, field

import numpy as np
import pytest
from pydrake.common import MemoryFile
from pydrake.geometry import Box as DrakeBox
from pydrake.geometry import Convex, InMemoryMesh
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from drake_traj import load_scenario
from drake_traj.cell import (Box, Cell, CellChecker, CollisionError, Cylinder, NoMounting, Obstacle, Pedestal, Sphere,
                             Tool, add_cell, refusal_figure, shape_outline)
from drake_traj.errors import Cause, DrakeTrajError
from drake_traj.robots import UR10E
from drake_traj.robots.ur10e import dh_frames
from drake_traj.scenario import ScenarioError

G = 9.81


def plant_with(cell: Cell, directory=None):
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    instance = UR10E.add_to_plant(plant)
    fields = add_cell(plant, cell, instance, directory=directory)
    plant.Finalize()
    return plant, instance, fields


def test_the_default_cell_is_a_table_flush_with_the_base():
    plant, _, fields = plant_with(Cell())
    assert fields == {"table": ("cell", "mounting")}
    assert plant.num_bodies() == 1 + 8  # world + the UR10e's links (base, six links, tool0): no tool body


def test_the_payload_changes_the_static_shoulder_torque_by_m_g_r():
    mass, com = 5.0, np.array([0.02, -0.03, 0.08])
    q = np.array([0.3, -1.1, 1.4, -0.9, 1.2, 0.5])
    torques = []
    for cell in (Cell(), Cell(tool=Tool(mass=mass, center_of_mass=com.tolist(), tcp_xyz=[0, 0, 0.1]))):
        plant, instance, _ = plant_with(cell)
        context = plant.CreateDefaultContext()
        plant.SetPositions(context, instance, q)
        torques.append(-plant.CalcGravityGeneralizedForces(context))  # the torque that holds the arm
    # independent: the payload's weight at its centre (flange frame -> base frame by the DH chain)
    frames = dh_frames(q)
    centre = frames[6][:3, :3] @ com + frames[6][:3, 3]
    axis, origin = frames[1][:3, 2], frames[1][:3, 3]  # joint 2 turns about z of DH frame 1
    expected = axis @ np.cross(centre - origin, [0.0, 0.0, -mass * G])
    change = torques[1][1] - torques[0][1]
    assert change == pytest.approx(-expected, rel=0.01)
    assert abs(change) > 10.0  # a real lever: m g r with r ~ 0.5 m


@pytest.mark.parametrize("cell, field, words", [
    (Cell(obstacles=[Box(size=[0.3, 0.2, -0.25])]), ("cell", "obstacles", 0, "size", 2), "must be positive"),
    (Cell(obstacles=[Box(size=[0.3, 0.0, 0.2])]), ("cell", "obstacles", 0, "size", 1), "must be positive"),
    (Cell(obstacles=[Sphere(radius=0.1, xyz=[0.5, float("nan"), 0.2])]), ("cell", "obstacles", 0, "xyz"), "finite"),
    (Cell(obstacles=[Cylinder(radius=0.1, length=0.2, rpy=[0, float("inf"), 0])]), ("cell", "obstacles", 0, "rpy"),
     "finite"),
    (Cell(mounting=Pedestal(radius=0.0)), ("cell", "mounting", "radius"), "must be positive"),
    (Cell(tool=Tool(mass=UR10E.rated_payload + 0.5, tcp_xyz=[0, 0, 0.2])), ("cell", "tool", "mass"), "rated payload"),
    (Cell(tool=Tool(mass=-1.0)), ("cell", "tool", "mass"), ">= 0"),
    (Cell(tool=Tool(mass=2.0, tcp_xyz=[0, 0, 0.1], center_of_mass=[0, 0, 0.4])), ("cell", "tool", "center_of_mass"),
     "beyond the tool"),
    (Cell(tool=Tool(tcp_xyz=[0, 0, float("nan")])), ("cell", "tool", "tcp_xyz"), "finite"),
    (Cell(tool=Tool(mass=1.0, tcp_xyz=[0, 0, 0.1], inertia=[1, 1, 5, 0, 0, 0])), ("cell", "tool", "inertia"),
     "not a physical inertia"),
    (Cell(clearance=-0.001), ("cell", "clearance"), ">= 0"),
])
def test_a_malformed_cell_is_refused_naming_its_field(cell, field, words):
    with pytest.raises(DrakeTrajError, match=words) as caught:
        cell.validate()
    assert caught.value.field == field
    assert caught.value.cause in (Cause.INVALID, Cause.INFEASIBLE)


def scenario_file(tmp_path, cell_yaml: str):
    path = tmp_path / "cell.yaml"
    path.write_text("name: cell_test\nplanner: !QuinticConfig\n  goals: [[-1.2, -1.6, -2.0, -0.9, 1.57, 0.8]]\n"
                    + textwrap.indent(textwrap.dedent(cell_yaml), ""))
    return path


def test_a_scenario_file_locates_a_bad_size_at_its_line(tmp_path):
    path = scenario_file(tmp_path, """\
        cell:
          obstacles:
          - !Box {name: fixture, size: [0.3, 0.2, -0.25], xyz: [0.6, -0.4, 0.125]}
        """)
    with pytest.raises(ScenarioError, match=r"line 6.*cell\.obstacles\[0\]\.size\[2\] must be positive"):
        load_scenario(path)


def test_directives_add_the_users_model_from_a_path_relative_to_the_scenario(tmp_path):
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "post.sdf").write_text(textwrap.dedent("""\
        <?xml version="1.0"?>
        <sdf version="1.7"><model name="post"><link name="body">
          <collision name="c"><geometry><cylinder><radius>0.05</radius><length>0.5</length></cylinder></geometry></collision>
        </link></model></sdf>
        """))
    path = scenario_file(tmp_path, """\
        cell:
          directives:
          - add_model: {name: post, file: models/post.sdf}
          - add_weld: {parent: world, child: post::body, X_PC: {translation: [0.7, 0.0, 0.25]}}
        """)
    scenario = load_scenario(path)
    checker = scenario.cell_checker()
    post = checker.plant.GetBodyByName("body", checker.plant.GetModelInstanceByName("post"))
    assert not post.is_floating_base_body()
    # the post (r 0.05 m, 0.5 m tall) stands 0.7 m along +x: the arm stretched along +x, its
    # upper arm about 0.4 m up, passes through it; turned away, it is clear
    into = [contact for contact in checker.contacts([np.pi, -0.3, 0.0, -1.2, -1.57, 0.0]) if "post::body" in contact.bodies]
    assert into and into[0].distance < 0
    assert not [c for c in checker.contacts([0.0, -0.3, 0.0, -1.2, -1.57, 0.0], 0.2) if "post::body" in c.bodies]


@pytest.mark.parametrize("directive, words, field", [
    ("- add_model: {name: post, file: models/missing.sdf}", "no model file 'models/missing.sdf'",
     ("cell", "directives", 0, "add_model", "file")),
    ("- add_model: {name: post, file: broken.sdf}", "broken.sdf cannot be used", ("cell", "directives", 0, "add_model", "file")),
    ("- add_weld: {parent: world, child: nothing::base}", "unknown frame 'nothing::base'",
     ("cell", "directives", 0, "add_weld")),
])
def test_a_bad_directive_is_refused_naming_its_entry(tmp_path, directive, words, field):
    (tmp_path / "broken.sdf").write_text("<sdf version='1.7'><model name='x'><link name='a'>")
    path = scenario_file(tmp_path, "cell:\n  directives:\n  " + directive + "\n")
    scenario = load_scenario(path)
    with pytest.raises(ScenarioError, match=words) as caught:
        scenario.cell_checker()
    assert caught.value.field == field
    assert f"{path}, line 6" in str(caught.value)  # the entry's line


@pytest.mark.parametrize("tolerance, clearance, refused", [
    (0.005, 0.01, False),  # the defaults: equal to half the clearance
    (0.003, 0.01, False),
    (0.0051, 0.01, True),
    (0.005, 0.008, True),
])
def test_a_tracking_tolerance_above_half_the_clearance_is_refused_at_its_line(tmp_path, tolerance, clearance, refused):
    path = scenario_file(tmp_path, f"cell:\n  clearance: {clearance}\ntracking_tolerance: {tolerance}\n")
    if not refused:
        assert load_scenario(path).tracking_tolerance == tolerance
        return
    with pytest.raises(ScenarioError) as caught:
        load_scenario(path)
    assert caught.value.field == ("tracking_tolerance",)
    message = str(caught.value)
    assert message.startswith(f"{path}, line 6")  # tracking_tolerance's line
    assert f"tracking_tolerance = {tolerance * 1e3:g} mm" in message and f"({clearance * 500:g} mm of cell.clearance" in message
    assert "lower tracking_tolerance" in message and "raise cell.clearance" in message


def test_the_tracking_tolerance_check_for_simulate_names_the_argument():
    from drake_traj.validation import tracking_tolerance_check

    tracking_tolerance_check(0.005, 0.01)
    tracking_tolerance_check(None, 0.0)  # no tracking check: nothing to compare
    with pytest.raises(ValueError, match=r"tracking_tolerance = 6 mm .* \(5 mm of cell\.clearance = 10 mm\).*"
                                         r"lower tracking_tolerance to at most 5 mm or raise cell\.clearance to at "
                                         r"least 12 mm") as caught:
        tracking_tolerance_check(0.006, 0.01)
    assert isinstance(caught.value, DrakeTrajError) and caught.value.field == ("tracking_tolerance",)
    with pytest.raises(ValueError, match=r"raise cell\.clearance to at least 10 mm") as caught:
        tracking_tolerance_check(0.005, 0.0)
    assert "lower" not in str(caught.value)  # no positive tolerance is at most 0


BLOCK_SDF = """\
<?xml version="1.0"?>
<sdf version="1.7"><model name="meshblock"><link name="block">
  <collision name="c"><geometry><box><size>0.1 0.1 0.1</size></box></geometry></collision>
</link></model></sdf>
"""


def test_a_motion_into_a_directives_model_is_refused_at_its_directive(tmp_path):
    from drake_traj.cell import CollisionError
    from drake_traj.scenario import make_planner, preflight

    (tmp_path / "block.sdf").write_text(BLOCK_SDF)
    plan = make_planner(load_scenario(scenario_file(tmp_path, ""))).plan()
    centre = UR10E.tool_position(plan.value(0.5 * plan.end_time()).ravel())  # where the tool passes
    path = scenario_file(tmp_path, f"""\
        cell:
          directives:
          - add_model: {{name: meshblock, file: block.sdf}}
          - add_weld: {{parent: world, child: meshblock::block, X_PC: {{translation: {centre.round(4).tolist()}}}}}
        """)
    scenario = load_scenario(path)
    assert scenario.cell_checker().cell_fields["meshblock::block"] == ("cell", "directives", 0)
    with pytest.raises(CollisionError) as caught:
        preflight(scenario, make_planner(scenario))
    error = caught.value
    assert "meshblock::block" in error.bodies and error.field == ("cell", "directives", 0)
    assert str(error).startswith(f"{path}, line 6")  # the entry that adds the model, not the planner's line 2


@pytest.mark.parametrize("cli", [False, True])
def test_a_directives_model_welded_to_nothing_is_refused_at_its_directive(tmp_path, cli):
    import subprocess
    import sys

    from drake_traj.scenario import check_in_cell, make_planner

    (tmp_path / "block.sdf").write_text(BLOCK_SDF)
    path = scenario_file(tmp_path, """\
        cell:
          directives:
          - add_model: {name: meshblock, file: block.sdf}
        """)
    expected = (f"{path}, line 6, column 5: cell.directives[0]: model 'meshblock' is not welded to anything (its body "
                "'block' would fall freely): add an add_weld {parent: world, child: meshblock::block}")
    if cli:
        done = subprocess.run([sys.executable, "-m", "drake_traj.cli", "run", str(path), "--out", str(tmp_path / "out")],
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 2 and expected in done.stderr, done.stderr
        assert "into each other" not in done.stderr
        return
    scenario = load_scenario(path)
    with pytest.raises(DrakeTrajError) as caught:
        check_in_cell(scenario, make_planner(scenario))
    assert str(caught.value).startswith(expected) and caught.value.field == ("cell", "directives", 0)
    assert caught.value.cause is Cause.INVALID


def test_a_free_body_of_ones_own_is_refused_naming_its_model():
    """What a station's before_finalize adds unwelded (drake_traj.cell.refuse_free_bodies after
    Finalize); the robot's own bodies and welded ones pass."""
    from pydrake.multibody.tree import SpatialInertia

    from drake_traj.cell import refuse_free_bodies

    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, 0.0)
    instance = UR10E.add_to_plant(plant)
    fields = add_cell(plant, Cell(), instance)
    welded = plant.AddRigidBody("plate", plant.AddModelInstance("fixture"), SpatialInertia.SolidCubeWithDensity(1000.0, 0.1))
    plant.WeldFrames(plant.world_frame(), welded.body_frame())
    plant.AddRigidBody("crate", plant.AddModelInstance("pallet"), SpatialInertia.SolidCubeWithDensity(1000.0, 0.1))
    plant.Finalize()
    with pytest.raises(DrakeTrajError, match=r"^model 'pallet' is not welded to anything \(its body 'crate' would fall "
                                             r"freely\): weld it before the plant is finalized") as caught:
        refuse_free_bodies(plant, instance, fields)
    assert caught.value.field == () and caught.value.cause is Cause.INVALID
    plant, instance, fields = plant_with(Cell())
    refuse_free_bodies(plant, instance, fields)  # nothing free


@pytest.mark.parametrize("through", [False, True])
def test_directives_files_that_include_each_other_are_refused_naming_the_chain(tmp_path, through):
    """Drake follows add_directives without end on a cycle until it crashes (segmentation
    fault): the files are followed first, the cycle named at the entry's line."""
    first, second = tmp_path / "first.dmd.yaml", tmp_path / "second.dmd.yaml"
    first.write_text(f"directives:\n- add_directives: {{file: {(second if through else first).as_uri()}}}\n")
    second.write_text(f"directives:\n- add_directives: {{file: {first.as_uri()}}}\n")
    path = scenario_file(tmp_path, f"cell:\n  directives:\n  - add_directives: {{file: {first.as_uri()}}}\n")
    chain = [first.as_uri(), second.as_uri(), first.as_uri()] if through else [first.as_uri(), first.as_uri()]
    with pytest.raises(ScenarioError, match="include each other in a cycle") as caught:
        load_scenario(path).cell_checker()
    assert caught.value.field == ("cell", "directives", 0, "add_directives", "file")
    assert str(caught.value).startswith(f"{path}, line 6") and " -> ".join(chain) in str(caught.value)


def test_directives_files_included_twice_without_a_cycle_are_used(tmp_path):
    (tmp_path / "block.sdf").write_text(BLOCK_SDF)
    inner = tmp_path / "inner.dmd.yaml"
    inner.write_text(f"directives:\n- add_model: {{name: meshblock, file: {(tmp_path / 'block.sdf').as_uri()}}}\n"
                     "- add_weld: {parent: world, child: meshblock::block, X_PC: {translation: [0.0, 1.0, 0.1]}}\n")
    outer = tmp_path / "outer.dmd.yaml"
    outer.write_text("directives:\n- add_model_instance: {name: a}\n- add_model_instance: {name: b}\n"
                     f"- add_directives: {{file: {inner.as_uri()}, model_namespace: a}}\n"
                     f"- add_directives: {{file: {inner.as_uri()}, model_namespace: b}}\n")
    path = scenario_file(tmp_path, f"cell:\n  directives:\n  - add_directives: {{file: {outer.as_uri()}}}\n")
    plant = load_scenario(path).cell_checker().plant
    assert plant.HasModelInstanceNamed("a::meshblock") and plant.HasModelInstanceNamed("b::meshblock")


def test_a_directive_model_file_that_is_a_symbolic_link_loop_is_refused_at_its_entry(tmp_path):
    (tmp_path / "loop.sdf").symlink_to(tmp_path / "loop.sdf")
    path = scenario_file(tmp_path, "cell:\n  directives:\n  - add_model: {name: post, file: loop.sdf}\n")
    with pytest.raises(ScenarioError, match=r"no model file 'loop.sdf' .*symbolic link that loops") as caught:
        load_scenario(path).cell_checker()
    assert caught.value.field == ("cell", "directives", 0, "add_model", "file")
    assert str(caught.value).startswith(f"{path}, line 6")


def _second_arm(plant, scene_graph=None):
    """A second arm (Boryga's 3-joint anthropomorphic model) welded 2 m beside the robot."""
    from pydrake.math import RigidTransform
    from pydrake.multibody.parsing import Parser

    from drake_traj.data import data_directory

    MODELS = data_directory("models")

    (arm,) = Parser(plant, "second").AddModels(str(MODELS / "boryga_anthropomorphic.urdf"))
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("base", arm), RigidTransform([0.0, 2.0, 0.0]))


def _free_crate(plant, scene_graph=None):
    from pydrake.multibody.tree import SpatialInertia

    plant.AddRigidBody("crate", plant.AddModelInstance("pallet"), SpatialInertia.SolidCubeWithDensity(1000.0, 0.1))


@pytest.mark.parametrize("before_finalize, words", [
    (_second_arm, r"^model 'second::boryga_anthropomorphic' has joints that move \('waist_joint', 'shoulder_joint', 'elbow_joint'\): the station "
                  r"drives the robot's joints only"),
    (_free_crate, r"^model 'pallet' is not welded to anything"),
])
def test_a_station_refuses_models_its_controller_does_not_drive(before_finalize, words):
    """Was "DiagramBuilder::Connect: Mismatched vector sizes" (the feed-forward's inverse
    dynamics takes the whole plant's state, the robot's port gives the robot's)."""
    from drake_traj.scenario import make_planner
    from drake_traj.station import build_station

    planner = make_planner(load_scenario("quintic_ptp"))
    with pytest.raises(DrakeTrajError, match=words) as caught:
        build_station(planner, before_finalize=before_finalize)
    assert caught.value.field == () and caught.value.cause is Cause.INVALID


@pytest.mark.parametrize("weld, words", [
    ("- add_weld: {parent: world, child: arm2::base, X_PC: {translation: [0.0, 2.0, 0.0]}}\n",
     r"cell\.directives\[0\]: model 'arm2' has joints that move \('waist_joint', 'shoulder_joint', 'elbow_joint'\)"),
    ("", r"cell\.directives\[0\]: model 'arm2' is not welded to anything"),
])
@pytest.mark.parametrize("how", ["check", "simulate"])
def test_a_directives_arm_beside_the_robot_is_refused_at_its_directive(tmp_path, weld, words, how):
    from drake_traj import simulate
    from drake_traj.data import data_directory

    MODELS = data_directory("models")
    from drake_traj.scenario import check_in_cell, make_planner

    path = scenario_file(tmp_path, f"cell:\n  directives:\n  - add_model: {{name: arm2, file: "
                                   f"{MODELS / 'boryga_anthropomorphic.urdf'}}}\n  " + weld)
    scenario = load_scenario(path)
    with pytest.raises(DrakeTrajError, match=words) as caught:
        check_in_cell(scenario, make_planner(scenario)) if how == "check" else simulate(scenario)
    assert caught.value.field == ("cell", "directives", 0)
    assert str(caught.value).startswith(f"{path}, line 6")


@pytest.mark.parametrize("obstacle, farthest, half", [
    # independent: the farthest corner of the box, the farthest point of the cylinder's rims, the sphere's
    # radius; the half extents along the shape's axes
    (Box(size=[0.3, 0.2, 0.25], xyz=[2.0, 0.5, 0.4], rpy=[0.3, -0.2, 1.0]),
     max(np.linalg.norm([x, y, z]) for x in (-0.15, 0.15) for y in (-0.1, 0.1) for z in (-0.125, 0.125)),
     [0.15, 0.1, 0.125]),
    (Cylinder(radius=0.04, length=0.3, xyz=[2.0, -0.5, 0.3], rpy=[1.2, 0.0, 0.4]),
     max(np.linalg.norm([0.04 * np.cos(a), 0.04 * np.sin(a), z]) for a in np.linspace(0, 2 * np.pi, 73) for z in (-0.15, 0.15)),
     [0.04, 0.04, 0.15]),
    (Sphere(radius=0.12, xyz=[-2.0, 0.0, 0.5]), 0.12, [0.12, 0.12, 0.12]),
], ids=["box", "cylinder", "sphere"])
def test_each_obstacle_shape_bounds_itself_and_outlines_its_own_surface(obstacle, farthest, half):
    name = ("cell", "obstacles", 0)
    assert obstacle.bounding_radius(name) == pytest.approx(farthest, abs=1e-12)
    outline = obstacle.outline()
    points = np.vstack(outline)
    # the outline reaches the bounding sphere (its corners, rims, great circles) and spans the shape
    assert np.linalg.norm(points, axis=1).max() == pytest.approx(farthest, abs=1e-12)
    shape = obstacle.shape(name)
    assert np.allclose(points.max(axis=0), half) and np.allclose(points.min(axis=0), np.negative(half))
    # every point of it on the shape's surface, as Drake's own geometry in the cell has it (pose included)
    checker = CellChecker(UR10E, Cell(mounting=NoMounting(), obstacles=[obstacle]))
    query = checker.pose_query(UR10E.home_configuration)
    pose = obstacle.pose(name)
    for point in pose.multiply(points.T).T:
        (distance,) = [d.distance for d in query.ComputeSignedDistanceToPoint(point, 0.1)
                       if checker.owner(d.id_G)[1] == checker.cell.obstacle_name(0)]
        assert abs(distance) < 1e-9
    assert [line.tolist() for line in outline] == [line.tolist() for line in shape_outline(shape)]  # as Drake's shape


@pytest.mark.parametrize("cell, field, words", [
    (Cell(obstacles=[Box(), "a cone"]), ("cell", "obstacles", 1), "'a cone' is not an obstacle shape"),
    (Cell(tool=Tool(shapes=[DrakeBox(0.1, 0.1, 0.2)])), ("cell", "tool", "shapes", 0),
     r"Box\(width=0\.1, depth=0\.1, height=0\.2\) is not an obstacle shape \(Box, Cylinder, Sphere, or a subclass of "
     r"drake_traj\.cell\.Obstacle\)"),
])
def test_an_object_that_is_not_an_obstacle_shape_is_refused_naming_it(cell, field, words):
    for check in (cell.validate, lambda: plant_with(cell)):
        with pytest.raises(DrakeTrajError, match=words) as caught:
            check()
        assert caught.value.field == field and caught.value.cause is Cause.INVALID


def test_an_obstacle_shape_without_an_outline_cannot_be_made():
    @dataclass
    class Shapeless(Obstacle):
        name: str = ""

        def shape(self, name):
            return DrakeBox(0.1, 0.1, 0.1)

    with pytest.raises(TypeError, match="abstract method.*outline"):
        Shapeless()


@dataclass
class Cone(Obstacle):
    """A toy obstacle shape, defined here the way one adds a shape: an upright cone, its base a
    circle of ``radius`` [m] in its frame's x-y plane, its apex ``height`` [m] above."""

    name: str = ""
    radius: float = 0.1
    height: float = 0.3
    xyz: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy: list[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])

    def _rim(self, count: int = 32) -> np.ndarray:
        angles = np.linspace(0.0, 2.0 * np.pi, count + 1)
        return np.column_stack([self.radius * np.cos(angles), self.radius * np.sin(angles), np.zeros_like(angles)])

    def shape(self, name):
        vertices = [[0.0, 0.0, self.height]] + self._rim()[:-1].tolist()
        faces = [f"f 1 {k + 2} {(k + 1) % (len(vertices) - 1) + 2}" for k in range(len(vertices) - 1)]
        obj = "\n".join([f"v {x} {y} {z}" for x, y, z in vertices] + faces) + "\n"
        return Convex(InMemoryMesh(mesh_file=MemoryFile(obj, ".obj", "cone.obj")))

    def outline(self):
        apex = np.array([0.0, 0.0, self.height])
        return [self._rim()] + [np.array([point, apex]) for point in self._rim(4)[:-1]]


def test_an_obstacle_shape_is_one_class(tmp_path):
    """The recipe: a shape defined as one subclass of Obstacle (its Drake shape and its outline)
    is added to the plant, bounds itself, is checked (a motion through it refused) and drawn."""
    from drake_traj.scenario import make_planner

    plan = make_planner(load_scenario(scenario_file(tmp_path, ""))).plan()
    centre = UR10E.tool_position(plan.value(0.5 * plan.end_time()).ravel())  # where the tool passes
    cone = Cone(name="cone", radius=0.05, height=0.15, xyz=(centre - [0.0, 0.0, 0.05]).tolist())
    assert cone.bounding_radius(("cell", "obstacles", 0)) == pytest.approx(0.15)  # its apex
    assert shape_outline(cone.shape(("cell", "obstacles", 0))) == []  # Drake's convex shape is not drawn as such
    _, _, fields = plant_with(Cell(obstacles=[cone]))
    assert fields == {"table": ("cell", "mounting"), "cone": ("cell", "obstacles", 0)}
    checker = CellChecker(UR10E, Cell(obstacles=[cone]))
    planner = make_planner(load_scenario(scenario_file(tmp_path, "")))
    with pytest.raises(CollisionError) as caught:
        checker.check_planner(planner)
    error = caught.value
    assert "cone" in error.bodies and error.field == ("cell", "obstacles", 0)
    figure = refusal_figure(checker, error)
    pose = cone.pose(("cell", "obstacles", 0))
    for axes, (u, v) in zip(figure.axes, ((0, 2), (0, 1))):
        drawn = [(np.column_stack(line.get_data()), line.get_color()) for line in axes.get_lines()]
        for outline in cone.outline():  # each of its lines drawn, red (a body of the refusal)
            points = pose.multiply(outline.T).T[:, [u, v]]
            assert any(colour == "tab:red" and data.shape == points.shape and np.allclose(data, points)
                       for data, colour in drawn)
