"""Offscreen MuJoCo observations: RGB frames and point clouds from depth cameras.

Observation cameras render without shadows, reflections, multisampling or shadow map (cheaper on a
CPU, ``docs/benchmarks.md``). A cloud is each camera's metric depth back-projected into the world
frame, cropped to the suite's ``CropBox`` and sampled to ``num_points`` with the env's generator.
"""

from __future__ import annotations

import atexit
import logging
import weakref

import mujoco
import numpy as np

from lerobot_mtdagger.envs.base import CropBox

logger = logging.getLogger(__name__)

# Renderers still open at interpreter exit are closed while the EGL display is still up; otherwise
# MuJoCo's own finalisers run after it is terminated and print EGL errors. MuJoCo registers the
# display's ``eglTerminate`` at exit when it creates the first context, so this handler is
# registered right after that (handlers run last-in, first-out).
_OPEN_RENDERERS: weakref.WeakSet[SceneRenderer] = weakref.WeakSet()
_EXIT_HANDLER_REGISTERED = False


def _close_open_renderers() -> None:
    for renderer in list(_OPEN_RENDERERS):
        renderer.close()


def _register_exit_handler() -> None:
    global _EXIT_HANDLER_REGISTERED
    if not _EXIT_HANDLER_REGISTERED:
        atexit.register(_close_open_renderers)
        _EXIT_HANDLER_REGISTERED = True


def renderer_without_shadow_map(model: mujoco.MjModel, height: int, width: int) -> mujoco.Renderer:
    """A ``mujoco.Renderer`` whose OpenGL context has no shadow map (only for ``SceneRenderer``).

    ``model.vis.quality.shadowsize`` is 0 only while the context is made, so the shared model keeps it.
    """
    shadow_size = model.vis.quality.shadowsize
    model.vis.quality.shadowsize = 0
    try:
        return mujoco.Renderer(model, height, width)
    finally:
        model.vis.quality.shadowsize = shadow_size


