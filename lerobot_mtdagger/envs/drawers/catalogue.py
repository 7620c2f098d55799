"""The drawers of the suite: 11 training drawers and 4 held-out drawers, and their names.

Each row is one ``DrawerVariant``, its fields grouped: handle, case and drawer, pose on the table,
colours. Each held-out drawer differs from every training drawer in at least five parameters.
"""

from __future__ import annotations

from lerobot_mtdagger.envs.drawers.variants import DrawerVariant

TRAINING_DRAWERS: tuple[DrawerVariant, ...] = (
    DrawerVariant(
        name="drawer-bar-wide",
        handle="bar", handle_size=0.16, handle_height=0.0, handle_clearance=0.03,
        width=0.34, height=0.14, depth=0.2, travel=0.15, damping=2.0, friction=0.5,
        x=-0.05, y=0.78, yaw=0.0,
    ),
    DrawerVariant(
        name="drawer-bar-narrow",
        handle="bar", handle_size=0.09, handle_height=0.3, handle_clearance=0.025,
        width=0.18, height=0.12, depth=0.2, travel=0.12, damping=4.0, friction=1.0,
        x=0.12, y=0.765, yaw=8.0,
        case_rgba=(0.15, 0.2, 0.35, 1.0),
        front_rgba=(0.2, 0.3, 0.55, 1.0),
    ),
    DrawerVariant(
        name="drawer-bar-low",
        handle="bar", handle_size=0.12, handle_height=-0.5, handle_clearance=0.03,
        width=0.26, height=0.2, depth=0.2, travel=0.13, damping=3.0, friction=0.5,
        x=-0.14, y=0.77, yaw=-6.0,
        case_rgba=(0.6, 0.6, 0.58, 1.0),
        front_rgba=(0.85, 0.85, 0.8, 1.0),
        handle_rgba=(0.1, 0.1, 0.1, 1.0),
    ),
    DrawerVariant(
        name="drawer-knob-small",
        handle="knob", handle_size=0.022, handle_height=0.0, handle_clearance=0.028,
        width=0.2, height=0.11, depth=0.18, travel=0.1, damping=1.5, friction=0.3,
        x=0.0, y=0.8, yaw=0.0, elevation=0.04,
        front_rgba=(0.8, 0.3, 0.25, 1.0),
        handle_rgba=(0.9, 0.85, 0.6, 1.0),
    ),
    DrawerVariant(
        name="drawer-knob-large",
        handle="knob", handle_size=0.03, handle_height=0.3, handle_clearance=0.032,
        width=0.3, height=0.16, depth=0.2, travel=0.14, damping=5.0, friction=1.5,
        x=0.13, y=0.755, yaw=-10.0,
        case_rgba=(0.3, 0.35, 0.25, 1.0),
        front_rgba=(0.35, 0.5, 0.3, 1.0),
    ),
    DrawerVariant(
        name="drawer-knob-deep",
        handle="knob", handle_size=0.026, handle_height=-0.2, handle_clearance=0.03,
        width=0.24, height=0.13, depth=0.26, travel=0.2, damping=2.0, friction=0.5,
        x=-0.1, y=0.7, yaw=5.0,
        front_rgba=(0.9, 0.75, 0.35, 1.0),
        handle_rgba=(0.25, 0.2, 0.15, 1.0),
    ),
    DrawerVariant(
        name="drawer-lip-wide",
        handle="lip", handle_size=0.2, handle_height=0.0, handle_clearance=0.03,
        width=0.36, height=0.12, depth=0.2, travel=0.14, damping=2.0, friction=0.5,
        x=0.0, y=0.78, yaw=0.0,
        case_rgba=(0.8, 0.8, 0.8, 1.0),
        front_rgba=(0.95, 0.95, 0.95, 1.0),
        handle_rgba=(0.55, 0.55, 0.6, 1.0),
    ),
    DrawerVariant(
        name="drawer-lip-shallow",
        handle="lip", handle_size=0.1, handle_height=0.0, handle_clearance=0.03,
        width=0.22, height=0.08, depth=0.18, travel=0.1, damping=1.0, friction=0.2,
        x=0.12, y=0.78, yaw=7.0, elevation=0.06,
        case_rgba=(0.2, 0.2, 0.22, 1.0),
        front_rgba=(0.3, 0.3, 0.32, 1.0),
    ),
    DrawerVariant(
        name="drawer-vbar-tall",
        handle="vbar", handle_size=0.12, handle_height=0.0, handle_clearance=0.03,
        width=0.2, height=0.22, depth=0.2, travel=0.14, damping=3.0, friction=0.8,
        x=-0.12, y=0.78, yaw=0.0,
        front_rgba=(0.5, 0.25, 0.2, 1.0),
        handle_rgba=(0.85, 0.7, 0.3, 1.0),
    ),
    DrawerVariant(
        name="drawer-vbar-stiff",
        handle="vbar", handle_size=0.1, handle_height=0.15, handle_clearance=0.028,
        width=0.24, height=0.16, depth=0.2, travel=0.12, damping=12.0, friction=3.0,
        x=0.1, y=0.765, yaw=-5.0,
        case_rgba=(0.25, 0.27, 0.3, 1.0),
        front_rgba=(0.4, 0.45, 0.5, 1.0),
    ),
    DrawerVariant(
        name="drawer-kitchen",
        handle="bar", handle_size=0.128, handle_height=0.0, handle_clearance=0.032,
        width=0.4, height=0.15, depth=0.28, travel=0.2, damping=8.0, friction=2.0,
        x=0.0, y=0.7, yaw=0.0, elevation=0.1,
        case_rgba=(0.62, 0.48, 0.33, 1.0),
        front_rgba=(0.96, 0.96, 0.94, 1.0),
        handle_rgba=(0.6, 0.6, 0.62, 1.0),
    ),
)  # fmt: skip

