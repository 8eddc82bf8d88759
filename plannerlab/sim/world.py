"""One PyBullet world: a robot from its URDF among static obstacles.

This package is the only plannerlab code that imports ``pybullet``. Every
:class:`SimWorld` owns its own physics client (``pybullet_utils.bullet_client.BulletClient``
adds the client id to every call), so any number of worlds can live in one process and no
global client id exists.

Physics follows the Arm-Z paper (``000_a8ed938e94518caf.txt``; ``docs/papers.md`` §1):
Featherstone multibody dynamics with a fixed base, time step 1/240 s, masses and inertias
taken from the URDF (``URDF_USE_INERTIA_FROM_FILE``: PyBullet would otherwise recompute
the inertia from the collision shapes), joint position control limited to each joint's
URDF effort (Arm-Z: 100 N·m).

Decisions:

* **Gravity is on**, −9.81 m/s² along world z (``gravity_mps2``): the paper simulates a
  real arm, so the motors must hold it up. The straight Arm-Z column (all θ = π) is held
  exactly, but trivially: every joint axis and every module's centre of mass lie in one
  vertical plane, so gravity has no torque about any joint. Bent poses of the 24-module
  arm whose static gravity torque stays under the 100 N·m limit hold to about 1e-3 rad;
  poses that need more (e.g. alternating θ = π and π − 0.6: about 125 N·m at joint 4)
  sag.
* **Self-collision** is reported (``URDF_USE_SELF_COLLISION``) but switched off, in the
  physics and in :meth:`SimWorld.contacts`, for the robot's ``excluded_pairs`` (modules
  that always overlap) and for its fixed links against the scene (the base stands on its
  pedestal), the same pairs :mod:`plannerlab.collision.fcl_checker` never checks; so are
  an obstacle's declared contacts (its ``touch_links``: a grasped object and the hand's
  links, ``setCollisionFilterPair``), in the physics, the contacts and the distances.
  ``..._EXCLUDE_ALL_PARENTS`` is not used: in a serial chain every pair of links is
  ancestor and descendant, so it would switch all self-collision off.
* **Link names**: PyBullet link indices are mapped to the robot's links by name (the child
  link name of each joint, the body name for the root). If the URDF root's name is not one
  of ``robot.link_names`` and exactly one fixed robot link has no URDF link of its name
  (Arm-Z: link ``module_0`` is the URDF root ``base``), the root is that link. URDF links
  without a robot link keep their URDF name in contacts.
* **Continuous joints** are not wrapped: :meth:`SimWorld.state` returns PyBullet's raw,
  unwrapped joint positions (equal to the input of :meth:`SimWorld.reset` right after a
  reset, continuing smoothly from there). :meth:`SimWorld.move_towards` sends each
  continuous joint the equivalent of its target nearest to the current angle, so a motor
  never turns the long way round.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from plannerlab.errors import PlannerlabError
from plannerlab.problem.scene import Box, Cylinder, Mesh, Obstacle, Scene, Sphere
from plannerlab.robots.base import Array, Robot, as_xyz, joint_difference
from plannerlab.sim.quiet import engine_output_logged

with engine_output_logged("pybullet import"):  # its build time, printed by C code
    import pybullet
    from pybullet_utils.bullet_client import BulletClient

#: the paper's control step [s]
DT_S: float = 1.0 / 240.0
#: gravity along world z [m/s^2]
GRAVITY_MPS2: tuple[float, float, float] = (0.0, 0.0, -9.81)
#: PyBullet's constraint solvers by name: "pgs" (its default, iterative projected
#: Gauss-Seidel) and "dantzig" (a direct solver of the mixed LCP)
SOLVERS: dict[str, int] = {
    "pgs": pybullet.CONSTRAINT_SOLVER_LCP_SI,
    "dantzig": pybullet.CONSTRAINT_SOLVER_LCP_DANTZIG,
}


@dataclass(frozen=True)
class Contact:
    """One contact point involving the robot.

    Attributes:
        link_name: the robot link in contact (robot link name; URDF name if it has none).
        other_name: an obstacle's name, or the other robot link for self-contact.
        other_is_link: True for self-contact.
        depth_m: penetration depth [m] (= −PyBullet's contact distance); < 0 is a gap
            within PyBullet's contact-breaking threshold.
        p_world_m: (3,) the contact point on the robot link, world frame [m].
    """

    link_name: str
    other_name: str
    other_is_link: bool
    depth_m: float
    p_world_m: tuple[float, float, float]


def _quat_xyzw(T: Array) -> list[float]:
    return [float(v) for v in Rotation.from_matrix(np.asarray(T)[:3, :3]).as_quat()]


def _pose(position: Any, quat_xyzw: Any) -> Array:
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat(np.asarray(quat_xyzw, dtype=float)).as_matrix()
    T[:3, 3] = np.asarray(position, dtype=float)
    return T


class SimWorld:
    """A PyBullet world holding one robot (fixed base at ``robot.T_world_base``) and a scene.

    Use it as a context manager, or call :meth:`close`::

        with SimWorld(problem.robot, problem.scene) as world:
            world.reset(q0)
            q = world.move_towards(q1, steps=100)

    It satisfies :class:`plannerlab.planners.base.Stepper`.

    Args:
        robot: the robot model; its ``urdf()`` is loaded.
        scene: static obstacles (boxes, cylinders, spheres at their poses; a mesh
            obstacle as its triangles, not the boxes covering it).
        gui: open PyBullet's GUI instead of the headless DIRECT mode (one per process).
        dt_s: physics time step [s] (paper: 1/240).
        gravity_mps2: gravity in the world frame [m/s²].
        position_gain, velocity_gain: PyBullet's position-control gains; None keeps
            PyBullet's defaults (0.1 and 1.0); the paper names no gains.
        max_force: motor force/torque limit per joint [N·m or N] overriding the URDF's
            effort limits (a scalar or one value per joint).
        solver: PyBullet's constraint solver, a key of :data:`SOLVERS`: ``"pgs"``
            (PyBullet's default, iterative projected Gauss-Seidel) or ``"dantzig"`` (a
            direct solver of the mixed LCP: the motors' constraint rows solved exactly;
            what the executors use, see :mod:`plannerlab.sim.execute`).
        solver_iterations: the iterative solver's iterations per step (None: PyBullet's
            default, 50).

    Raises:
        PlannerlabError: a joint of ``robot.joint_names`` is missing from the URDF, or a
            joint has no positive effort limit and ``max_force`` is not given.
    """

    def __init__(
        self,
        robot: Robot,
        scene: Scene | None = None,
        *,
        gui: bool = False,
        dt_s: float = DT_S,
        gravity_mps2: tuple[float, float, float] = GRAVITY_MPS2,
        position_gain: float | None = None,
        velocity_gain: float | None = None,
        max_force: float | Array | None = None,
        solver: str = "pgs",
        solver_iterations: int | None = None,
    ) -> None:
        self.robot = robot
        self.scene = scene if scene is not None else Scene()
        self.dt_s = float(dt_s)
        self.gravity_mps2: tuple[float, float, float] = (
            float(gravity_mps2[0]),
            float(gravity_mps2[1]),
            float(gravity_mps2[2]),
        )
        self.steps_taken = 0
        if solver not in SOLVERS:
            raise PlannerlabError(f"solver must be one of {', '.join(SOLVERS)}, got {solver!r}")
        self.solver = solver
        self._continuous = np.asarray(robot.continuous, dtype=bool)
        # argv[0]=, a GUI's OpenGL report, the solver's name: C code's, logged
        with engine_output_logged("pybullet connect"):
            self._client: BulletClient | None = BulletClient(
                connection_mode=pybullet.GUI if gui else pybullet.DIRECT
            )
        try:
            with engine_output_logged("pybullet set-up"):
                self._build(max_force)
                if solver != "pgs":
                    self.client.setPhysicsEngineParameter(constraintSolverType=SOLVERS[solver])
                if solver_iterations is not None:
                    self.client.setPhysicsEngineParameter(
                        numSolverIterations=int(solver_iterations)
                    )
        except BaseException:
            self.close()
            raise
        dof = robot.dof
        self._gains: dict[str, list[float]] = {}
        if position_gain is not None:
            self._gains["positionGains"] = [float(position_gain)] * dof
        if velocity_gain is not None:
            self._gains["velocityGains"] = [float(velocity_gain)] * dof

    # ------------------------------------------------------------------ building
    @property
    def client(self) -> BulletClient:
        """The world's own PyBullet client (raises once closed)."""
        if self._client is None:
            raise PlannerlabError("this SimWorld is closed")
        return self._client

    def _build(self, max_force: float | Array | None) -> None:
        c = self.client
        robot = self.robot
        c.setTimeStep(self.dt_s)
        c.setGravity(*self.gravity_mps2)
        T = np.asarray(robot.T_world_base, dtype=float)
        flags = pybullet.URDF_USE_SELF_COLLISION | pybullet.URDF_USE_INERTIA_FROM_FILE
        with tempfile.TemporaryDirectory(prefix="plannerlab_urdf_") as tmp:
            path = Path(tmp) / f"{robot.kind}.urdf"
            path.write_text(robot.urdf(), encoding="utf-8")
            self.body = c.loadURDF(
                str(path), T[:3, 3].tolist(), _quat_xyzw(T), useFixedBase=True, flags=flags
            )

        # Joints and links by name.
        n_joints = c.getNumJoints(self.body)
        infos = [c.getJointInfo(self.body, j) for j in range(n_joints)]
        joint_index = {info[1].decode(): j for j, info in enumerate(infos)}
        missing = [n for n in robot.joint_names if n not in joint_index]
        if missing:
            raise PlannerlabError(
                f"the {robot.kind} URDF lacks joints {missing}; it has {sorted(joint_index)}"
            )
        self._joints = [joint_index[n] for n in robot.joint_names]
        #: PyBullet link index (-1 = root) -> URDF link name
        self.urdf_link_names: dict[int, str] = {-1: c.getBodyInfo(self.body)[0].decode()}
        for j, info in enumerate(infos):
            self.urdf_link_names[j] = info[12].decode()
        self._pb_link = {name: j for j, name in self.urdf_link_names.items()}
        robot_links = list(robot.link_names)
        # the URDF link of each robot link: its name, unless the robot says otherwise (a
        # URDF robot has several capsules per URDF link; the first one stands for them
        # all, their self-collision pairs being excluded or not alike)
        urdf_of_link = list(getattr(robot, "link_urdf_names", robot_links))
        # PyBullet link index -> robot link index
        self._robot_link: dict[int, int] = {
            j: urdf_of_link.index(name)
            for j, name in self.urdf_link_names.items()
            if name in urdf_of_link
        }
        if -1 not in self._robot_link:
            unmatched = [i for i, n in enumerate(robot_links) if n not in self._pb_link]
            if len(unmatched) == 1 and unmatched[0] in robot.fixed_links:
                self._robot_link[-1] = unmatched[0]
        self._pb_of_robot_link = {i: j for j, i in self._robot_link.items()}
        self._frame_links = []
        for name in robot.link_frame_names:
            if name not in self._pb_link:
                raise PlannerlabError(
                    f"the {robot.kind} URDF lacks link {name!r}; it has {sorted(self._pb_link)}"
                )
            self._frame_links.append(self._pb_link[name])
        self._moving_frame_links = [j for j in self._frame_links if j >= 0]
        dyn = c.getDynamicsInfo(self.body, -1)
        self._T_com_rootlink = np.linalg.inv(_pose(dyn[3], dyn[4]))

        # Motor limits.
        if max_force is not None:
            forces = np.broadcast_to(np.asarray(max_force, dtype=float), (robot.dof,)).copy()
        else:
            forces = np.array([infos[j][10] for j in self._joints], dtype=float)
        bad = [robot.joint_names[i] for i in np.flatnonzero(~(forces > 0))]
        if bad:
            raise PlannerlabError(
                f"joints {bad} have no positive effort limit in the URDF; pass max_force"
            )
        self.max_force = forces
        self.max_force.setflags(write=False)
        #: the URDF joints' velocity limits (dof,) [rad/s or m/s] (inf where none is set)
        vel = np.array([infos[j][11] for j in self._joints], dtype=float)
        self.max_velocity = np.where(vel > 0, vel, np.inf)
        self.max_velocity.setflags(write=False)
        # PyBullet's inverse dynamics takes every movable joint in index order.
        movable = [j for j, info in enumerate(infos) if info[2] != pybullet.JOINT_FIXED]
        self._dyn_order: list[int] | None = (
            [movable.index(j) for j in self._joints]
            if sorted(movable) == sorted(self._joints)
            else None
        )
        self._dyn_order_array = np.asarray(self._dyn_order or [], dtype=np.intp)
        self._dyn_identity = self._dyn_order == list(range(len(self._joints)))

        # Self-collision filters: the pairs the FCL checker never checks.
        self._excluded_pairs = robot.excluded_pairs
        n_links = len(robot_links)
        #: (L, L) True for a link with itself and for excluded pairs
        self._unchecked_pairs = np.eye(n_links, dtype=bool)
        for i, j in self._excluded_pairs:
            self._unchecked_pairs[i, j] = self._unchecked_pairs[j, i] = True
        for i, j in robot.excluded_pairs:
            a, b = self._pb_of_robot_link.get(i), self._pb_of_robot_link.get(j)
            if a is not None and b is not None:
                c.setCollisionFilterPair(self.body, self.body, a, b, 0)
        # The checked pairs as PyBullet link pairs (a, b, robot link of a, of b):
        # link_distances asks for these alone. Asked for the body against itself,
        # PyBullet measures every pair, the excluded ones too (getClosestPoints ignores
        # the collision filters), and adjacent links overlap at their joints: on the
        # SO-101's meshes that was 28 of 28.5 ms a state, the same distances
        # (bench/sim_clearance_queries.py).
        pb = sorted(self._robot_link)
        self._self_queries = [
            (a, b, self._robot_link[a], self._robot_link[b])
            for n, a in enumerate(pb)
            for b in pb[n + 1 :]
            if not self._unchecked_pairs[self._robot_link[a], self._robot_link[b]]
        ]

        # Obstacles: static bodies; fixed robot links never touch them.
        self._gui = c.getConnectionInfo()["connectionMethod"] == pybullet.GUI
        self.obstacle_names: dict[int, str] = {}
        # a mesh obstacle is its triangles here (its cover boxes are the planners')
        shapes: list[Obstacle | Mesh] = [
            o for o in self.scene.obstacles if not getattr(o, "cover_of", "")
        ]
        #: per obstacle body, the PyBullet links of its declared contacts (its
        #: ``touch_links``): no contact is made or counted between them, and no
        #: distance measured (the pairs the collision checker never checks)
        self._touch_links: dict[int, frozenset[int]] = {}
        for o in [*shapes, *self.scene.meshes]:
            uid = self._make_obstacle(o)
            self.obstacle_names[uid] = o.name
            for i in robot.fixed_links:
                a = self._pb_of_robot_link.get(i)
                if a is not None:
                    c.setCollisionFilterPair(self.body, uid, a, -1, 0)
            touch = frozenset(self._pb_link[n] for n in o.touch_links if n in self._pb_link)
            if touch:
                self._touch_links[uid] = touch
                for a in touch:
                    c.setCollisionFilterPair(self.body, uid, a, -1, 0)

    def _make_obstacle(self, o: Obstacle | Mesh) -> int:
        c = self.client
        if isinstance(o, Mesh):
            # a static body: its triangles as they are (concave), not their convex hull
            mesh_args = dict(
                vertices=np.asarray(o.vertices_m, dtype=float).tolist(),
                indices=np.asarray(o.faces, dtype=int).reshape(-1).tolist(),
            )
            shape = c.createCollisionShape(
                pybullet.GEOM_MESH, flags=pybullet.GEOM_FORCE_CONCAVE_TRIMESH, **mesh_args
            )
            visual = dict(shapeType=pybullet.GEOM_MESH, **mesh_args)
        elif isinstance(o, Box):
            half = [float(s) / 2.0 for s in o.size_m]
            shape = c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=half)
            visual = dict(shapeType=pybullet.GEOM_BOX, halfExtents=half)
        elif isinstance(o, Cylinder):
            shape = c.createCollisionShape(
                pybullet.GEOM_CYLINDER, radius=float(o.radius_m), height=float(o.length_m)
            )
            visual = dict(
                shapeType=pybullet.GEOM_CYLINDER, radius=float(o.radius_m), length=float(o.length_m)
            )
        elif isinstance(o, Sphere):
            shape = c.createCollisionShape(pybullet.GEOM_SPHERE, radius=float(o.radius_m))
            visual = dict(shapeType=pybullet.GEOM_SPHERE, radius=float(o.radius_m))
        else:  # pragma: no cover - Scene only holds the three kinds
            raise PlannerlabError(f"obstacle {o.name!r}: unsupported kind {o.kind!r}")
        vis = -1
        if self._gui:
            vis = c.createVisualShape(rgbaColor=[0.6, 0.6, 0.7, 0.5], **visual)
        T = o.T_world_obstacle
        return c.createMultiBody(
            baseMass=0.0,
            baseCollisionShapeIndex=shape,
            baseVisualShapeIndex=vis,
            basePosition=T[:3, 3].tolist(),
            baseOrientation=_quat_xyzw(T),
        )

    # ------------------------------------------------------------------ lifetime
    def close(self) -> None:
        """Disconnect the client (idempotent)."""
        if self._client is not None:
            try:
                self._client.disconnect()
            finally:
                self._client = None

    def __enter__(self) -> SimWorld:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()

    @property
    def sim_time_s(self) -> float:
        """Simulated time since the world was built: steps taken × ``dt_s`` [s]."""
        return self.steps_taken * self.dt_s

    # ------------------------------------------------------------------ state
    def to_urdf(self, q: Array) -> Array:
        """q (..., dof) -> the URDF's joint values (..., dof) (the identity for Arm-Z)."""
        return self._to_urdf(q)

    def from_urdf(self, q_urdf: Array) -> Array:
        """Inverse of :meth:`to_urdf`."""
        return self._from_urdf(q_urdf)

    def _to_urdf(self, q: Array) -> Array:
        """q -> the URDF's joint values. A robot whose URDF joints are not q itself (the
        IRb-6 keeps absolute angles in q) provides ``urdf_joint_positions``."""
        convert = getattr(self.robot, "urdf_joint_positions", None)
        return np.asarray(convert(q) if convert is not None else q, dtype=float)

    def _from_urdf(self, q_urdf: Array) -> Array:
        convert = getattr(self.robot, "q_from_urdf_joint_positions", None)
        return np.asarray(convert(q_urdf) if convert is not None else q_urdf, dtype=float)

    def _q(self, q: Array) -> Array:
        q = np.asarray(q, dtype=float)
        if q.shape != (self.robot.dof,):
            raise PlannerlabError(f"q must have shape ({self.robot.dof},), got {q.shape}")
        return q

    def reset(self, q_rad: Array) -> None:
        """Put the robot at q (dof,) at rest, and hold it there with the motors.

        Continuous joints keep the given values (no wrapping), so :meth:`state` returns
        ``q_rad`` right after. Contacts are recomputed for the new state.
        """
        q = self._q(q_rad)
        c = self.client
        for j, v in zip(self._joints, self._to_urdf(q), strict=True):
            c.resetJointState(self.body, j, float(v), 0.0)
        self._command(q)
        c.performCollisionDetection()

    def state(self) -> Array:
        """Joint positions (dof,) [rad or m]: PyBullet's raw values, continuous joints
        unwrapped (they continue from the last :meth:`reset` without jumps)."""
        states = self.client.getJointStates(self.body, self._joints)
        return self._from_urdf(np.array([s[0] for s in states], dtype=float))

    def velocity(self) -> Array:
        """Joint velocities (dof,) [rad/s or m/s] of the URDF's joints (for robots whose
        URDF joints are not q itself, see ``_to_urdf``, these are the URDF's rates)."""
        states = self.client.getJointStates(self.body, self._joints)
        return np.array([s[1] for s in states], dtype=float)

    def _command(self, q_target: Array) -> None:
        self.client.setJointMotorControlArray(
            self.body,
            self._joints,
            pybullet.POSITION_CONTROL,
            targetPositions=self._to_urdf(q_target).tolist(),
            forces=self.max_force.tolist(),
            **self._gains,
        )

    def command(self, q_target_rad: Array) -> Array:
        """Set the position-control target without stepping.

        Continuous joints get the equivalent of their target nearest to the current angle.

        Returns:
            the target actually sent (dof,).
        """
        q_t = self._q(q_target_rad)
        q_now = self.state()
        sent = np.where(
            self._continuous, q_now + joint_difference(q_t, q_now, self._continuous), q_t
        )
        self._command(sent)
        return sent

    def state_urdf(self) -> tuple[Array, Array]:
        """Positions and velocities (dof,) of the URDF's joints."""
        states = self.client.getJointStates(self.body, self._joints)
        return (
            np.array([s[0] for s in states], dtype=float),
            np.array([s[1] for s in states], dtype=float),
        )

    def command_urdf(
        self, q_urdf: Array, qd_urdf: Array, *, position_gain: float | None = None
    ) -> None:
        """Position and velocity targets (dof,) for the URDF's joints, without stepping
        (no wrapping: continuous joints go to the value given).

        PyBullet's motor asks for velocity ``qd_urdf + position_gain × (q_urdf − q)/dt``
        (velocity gain 1), within the effort limits. ``position_gain`` overrides the
        world's gain for this command.
        """
        gains = dict(self._gains)
        if position_gain is not None:
            gains["positionGains"] = [float(position_gain)] * self.robot.dof
        self.client.setJointMotorControlArray(
            self.body,
            self._joints,
            pybullet.POSITION_CONTROL,
            targetPositions=np.asarray(q_urdf, dtype=float).tolist(),
            targetVelocities=np.asarray(qd_urdf, dtype=float).tolist(),
            forces=self.max_force.tolist(),
            **gains,
        )

    def inverse_dynamics(self, q_urdf: Array, qd_urdf: Array, qdd_urdf: Array) -> Array:
        """Joint torques/forces (dof,) that give accelerations ``qdd_urdf`` at positions
        ``q_urdf`` and velocities ``qd_urdf`` (URDF joints), under the world's gravity.

        Raises:
            PlannerlabError: the URDF has movable joints the robot does not drive.
        """
        if self._dyn_order is None:
            raise PlannerlabError(
                f"the {self.robot.kind} URDF has movable joints outside robot.joint_names; "
                "no inverse dynamics"
            )
        # toppra asks this ~10^4 times a leg: plain lists when the orders agree
        order = self._dyn_order_array
        if self._dyn_identity:
            args = [np.asarray(v, dtype=float).tolist() for v in (q_urdf, qd_urdf, qdd_urdf)]
            return np.array(self.client.calculateInverseDynamics(self.body, *args))
        full = np.zeros((3, len(order)))
        full[:, order] = np.stack((q_urdf, qd_urdf, qdd_urdf))
        tau = np.asarray(self.client.calculateInverseDynamics(self.body, *full.tolist()))
        return tau[order]

    def step(self, steps: int = 1) -> None:
        """Advance the physics ``steps`` time steps of ``dt_s``."""
        c = self.client
        for _ in range(int(steps)):
            c.stepSimulation()
        self.steps_taken += int(steps)

    def move_towards(self, q_target: Array, steps: int) -> Array:
        """Position control towards q_target (dof,) for ``steps`` steps; the state reached.

        The paper's ``posctrltowards``: motor forces limited to the joints' effort
        limits, continuous joints driven the short way round.
        """
        self.command(q_target)
        self.step(steps)
        return self.state()

    # ------------------------------------------------------------------ queries
    def link_frames(self) -> Array:
        """``T_world_link`` (F, 4, 4) of the URDF links ``robot.link_frame_names``, in
        order; comparable with ``robot.fk(self.state())``."""
        c = self.client
        states = c.getLinkStates(self.body, self._moving_frame_links, computeForwardKinematics=True)
        # PyBullet rounds the URDF link frame (items 4, 5) to float32; the inertial frame
        # (items 0, 1) and its local offset (items 2, 3) come in full double precision.
        by_index = {
            j: _pose(s[0], s[1]) @ np.linalg.inv(_pose(s[2], s[3]))
            for j, s in zip(self._moving_frame_links, states, strict=True)
        }
        if -1 in self._frame_links:
            pos, orn = c.getBasePositionAndOrientation(self.body)  # the root's inertial frame
            by_index[-1] = _pose(pos, orn) @ self._T_com_rootlink
        return np.stack([by_index[j] for j in self._frame_links])

    def link_name(self, pb_link: int) -> tuple[str, int | None]:
        """The name of a PyBullet link index of the robot's body, and its index among
        ``robot.link_names`` (None for a URDF link that is no robot link: the base, a
        fixed mount). Contact and closest-point queries report links by PyBullet index.
        """
        i = self._robot_link.get(pb_link)
        if i is None:
            return self.urdf_link_names[pb_link], None
        if getattr(self.robot, "mesh_covers", ()) or getattr(self.robot, "sim_urdf_path", None):
            # PyBullet holds the link's meshes, not the spheres covering them
            return self.urdf_link_names[pb_link], i
        return self.robot.link_names[i], i

    def set_state(self, q_rad: Array) -> None:
        """Put the joints at q (dof,) kinematically (no motor command, no physics step):
        for closest-point queries of a probe world (:mod:`plannerlab.sim.measure`)."""
        q = self._q(q_rad)
        # one call for every joint (a probe is set thousands of times an execution)
        self.client.resetJointStatesMultiDof(
            self.body,
            self._joints,
            [[float(v)] for v in self._to_urdf(q)],
            [[0.0]] * len(self._joints),
        )

    def link_distances(
        self, max_distance_m: float, starts: Array | None = None
    ) -> tuple[Array, list[str], Array]:
        """Closest distances of the robot's current state, from PyBullet's closest points
        (``getClosestPoints``) up to ``max_distance_m``: every robot link not in
        ``robot.fixed_links`` against every obstacle (but an obstacle's declared contacts,
        its ``touch_links``), and every pair of robot links not in
        ``robot.excluded_pairs`` (the pairs the collision checker checks).

        Args:
            max_distance_m: pairs farther than this are not read [m].
            starts: (G,) increasing robot link indices, 0 first: report per group of
                consecutive links (the links from ``starts[g]`` up to the next start)
                instead of per link. A mesh robot's URDF link is covered by a run of
                capsules that PyBullet measures as one link, its meshes: per URDF link
                the arrays are G, not L capsules long (a finer cover has hundreds, and
                (L, L) arrays cost more than the query).

        Returns:
            ``scene_m`` (L,) or (G,): per robot link (group), the distance to the nearest
            obstacle [m] (negative: penetration; ``max_distance_m`` when none is that
            close, inf for a fixed link); ``obstacle``: that obstacle's name ("" when
            none); ``self_m`` (L, L) or (G, G): symmetric, the distance between two links
            [m] (``max_distance_m`` when farther, inf for a link with itself and for an
            excluded pair; a group pair: its first links').
        """
        c = self.client
        robot = self.robot
        L = len(robot.link_names)
        dmax = float(max_distance_m)
        fixed = np.zeros(L, dtype=bool)
        fixed[list(robot.fixed_links)] = True
        if starts is None:
            group = np.arange(L)
            first = group
        else:
            first = np.asarray(starts, dtype=np.intp)
            group = np.searchsorted(first, np.arange(L), side="right") - 1
        G = len(first)
        scene = np.where(fixed[first], np.inf, dmax)
        names = [""] * G
        for uid, name in self.obstacle_names.items():
            touch = self._touch_links.get(uid, frozenset())
            for pt in c.getClosestPoints(self.body, uid, dmax):
                i = self._robot_link.get(pt[3])
                if i is None or fixed[i] or pt[3] in touch:
                    continue
                g, d = int(group[i]), float(pt[8])
                if d < scene[g]:
                    scene[g] = d
                    names[g] = name
        unchecked = (
            self._unchecked_pairs if starts is None else self._unchecked_pairs[np.ix_(first, first)]
        )
        pair = np.where(unchecked, np.inf, dmax)
        for a, b, i, k in self._self_queries:
            g, h = int(group[i]), int(group[k])
            for pt in c.getClosestPoints(self.body, self.body, dmax, a, b):
                d = float(pt[8])
                if d < pair[g, h]:
                    pair[g, h] = pair[h, g] = d
        return scene, names, pair

    def contacts(self, min_depth_m: float = 0.0) -> list[Contact]:
        """Contact points of the robot from the last physics step (or reset).

        Args:
            min_depth_m: keep points whose penetration depth exceeds this [m]. 0 keeps
                every touching point; a negative value also keeps near misses within
                PyBullet's contact-breaking threshold.

        Returns:
            one :class:`Contact` per point; self-contacts once, with the lower-indexed
            robot link as ``link_name``. Excluded pairs and an obstacle's declared contacts
            (its ``touch_links``) never appear.
        """
        out: list[Contact] = []
        excluded = self._excluded_pairs
        fixed = self.robot.fixed_links
        for pt in self.client.getContactPoints(bodyA=self.body):
            a, b, la, lb = pt[1], pt[2], pt[3], pt[4]
            depth = -float(pt[8])
            if depth <= min_depth_m:
                continue
            p_on_robot = pt[5]
            if a != self.body:  # make the robot side A
                a, b, la, lb = b, a, lb, la
                p_on_robot = pt[6]
            name, i = self.link_name(la)
            if b == self.body:
                other, k = self.link_name(lb)
                if i is not None and k is not None:
                    if (min(i, k), max(i, k)) in excluded:
                        continue
                    if k < i:  # name the lower link first; the point lies on it
                        name, other = other, name
                        p_on_robot = pt[6] if p_on_robot is pt[5] else pt[5]
                out.append(Contact(name, other, True, depth, as_xyz(p_on_robot)))
            else:
                if (i is not None and i in fixed) or la in self._touch_links.get(b, ()):
                    continue
                other = self.obstacle_names.get(b, f"body_{b}")
                out.append(Contact(name, other, False, depth, as_xyz(p_on_robot)))
        return out
