"""What a drawer is: the ``DrawerVariant`` dataclass, its validation, and the suite's constants.

Numpy and the standard library only, so the scripted expert and the catalogue import no MuJoCo.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

HANDLE_TYPES: tuple[str, ...] = ("bar", "knob", "lip", "vbar")
SUCCESS_FRACTION = 0.8
PULL_FRACTION = 0.1
PLACEMENT_RANGE = (0.03, 0.03, 5.0)  # the "narrow" setting's +- x (m), +- y (m), +- yaw (degrees)
MAX_EPISODE_STEPS = 300

# The table top is z = 0, x in [-0.7, 0.7]; MetaWorld's retaining walls stand at y = 0.21 and 0.99.
TABLE_X_LIMIT = 0.62
TABLE_Y_RANGE = (0.45, 0.985)

# Handle-part sizes shared by the validation below and the MJCF (``mjcf.py``).
BAR_RADIUS = 0.007
VBAR_OVERHANG = 0.03
LIP_TAB_HEIGHT = 0.035
FINGER_MARGIN = 0.005
STANDOFF_RADIUS = 0.005
BAR_POST_INSET = 0.012  # a bar's standoffs stand this far in from its ends


@dataclass(frozen=True)
class Placement:
    """How far each reset moves and recolours a drawer around its variant's nominal pose.

    Attributes:
        name: The setting's name (``PLACEMENTS``).
        x: Shift across the table, +- metres.
        y: Shift towards or away from the robot, +- metres.
        yaw: Turn about the vertical, +- degrees.
        lift: The case stands up to this many metres higher (on a taller plinth).
        colour: Shift of each RGB channel of the case, the front and the handle, +-.
        keep_on_table: Move a case that a shift pushes off the table or into the back wall back just
            far enough (``narrow`` does not, so that it replays exactly).
    """

    name: str
    x: float
    y: float
    yaw: float
    lift: float = 0.0
    colour: float = 0.0
    keep_on_table: bool = True

    def __post_init__(self) -> None:
        for field_name in ("x", "y", "yaw", "lift", "colour"):
            value = getattr(self, field_name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"Placement {self.name!r}: {field_name} must be >= 0, got {value}.")

    @property
    def reset_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Low and high of the per-reset offset vector: x, y, yaw, then lift and 9 colour shifts if any."""
        low, high = [-self.x, -self.y, -self.yaw], [self.x, self.y, self.yaw]
        if self.lift or self.colour:
            low += [0.0] + [-self.colour] * 9
            high += [self.lift] + [self.colour] * 9
        return np.array(low), np.array(high)


PLACEMENTS: dict[str, Placement] = {
    placement.name: placement
    for placement in (
        # The suite's first ranges: a drawer nearly where its variant puts it, always the same colours.
        Placement(
            "narrow", x=PLACEMENT_RANGE[0], y=PLACEMENT_RANGE[1], yaw=PLACEMENT_RANGE[2], keep_on_table=False
        ),
        # What a row of kitchen drawers shows a robot whose base is not square to the counter:
        # positions along the counter, counter depths, cabinet heights, the robot's angle to it,
        # and paint / wood / metal finishes.
        Placement("kitchen", x=0.10, y=0.05, yaw=12.0, lift=0.06, colour=0.2),
    )
}
DEFAULT_PLACEMENT = "kitchen"


def placement_named(name: str | None) -> Placement:
    """The placement setting ``name`` (None: ``DEFAULT_PLACEMENT``); a ``ValueError`` lists the settings."""
    name = DEFAULT_PLACEMENT if name is None else name
    if name not in PLACEMENTS:
        raise ValueError(f"Unknown drawer placement {name!r}; choose one of {sorted(PLACEMENTS)}.")
    return PLACEMENTS[name]


DRAWER_STATE_NAMES: list[str] = [
    "hand_x",
    "hand_y",
    "hand_z",
    "gripper",
    "handle_x",
    "handle_y",
    "handle_z",
    "grasp_x",
    "grasp_y",
    "grasp_z",
    "axis_x",
    "axis_y",
    "axis_z",
    "opening",
    "travel",
    "goal_x",
    "goal_y",
    "goal_z",
]
STATE_INDEX = {name: i for i, name in enumerate(DRAWER_STATE_NAMES)}


def _check(condition: bool, message: str) -> None:
    if not condition:
        raise ValueError(message)