HELDOUT_DRAWERS: tuple[DrawerVariant, ...] = (
    DrawerVariant(
        name="drawer-bar-angled",
        handle="bar", handle_size=0.1, handle_height=-0.2, handle_clearance=0.027,
        width=0.28, height=0.13, depth=0.2, travel=0.13, damping=6.0, friction=1.0,
        x=0.15, y=0.75, yaw=15.0, elevation=0.02,
        case_rgba=(0.35, 0.15, 0.3, 1.0),
        front_rgba=(0.6, 0.2, 0.45, 1.0),
    ),
    DrawerVariant(
        name="drawer-knob-tall",
        handle="knob", handle_size=0.024, handle_height=0.5, handle_clearance=0.03,
        width=0.22, height=0.2, depth=0.2, travel=0.12, damping=3.0, friction=1.0,
        x=-0.15, y=0.76, yaw=-12.0,
        front_rgba=(0.3, 0.6, 0.65, 1.0),
        handle_rgba=(0.2, 0.2, 0.2, 1.0),
    ),
    DrawerVariant(
        name="drawer-vbar-short",
        handle="vbar", handle_size=0.08, handle_height=0.0, handle_clearance=0.026,
        width=0.18, height=0.14, depth=0.18, travel=0.1, damping=2.0, friction=0.4,
        x=0.05, y=0.78, yaw=10.0, elevation=0.08,
        front_rgba=(0.9, 0.55, 0.2, 1.0),
    ),
    DrawerVariant(
        name="drawer-lip-heavy",
        handle="lip", handle_size=0.14, handle_height=0.0, handle_clearance=0.03,
        width=0.26, height=0.1, depth=0.22, travel=0.16, damping=10.0, friction=2.5,
        x=-0.1, y=0.74, yaw=-8.0, elevation=0.03,
        case_rgba=(0.3, 0.25, 0.4, 1.0),
        front_rgba=(0.45, 0.35, 0.6, 1.0),
    ),
)  # fmt: skip

DRAWER_TASKS: tuple[str, ...] = tuple(v.name for v in TRAINING_DRAWERS)
HELDOUT_TASKS: tuple[str, ...] = tuple(v.name for v in HELDOUT_DRAWERS)
VARIANTS: dict[str, DrawerVariant] = {v.name: v for v in TRAINING_DRAWERS + HELDOUT_DRAWERS}