class SceneRenderer:
    """RGB and depth rendering of one MuJoCo model with shadows and reflections off.

    Its OpenGL context is made on first use, so an env can be built in one process and stepped in another.
    """

    def __init__(self, model: mujoco.MjModel, height: int, width: int, multisamples: int = 0) -> None:
        """Prepares a ``height`` x ``width`` renderer (``ValueError`` beyond the model's offscreen buffer)."""
        if height <= 0 or width <= 0:
            raise ValueError(f"Render size must be positive, got {height}x{width}.")
        offwidth, offheight = model.vis.global_.offwidth, model.vis.global_.offheight
        if width > offwidth or height > offheight:
            raise ValueError(
                f"Render size {height}x{width} exceeds the model's offscreen buffer {offheight}x{offwidth}; "
                "choose a smaller image_size."
            )
        if multisamples < 0:
            raise ValueError(f"multisamples must be >= 0, got {multisamples}.")
        model.vis.quality.offsamples = multisamples
        self.model = model
        self.height, self.width = height, width
        self._renderer: mujoco.Renderer | None = None

    def _get(self) -> mujoco.Renderer:
        if self._renderer is None:
            self._renderer = renderer_without_shadow_map(self.model, self.height, self.width)
            _register_exit_handler()
            _OPEN_RENDERERS.add(self)
        return self._renderer

    def _update(self, data: mujoco.MjData, camera: str) -> mujoco.Renderer:
        renderer = self._get()
        renderer.update_scene(data, camera=camera)
        renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = 0
        renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
        return renderer

    def rgb(self, data: mujoco.MjData, camera: str) -> np.ndarray:
        """Renders an RGB frame, (H, W, 3) uint8."""
        return self._update(data, camera).render().copy()

    def depth(self, data: mujoco.MjData, camera: str) -> np.ndarray:
        """Renders metric depth along the optical axis, (H, W) float32 metres."""
        renderer = self._get()
        renderer.enable_depth_rendering()
        try:
            return self._update(data, camera).render().copy()
        finally:
            renderer.disable_depth_rendering()

    def close(self) -> None:
        """Frees the OpenGL context (safe to call twice)."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        _OPEN_RENDERERS.discard(self)


MIN_FACES_TO_SIMPLIFY = 1000
"""Meshes with fewer faces are rendered as they are (the drawers' and the objects' meshes)."""


def simplified_model(model: mujoco.MjModel, detail: float) -> mujoco.MjModel:
    """A copy of ``model`` for rendering only, its large untextured meshes simplified.

    Each mesh of at least ``MIN_FACES_TO_SIMPLIFY`` faces without texture coordinates (the Sawyer arm's)
    keeps about ``detail`` of its faces (quadric decimation); geoms, bodies and cameras are untouched, so
    the copy renders the physics model's ``MjData``. ``detail=1`` returns ``model`` itself.

    Raises:
        ValueError: If ``detail`` is outside (0, 1].
    """
    if not 0.0 < detail <= 1.0:
        raise ValueError(f"detail must be in (0, 1], got {detail}.")
    if detail == 1.0:
        return model
    import fast_simplification

    copy = mujoco.MjModel.__copy__(model)
    for mesh in range(copy.nmesh):
        if copy.mesh_facenum[mesh] < MIN_FACES_TO_SIMPLIFY or copy.mesh_texcoordadr[mesh] >= 0:
            continue
        vert, face = copy.mesh_vertadr[mesh], copy.mesh_faceadr[mesh]
        vertices = copy.mesh_vert[vert : vert + copy.mesh_vertnum[mesh]]
        faces = copy.mesh_face[face : face + copy.mesh_facenum[mesh]]
        kept_vertices, kept_faces = fast_simplification.simplify(
            vertices.astype(np.float32), faces.astype(np.int64), target_reduction=1.0 - detail
        )
        if len(kept_vertices) <= copy.mesh_normalnum[mesh]:  # the normals fit the mesh's slots
            _write_mesh(copy, mesh, kept_vertices, kept_faces.astype(np.int32))
    return copy


def _write_mesh(model: mujoco.MjModel, mesh: int, vertices: np.ndarray, faces: np.ndarray) -> None:
    """Puts a smaller mesh into the slots of ``mesh`` (its normals one per vertex, area-weighted)."""
    vert, face, normal = model.mesh_vertadr[mesh], model.mesh_faceadr[mesh], model.mesh_normaladr[mesh]
    model.mesh_vert[vert : vert + len(vertices)] = vertices
    model.mesh_vertnum[mesh] = len(vertices)
    model.mesh_face[face : face + len(faces)] = faces
    model.mesh_facenum[mesh] = len(faces)
    corners = vertices[faces]  # (F, 3, 3)
    face_normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals = np.zeros_like(vertices, dtype=np.float64)
    for corner in range(3):
        np.add.at(normals, faces[:, corner], face_normals)
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    model.mesh_normal[normal : normal + len(vertices)] = normals
    model.mesh_normalnum[mesh] = len(vertices)
    model.mesh_facenormal[face : face + len(faces)] = faces


def camera_rays(model: mujoco.MjModel, camera: str, height: int, width: int) -> np.ndarray:
    """Per-pixel ray directions in the camera frame, (H, W, 3) float64: a depth d gives the point ``d * ray``.

    ``ray = ((u + 0.5 - W/2) / f, -(v + 0.5 - H/2) / f, -1)``, ``f = (H / 2) / tan(fovy / 2)``; row 0 is
    the top of the image.

    Raises:
        ValueError: If the model has no camera of that name.
    """
    camera_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
    if camera_id < 0:
        names = [model.camera(i).name for i in range(model.ncam)]
        raise ValueError(f"Unknown camera {camera!r}; the model has cameras {names}.")
    fovy = np.deg2rad(model.cam_fovy[camera_id])
    focal = (height / 2.0) / np.tan(fovy / 2.0)
    u = (np.arange(width) + 0.5 - width / 2.0) / focal
    v = -(np.arange(height) + 0.5 - height / 2.0) / focal
    rays = np.empty((height, width, 3))
    rays[..., 0] = u[None, :]
    rays[..., 1] = v[:, None]
    rays[..., 2] = -1.0
    return rays


def depth_to_world(
    depth: np.ndarray, rays: np.ndarray, position: np.ndarray, rotation: np.ndarray
) -> np.ndarray:
    """Back-projects a (H, W) depth image to world coordinates, (3, H, W): one plane per axis.

    The point of pixel (v, u) is ``rotation @ (depth[v, u] * rays[v, u]) + position``, computed per
    axis from the separable rays (about 5x faster than an (H * W, 3) x (3, 3) product).
    """
    across, down = rays[0, :, 0], rays[:, 0, 1]
    planes = np.empty((3, *depth.shape))
    for axis in range(3):
        direction = (
            rotation[axis, 0] * across[None, :] + (rotation[axis, 1] * down - rotation[axis, 2])[:, None]
        )
        np.multiply(depth, direction, out=planes[axis])
        planes[axis] += position[axis]
    return planes


def sample_points(
    points: np.ndarray, num_points: int, rng: np.random.Generator, fallback: np.ndarray
) -> np.ndarray:
    """Samples exactly ``num_points`` rows of ``points`` (M, C), with replacement only when M is smaller.

    With no point left, returns ``num_points`` copies of ``fallback`` (C,) and logs a warning.
    """
    count = points.shape[0]
    if count == 0:
        logger.warning("No point inside the crop box: returning %d copies of the box centre.", num_points)
        return np.repeat(fallback[None, :].astype(points.dtype), num_points, axis=0)
    index = rng.choice(count, size=num_points, replace=count < num_points)
    return points[index]


class PointCloudCamera:
    """Turns depth renders of several cameras into one cropped, sampled world-frame point cloud."""

    def __init__(
        self,
        renderer: SceneRenderer,
        cameras: tuple[str, ...],
        crop: CropBox,
        num_points: int,
        with_color: bool = False,
    ) -> None:
        """Precomputes each camera's rays (``ValueError``: an unknown camera, none, ``num_points <= 0``)."""
        if num_points <= 0:
            raise ValueError(f"num_points must be > 0, got {num_points}.")
        if not cameras:
            raise ValueError("A point cloud needs at least one camera.")
        self.renderer = renderer
        self.cameras = tuple(cameras)
        self.crop = crop
        self.num_points = num_points
        self.with_color = with_color
        model = renderer.model
        self._rays = [camera_rays(model, c, renderer.height, renderer.width) for c in self.cameras]
        self._ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, c) for c in self.cameras]

    @property
    def channels(self) -> int:
        """3 (xyz) or 6 (xyz + rgb)."""
        return 6 if self.with_color else 3

    def capture(self, data: mujoco.MjData, rng: np.random.Generator) -> np.ndarray:
        """Renders, back-projects, crops and samples: (num_points, 3) float32 xyz, or 6 with rgb in [0, 1]."""
        depths = {camera: self.renderer.depth(data, camera) for camera in self.cameras}
        colors = (
            {camera: self.renderer.rgb(data, camera) for camera in self.cameras} if self.with_color else None
        )
        return self.cloud_from_renders(data, depths, rng, colors)

    def cloud_from_renders(
        self,
        data: mujoco.MjData,
        depths: dict[str, np.ndarray],
        rng: np.random.Generator,
        colors: dict[str, np.ndarray] | None = None,
    ) -> np.ndarray:
        """``capture`` after its renders (each camera's depth, and colour when the cloud has it)."""
        parts = []
        for camera, camera_id, rays in zip(self.cameras, self._ids, self._rays, strict=True):
            rotation = data.cam_xmat[camera_id].reshape(3, 3)
            planes = depth_to_world(depths[camera], rays, data.cam_xpos[camera_id], rotation)
            keep = self.crop.contains_planes(planes)
            points = planes[:, keep].T
            if colors is not None:
                points = np.concatenate([points, colors[camera][keep] / 255.0], axis=1)
            parts.append(points)
        cloud = np.concatenate(parts, axis=0)
        fallback = np.concatenate([self.crop.center, np.zeros(self.channels - 3)])
        return sample_points(cloud, self.num_points, rng, fallback).astype(np.float32)