@dataclass(frozen=True)
class DrawerVariant:
    """One procedurally generated drawer. Lengths in metres, angles in degrees.

    Attributes:
        name: Task name, ``drawer-<handle>-<what sets it apart>``.
        handle: ``bar``, ``knob``, ``lip`` or ``vbar``.
        handle_size: Bar length (bar, vbar), cap radius (knob) or tab width (lip).
        handle_height: Handle centre on the front, a fraction of half the front height (-1 bottom,
            1 top); 0 for ``lip``.
        handle_clearance: Gap between the front panel and the back of the handle (unused by ``lip``).
        width: Outer width of the case.
        height: Outer height of the case.
        depth: Outer depth of the case.
        travel: How far the drawer slides open.
        damping: Viscous damping of the slide joint, N s/m.
        friction: Dry friction of the slide joint (MuJoCo ``frictionloss``), N.
        x: Case front centre, world x (the table spans about -0.6 .. 0.6).
        y: Case front centre, world y (the case extends from here away from the robot).
        yaw: Case rotation about the vertical axis; 0 faces the robot.
        elevation: Height of a plinth under the case (0: on the table).
        case_rgba: Case colour.
        front_rgba: Front panel colour.
        handle_rgba: Handle colour.
    """

    name: str
    handle: str
    handle_size: float
    handle_height: float
    handle_clearance: float
    width: float
    height: float
    depth: float
    travel: float
    damping: float
    friction: float
    x: float
    y: float
    yaw: float
    elevation: float = 0.0
    case_rgba: tuple[float, float, float, float] = (0.55, 0.42, 0.3, 1.0)
    front_rgba: tuple[float, float, float, float] = (0.75, 0.6, 0.42, 1.0)
    handle_rgba: tuple[float, float, float, float] = (0.7, 0.7, 0.72, 1.0)

    def __post_init__(self) -> None:
        where = f"DrawerVariant {self.name!r}"
        _check(
            self.name.startswith("drawer-"),
            f"{where}: task names start with 'drawer-' (got {self.name!r}).",
        )
        _check(
            self.handle in HANDLE_TYPES,
            f"{where}: handle must be one of {HANDLE_TYPES}, got {self.handle!r}.",
        )
        for field in ("handle_size", "handle_clearance", "width", "height", "depth"):
            value = getattr(self, field)
            _check(
                math.isfinite(value) and value > 0,
                f"{where}: {field} must be a positive length in metres, got {value}.",
            )
        _check(
            math.isfinite(self.travel) and self.travel > 0,
            f"{where}: travel must be > 0 (a drawer that cannot move cannot be opened), got {self.travel}.",
        )
        _check(
            self.travel <= 0.8 * self.depth,
            f"{where}: travel {self.travel} m exceeds 0.8 x depth ({0.8 * self.depth:.3f} m); "
            "make the case deeper or the travel shorter.",
        )
        for field in ("damping", "friction", "elevation"):
            value = getattr(self, field)
            _check(math.isfinite(value) and value >= 0, f"{where}: {field} must be >= 0, got {value}.")
        _check(
            -1.0 < self.handle_height < 1.0,
            f"{where}: handle_height must be in (-1, 1), got {self.handle_height}.",
        )
        _check(
            self.handle != "lip" or self.handle_height == 0.0,
            f"{where}: a lip handle sits on the top edge; set handle_height=0 (got {self.handle_height}).",
        )
        _check(abs(self.yaw) <= 30.0, f"{where}: yaw must be within +-30 degrees, got {self.yaw}.")
        for field in ("case_rgba", "front_rgba", "handle_rgba"):
            color = getattr(self, field)
            _check(
                len(color) == 4 and all(0.0 <= c <= 1.0 for c in color),
                f"{where}: {field} must be 4 numbers in [0, 1], got {color}.",
            )
        self._check_handle_fits(where)
        self._check_on_table(where)

    def _check_handle_fits(self, where: str) -> None:
        pad_room = 2 * 0.004 + 2 * FINGER_MARGIN
        _check(
            self.handle_clearance >= pad_room,
            f"{where}: handle_clearance {self.handle_clearance} m leaves no room for a finger; "
            f"use >= {pad_room}.",
        )
        _check(self.width >= 0.12, f"{where}: width must be >= 0.12 m, got {self.width}.")
        _check(self.height >= 0.06, f"{where}: height must be >= 0.06 m, got {self.height}.")
        _check(self.depth >= 0.12, f"{where}: depth must be >= 0.12 m, got {self.depth}.")
        low, high = self.handle_extent_z()
        front_low, front_high = self.elevation + 0.003, self.elevation + self.height - 0.003
        if self.handle in ("bar", "lip"):
            _check(
                0.08 <= self.handle_size <= self.width - 0.02,
                f"{where}: a {self.handle} handle needs handle_size in [0.08, width - 0.02], "
                f"got {self.handle_size}.",
            )
        if self.handle == "knob":
            _check(
                0.018 <= self.handle_size <= 0.04,
                f"{where}: a knob's cap radius (handle_size) must be in [0.018, 0.04] m, "
                f"got {self.handle_size}.",
            )
        if self.handle == "vbar":
            _check(
                self.handle_size >= 2 * VBAR_OVERHANG + 0.02,
                f"{where}: a vbar needs handle_size >= {2 * VBAR_OVERHANG + 0.02} m, got {self.handle_size}.",
            )
        if self.handle != "lip":
            _check(
                front_low <= low and high <= front_high,
                f"{where}: the handle spans z {low:.3f}..{high:.3f} m, outside the front "
                f"({front_low:.3f}..{front_high:.3f}); move handle_height towards 0 or shrink handle_size.",
            )

    def _check_on_table(self, where: str) -> None:
        corners = self.case_corners_xy()
        _check(
            bool(np.all(np.abs(corners[:, 0]) <= TABLE_X_LIMIT)),
            f"{where}: the case reaches x = {np.abs(corners[:, 0]).max():.3f} m, off the table "
            f"(|x| <= {TABLE_X_LIMIT}); move x towards 0 or narrow the case.",
        )
        _check(
            bool(np.all((corners[:, 1] >= TABLE_Y_RANGE[0]) & (corners[:, 1] <= TABLE_Y_RANGE[1]))),
            f"{where}: the case spans y {corners[:, 1].min():.3f}..{corners[:, 1].max():.3f} m, outside "
            f"{TABLE_Y_RANGE} (MetaWorld's back wall stands at 0.99); move y or make the case shallower.",
        )

    def case_corners_xy(
        self, x: float | None = None, y: float | None = None, yaw: float | None = None
    ) -> np.ndarray:
        """World (x, y) of the case footprint's corners, (4, 2), at the nominal or given pose (yaw: rad)."""
        half = self.width / 2
        local = np.array([[-half, 0.0], [half, 0.0], [-half, self.depth], [half, self.depth]])
        yaw = math.radians(self.yaw) if yaw is None else yaw
        rotation = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
        return local @ rotation.T + np.array([self.x if x is None else x, self.y if y is None else y])

    def handle_center_z(self) -> float:
        """Height of the handle centre above the case bottom (case frame, without elevation)."""
        if self.handle == "lip":
            return self.height + LIP_TAB_HEIGHT / 2 - 0.003
        return self.height / 2 + self.handle_height * (self.height / 2 - 0.003)

    def handle_extent_z(self) -> tuple[float, float]:
        """World z range of the handle at the nominal pose."""
        center = self.elevation + self.handle_center_z()
        half = {
            "bar": BAR_RADIUS,
            "knob": self.handle_size,
            "lip": LIP_TAB_HEIGHT / 2,
            "vbar": self.handle_size / 2 + BAR_RADIUS,
        }[self.handle]
        return center - half, center + half

    def handle_half_width(self) -> float:
        """Half the handle's extent across the pull axis (horizontal, in the drawer's front plane)."""
        return {
            "bar": self.handle_size / 2,
            "knob": self.handle_size,
            "lip": self.handle_size / 2,
            "vbar": BAR_RADIUS,
        }[self.handle]

    def free_gap_half_width(self) -> float:
        """Half-width across the pull axis of the finger gap behind the handle free of standoffs.

        A bar's standoffs cross it at the handle's height; other handles leave it free (``inf``).
        """
        if self.handle == "bar":
            return self.handle_size / 2 - BAR_POST_INSET - STANDOFF_RADIUS
        return math.inf

    def parameter_vector(self) -> np.ndarray:
        """Numeric description (handle one-hot, then every geometric and physical parameter)."""
        one_hot = [float(self.handle == h) for h in HANDLE_TYPES]
        numbers = [
            self.handle_size,
            self.handle_height,
            self.handle_clearance,
            self.width,
            self.height,
            self.depth,
            self.travel,
            self.damping,
            self.friction,
            self.x,
            self.y,
            self.yaw,
            self.elevation,
        ]
        return np.asarray(one_hot + numbers + list(self.front_rgba), dtype=np.float64)

    def handle_distance(self, other: DrawerVariant) -> float:
        """How unlike ``other``'s handle this drawer's is (what the ``nearest`` unseen-task rule ranks by).

        Infinite across handle types; else the relative difference of ``handle_size`` plus that of
        ``handle_height``.
        """
        if self.handle != other.handle:
            return math.inf
        size = abs(self.handle_size - other.handle_size) / max(self.handle_size, other.handle_size)
        return size + abs(self.handle_height - other.handle_height)


def nearest_variant(variant: DrawerVariant, candidates: Sequence[DrawerVariant]) -> DrawerVariant | None:
    """The candidate whose handle is most like ``variant``'s (first on a tie; None if none has its type)."""
    ranked = sorted(candidates, key=variant.handle_distance)  # stable: ties keep the given order
    if not ranked or math.isinf(variant.handle_distance(ranked[0])):
        return None
    return ranked[0]
