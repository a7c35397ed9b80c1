"""``BodyScene``: the posed body, a floor and lights, rendered headless with pyrender.

The body is the same :class:`~avatar_models.body.BodyDescription` as the physics humanoid: each
segment (capsule, box, sphere) is tessellated once in its body frame, and the segments are
merged into ONE mesh (per-vertex colours, and per-vertex part labels in ``texcoord_1``) that
is posed by transforming its vertices: pyrender spends ~0.2 ms of Python per drawn primitive,
so one draw call instead of ~25 per view.

Passes (one GL context per scene, single-sampled unless ``antialias=True``; what this takes
from pyrender's private API is isolated in :mod:`render_cams.pyrender_patch`):

- :meth:`BodyScene.render`: colour and depth, with a diffuse-only shader
  (``shaders/matte.frag``; ``shading="pbr"`` keeps pyrender's physically based one);
- :meth:`BodyScene.render_depth_and_parts`: depth and part labels from ONE flat segmentation
  pass (``shaders/labels.*``) that draws every mesh, so labels and depth agree at every pixel.

Single sampling puts every sample at the pixel centre. pyrender's default 4x multisampling
resolves depth by taking one sample, about 0.37 px off the centre, and blends label colours
at silhouettes. The headless OpenGL backend (EGL, OSMesa as fallback) is chosen in
:mod:`avatar_models` before pyrender is imported.

Camera convention (OpenCV): x right, y down, z forward (the optical axis). A camera is given by
its pose ``camera_to_world`` (4x4, camera axes as columns of the rotation, its centre as the
translation); ``world_to_camera = inv(camera_to_world)`` maps a world point to camera
coordinates, ``X_cam = R.T @ (X_world - t)``. Pixel ``(u, v)`` has its centre at integer
coordinates, as in OpenCV (``u = fx * x / z + cx``). Depth is the camera-frame ``z`` in metres,
0 where nothing was hit.

Part labels: 0 is background (floor, room, nothing), ``k + 1`` is body segment ``k``
(:attr:`BodyScene.part_names`), so ``parts > 0`` is a body-index map.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pyrender
import trimesh

import avatarsim.avatar_models  # noqa: F401  (picks the OpenGL backend before pyrender loads)
from avatarsim.avatar_models import AvatarsimError, Motion, quat
from avatarsim.avatar_models.body import BodyDescription, build_body
from avatarsim.avatar_models.body.mesh import mesh_template
from avatarsim.avatar_models.skeleton import Skeleton
from avatarsim.render_cams.pyrender_patch import close_renderer, open_renderer

# OpenCV camera axes (x right, y down, z forward) -> pyrender/OpenGL (x right, y up, z back).
CV_TO_GL = np.diag([1.0, -1.0, -1.0, 1.0])
Z_NEAR_M = 0.01  # a controller camera can be a few cm from the hand holding it
Z_FAR_M = 50.0
SHADERS = Path(__file__).with_name("shaders")
MATTE_SHADER = SHADERS / "matte.frag"
LABELS_VERT, LABELS_FRAG = SHADERS / "labels.vert", SHADERS / "labels.frag"
WHITE = np.array([255, 255, 255])  # segmentation colour: labels.frag outputs labels as they are
SHADINGS = ("matte", "pbr")


class SceneError(AvatarsimError, ValueError):
    """A scene or camera configured with impossible values (bad intrinsics, image size...)."""


REGION_OF_KIND = {
    "head": "skin",
    "hand": "skin",
    "forearm": "skin",
    "torso": "shirt",
    "upper_arm": "shirt",
    "pelvis": "trousers",
    "thigh": "trousers",
    "shank": "trousers",
    "foot": "shoes",
}


@dataclass(frozen=True)
class Clothing:
    """RGB colours (0-255) per body region; segment kinds map to regions by ``REGION_OF_KIND``."""

    skin: tuple[int, int, int] = (224, 172, 140)
    shirt: tuple[int, int, int] = (52, 101, 164)
    trousers: tuple[int, int, int] = (60, 60, 70)
    shoes: tuple[int, int, int] = (30, 30, 30)

    def colour_of(self, kind: str) -> np.ndarray:
        """``(3,)`` float RGB in [0, 1] of a segment kind (skin for unknown kinds)."""
        return np.asarray(getattr(self, REGION_OF_KIND.get(kind, "skin")), float) / 255.0


@dataclass(frozen=True)
class Room:
    """Optional surroundings: a textured cylindrical wall around the origin.

    Attributes:
        texture: ``(h, w, 3)`` uint8 image wrapped once around the wall.
        radius_m, height_m: wall size.
    """

    texture: np.ndarray
    radius_m: float = 4.0
    height_m: float = 3.0
    sections: int = field(default=64)

    def mesh(self) -> trimesh.Trimesh:
        """The wall as a textured open cylinder, faces pointing inwards."""
        angles = np.linspace(0.0, 2.0 * np.pi, self.sections + 1)
        ring = np.stack([np.cos(angles), np.sin(angles)], axis=1) * self.radius_m
        vertices = np.concatenate(
            [np.c_[ring, np.zeros(len(ring))], np.c_[ring, np.full(len(ring), self.height_m)]]
        )
        n = len(ring)
        i = np.arange(self.sections)
        # Counter-clockwise seen from inside (the camera is always inside the room).
        faces = np.concatenate(
            [np.stack([i, i + n, i + 1], 1), np.stack([i + 1, i + n, i + n + 1], 1)]
        )
        u = np.concatenate([angles, angles]) / (2.0 * np.pi)
        v = np.concatenate([np.zeros(n), np.ones(n)])
        visual = trimesh.visual.TextureVisuals(
            uv=np.stack([u, v], 1),
            material=trimesh.visual.material.SimpleMaterial(
                image=_as_pil(self.texture), diffuse=[255, 255, 255, 255]
            ),
        )
        return trimesh.Trimesh(vertices=vertices, faces=faces, visual=visual, process=False)


def _as_pil(image: np.ndarray):
    from PIL import Image

    array = np.asarray(image)
    if array.ndim != 3 or array.shape[2] != 3 or array.dtype != np.uint8:
        raise SceneError(f"room texture must be (h, w, 3) uint8, got {array.shape} {array.dtype}")
    return Image.fromarray(array)


def check_intrinsics(K: np.ndarray, width: int, height: int) -> tuple[np.ndarray, int, int]:
    """``K`` as a float ``(3, 3)`` pinhole matrix and the image size as ints.

    Raises :class:`SceneError` for non-positive focal lengths or sizes, skew, or NaN.
    """
    K = np.asarray(K, dtype=float)
    if K.shape != (3, 3) or not np.all(np.isfinite(K)):
        raise SceneError(f"K must be a finite 3x3 matrix, got shape {K.shape}")
    if not (K[0, 0] > 0 and K[1, 1] > 0):
        raise SceneError(f"focal lengths must be positive, got fx={K[0, 0]}, fy={K[1, 1]}")
    if K[0, 1] != 0 or not np.allclose(K[2], [0.0, 0.0, 1.0]):
        raise SceneError("K must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (no skew)")
    if int(width) < 1 or int(height) < 1:
        raise SceneError(f"image size must be positive, got {width}x{height}")
    return K, int(width), int(height)


def pinhole_K(fov_x_rad: float, width: int, height: int) -> np.ndarray:
    """``(3, 3)`` K of a square-pixel pinhole with horizontal field of view ``fov_x_rad``,
    principal point at the image centre ``((w - 1) / 2, (h - 1) / 2)``."""
    f = 0.5 * width / np.tan(0.5 * fov_x_rad)
    return np.array([[f, 0.0, 0.5 * (width - 1)], [0.0, f, 0.5 * (height - 1)], [0, 0, 1.0]])


def body_for_motion(motion: Motion, body: BodyDescription | None = None) -> BodyDescription:
    """The body to pose with ``motion``: ``body`` itself when given (the humanoid the caller
    built once for this motion; ``motion`` must be on its skeleton), else one built from the
    motion's skeleton (which must then be an upright humanoid rig).

    Raises:
        SceneError: ``motion`` is not on ``body``'s skeleton.
        BodyError: no body can be built from the motion's skeleton.
    """
    if body is None:
        return build_body(motion.skeleton)
    if not isinstance(body, BodyDescription):
        raise SceneError(f"body must be a BodyDescription, got {type(body).__name__}")
    if not motion.skeleton.same_topology(body.skeleton):
        raise SceneError(
            f"the motion is on skeleton {motion.skeleton.name!r} ({motion.skeleton.n_joints} "
            f"joints), not on the body's {body.skeleton.name!r} "
            f"({body.skeleton.n_joints} joints); retarget it onto the body first"
        )
    return body


class BodyScene:
    """The posed body (and floor, lights, optional room) ready to render from any camera.

    Args:
        body: a :class:`BodyDescription` (the humanoid built once for the motion, see
            :func:`body_for_motion`), or a skeleton to build one from.
        clothing: colours per body region.
        floor: add a 20 m square floor at z = 0.
        room: optional textured wall around the user.
        background: RGB 0-255 of empty pixels.
        shading: ``"matte"`` (diffuse only, ~2x faster in software rendering) or ``"pbr"``
            (pyrender's physically based shader, with a weak specular highlight).
        antialias: 4x multisampled colour (smoother edges; depth then comes from one sample,
            ~0.37 px off the pixel centre). Off: exact pixel-centre sampling, faster.
    """

    def __init__(
        self,
        body: BodyDescription | Skeleton,
        clothing: Clothing | None = None,
        floor: bool = True,
        room: Room | None = None,
        background: tuple[int, int, int] = (150, 160, 175),
        shading: str = "matte",
        antialias: bool = False,
    ):
        if shading not in SHADINGS:
            raise SceneError(f"shading must be one of {SHADINGS}, got {shading!r}")
        self.shading = shading
        self.antialias = antialias
        self.body = body if isinstance(body, BodyDescription) else build_body(body)
        self.clothing = clothing or Clothing()
        self.scene = pyrender.Scene(
            bg_color=np.r_[np.asarray(background, float) / 255.0, 1.0], ambient_light=[0.35] * 3
        )
        segments = self.body.segments
        self.part_names: tuple[str, ...] = tuple(s.name for s in segments)
        self.part_bodies = np.array([s.body for s in segments])
        self._init_merged_body([self._segment_mesh(s) for s in segments])
        if floor:
            self._add_floor()
        if room is not None:
            self.scene.add(pyrender.Mesh.from_trimesh(room.mesh(), smooth=False))
        for direction in ([-0.4, 0.3, -1.0], [0.6, -0.5, -0.6]):
            self.scene.add(pyrender.DirectionalLight(intensity=2.5), pose=_light_pose(direction))
        self._camera = pyrender.IntrinsicsCamera(1, 1, 0, 0, znear=Z_NEAR_M, zfar=Z_FAR_M)
        self._camera_node = self.scene.add(self._camera, pose=np.eye(4))
        self._renderer: pyrender.OffscreenRenderer | None = None

    # -- content ------------------------------------------------------------------------
    @staticmethod
    def _segment_mesh(segment) -> trimesh.Trimesh:
        template = mesh_template((segment,))
        return trimesh.Trimesh(template.vertices, template.faces, process=False)

    def _init_merged_body(self, pieces: list[trimesh.Trimesh]) -> None:
        """The merged body: segment meshes (body frames) concatenated, coloured and labelled
        per vertex."""
        sizes = [len(p.vertices) for p in pieces]
        merged = trimesh.util.concatenate(pieces)
        self._merged_vertices = np.asarray(merged.vertices)  # (V, 3) body frames
        self._merged_normals = np.asarray(merged.vertex_normals)  # (V, 3)
        self._merged_faces = np.asarray(merged.faces)  # (F, 3)
        self._merged_vertex_body = np.repeat(self.part_bodies, sizes)  # (V,)
        colours = np.stack([self.clothing.colour_of(s.kind) for s in self.body.segments])
        self._merged_colours = np.c_[np.repeat(colours, sizes, axis=0), np.ones(sum(sizes))]
        labels = np.repeat(np.arange(1, len(pieces) + 1), sizes)
        self._merged_labels = np.c_[labels, np.zeros(len(labels))]  # (V, 2) texcoord_1
        self._merged_material = pyrender.MetallicRoughnessMaterial(
            baseColorFactor=[1.0, 1.0, 1.0, 1.0], metallicFactor=0.0, roughnessFactor=0.8
        )
        self._merged_node: pyrender.Node | None = None
        # The pose last set: global joint positions (J, 3) and rotations (J, 3, 3).
        self.pose: tuple[np.ndarray, np.ndarray] | None = None

    def _add_floor(self) -> None:
        half = 10.0
        corners = np.array([[-half, -half, 0], [half, -half, 0], [half, half, 0], [-half, half, 0]])
        floor = trimesh.Trimesh(corners, np.array([[0, 1, 2], [0, 2, 3]]), process=False)
        material = pyrender.MetallicRoughnessMaterial(
            baseColorFactor=[0.55, 0.52, 0.48, 1.0], metallicFactor=0.0, roughnessFactor=1.0
        )
        self.scene.add(pyrender.Mesh.from_trimesh(floor, material=material, smooth=False))

    # -- pose ---------------------------------------------------------------------------
    def set_pose(self, positions: np.ndarray, rotations: np.ndarray) -> None:
        """Pose the body by global joint positions ``(J, 3)`` and rotations ``(J, 3, 3)`` or
        ``(J, 4)`` wxyz of the body's skeleton."""
        positions = np.asarray(positions, float)
        rotations = np.asarray(rotations, float)
        if rotations.ndim == 2 and rotations.shape[-1] == 4:
            rotations = quat.to_matrix(rotations)
        n = self.body.skeleton.n_joints
        if positions.shape != (n, 3) or rotations.shape != (n, 3, 3):
            raise SceneError(
                f"pose must be ({n}, 3) positions and ({n}, 3, 3) rotations, "
                f"got {positions.shape} and {rotations.shape}"
            )
        body = self._merged_vertex_body
        # v_world = R_body v + p_body, n_world = R_body n, for all vertices at once.
        vertices = np.einsum("vij,vj->vi", rotations[body], self._merged_vertices)
        normals = np.einsum("vij,vj->vi", rotations[body], self._merged_normals)
        primitive = pyrender.Primitive(
            positions=vertices + positions[body],
            normals=normals,
            color_0=self._merged_colours,
            texcoord_1=self._merged_labels,
            indices=self._merged_faces,
            material=self._merged_material,
        )
        # A new Mesh each pose: pyrender uploads vertices when a mesh enters the scene.
        if self._merged_node is not None:
            self.scene.remove_node(self._merged_node)
        self._merged_node = self.scene.add(pyrender.Mesh([primitive]))
        self.pose = (positions, rotations)

    def update(self, motion: Motion, frame: int) -> None:
        """Pose the body as frame ``frame`` of ``motion`` (on the body's skeleton)."""
        if not 0 <= frame < motion.n_frames:
            raise SceneError(f"frame {frame} outside the motion's {motion.n_frames} frames")
        positions, rotations = motion[[frame]].fk()
        self.set_pose(positions[0], rotations[0])

    # -- rendering ----------------------------------------------------------------------
    def _shader_swaps(self) -> dict[str, Path]:
        """pyrender shader file -> ours: the label pass always, the matte colour shader when
        asked."""
        swaps = {"segmentation.vert": LABELS_VERT, "segmentation.frag": LABELS_FRAG}
        if self.shading == "matte":
            swaps["mesh.frag"] = MATTE_SHADER
        return swaps

    def _prepare(
        self, camera_to_world: np.ndarray, K: np.ndarray, width: int, height: int
    ) -> pyrender.OffscreenRenderer:
        """This scene's renderer, sized, with the camera placed (checks every argument)."""
        K, width, height = check_intrinsics(K, width, height)
        pose = np.asarray(camera_to_world, float)
        if pose.shape != (4, 4) or not np.all(np.isfinite(pose)):
            raise SceneError(f"camera pose must be a finite 4x4 matrix, got {pose.shape}")
        if self._merged_node is None:
            raise SceneError("pose the body (update or set_pose) before rendering it")
        self._camera.fx, self._camera.fy = K[0, 0], K[1, 1]
        # pyrender puts pixel centres at half-integers; OpenCV at integers.
        self._camera.cx, self._camera.cy = K[0, 2] + 0.5, K[1, 2] + 0.5
        self.scene.set_pose(self._camera_node, pose @ CV_TO_GL)
        # One renderer (one GL context) per scene: pyrender binds meshes to a single context.
        # A new size only resizes its framebuffer.
        if self._renderer is None:
            self._renderer = open_renderer(width, height, self._shader_swaps(), self.antialias)
        self._renderer.viewport_width, self._renderer.viewport_height = width, height
        return self._renderer

    def render(
        self, camera_to_world: np.ndarray, K: np.ndarray, width: int, height: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """Colour ``(H, W, 3)`` uint8 and depth ``(H, W)`` float32 metres (camera z; 0 = no hit)
        of a pinhole camera with intrinsics ``K`` at pose ``camera_to_world`` (OpenCV axes)."""
        return self._prepare(camera_to_world, K, width, height).render(self.scene)

    def render_depth_and_parts(
        self, camera_to_world: np.ndarray, K: np.ndarray, width: int, height: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """Depth ``(H, W)`` float32 metres (camera z; 0 = no hit) and part labels ``(H, W)``
        int32 (0 background, ``k + 1`` segment ``k``) from one pass: they agree at every
        pixel, silhouettes included."""
        renderer = self._prepare(camera_to_world, K, width, height)
        # pyrender's SEG pass draws only the nodes in the map: all of them, so that depth
        # covers the whole scene; meshes without per-vertex labels come out as 0.
        every_mesh = dict.fromkeys(self.scene.mesh_nodes, WHITE)
        seg, depth = renderer.render(self.scene, pyrender.RenderFlags.SEG, every_mesh)
        labels = seg[..., 0].astype(np.int32)
        labels += seg[..., 1].astype(np.int32) << 8
        return depth, labels

    def render_parts(
        self, camera_to_world: np.ndarray, K: np.ndarray, width: int, height: int
    ) -> np.ndarray:
        """``(H, W)`` int32 body-part labels (0 background, ``k + 1`` segment ``k``)."""
        return self.render_depth_and_parts(camera_to_world, K, width, height)[1]

    def close(self) -> None:
        """Release this scene's OpenGL context (other scenes keep theirs)."""
        if self._renderer is not None:
            close_renderer(self._renderer)
            self._renderer = None

    def __enter__(self) -> BodyScene:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _light_pose(direction) -> np.ndarray:
    """Pose of a directional light shining along ``direction`` (pyrender lights look down -z)."""
    d = np.asarray(direction, float)
    z = -d / np.linalg.norm(d)
    x = np.cross([0.0, 0.0, 1.0], z)
    x = x / np.linalg.norm(x) if np.linalg.norm(x) > 1e-9 else np.array([1.0, 0.0, 0.0])
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, np.cross(z, x), z], axis=1)
    return pose
