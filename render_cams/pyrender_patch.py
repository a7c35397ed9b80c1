"""The one place avatarsim reaches into pyrender's private API, and why (pyrender 0.1.45).

:class:`~render_cams.scene.BodyScene` needs three things that pyrender's public API does not
offer:

1. Single-sampled framebuffers. pyrender always renders into a 4x multisampled framebuffer;
   resolving its depth takes one sample about 0.37 px off the pixel centre, and label colours
   blend at silhouettes. :class:`BodyRenderer` gives the multisampled renderbuffers one sample
   (override of ``Renderer._configure_main_framebuffer``) and reads them directly, with depth
   linearised in one vectorised pass (override of ``Renderer._read_main_framebuffer``, whose
   boolean indexing cost about as much as drawing a Kinect frame).
2. Its own shaders (the matte colour shader, the label pass): swapped in through
   ``Renderer._program_cache``, installed into ``OffscreenRenderer._renderer``.
3. Closing one scene's EGL context only. With EGL every context lives on one shared display,
   and ``OffscreenRenderer.delete`` terminates it (``eglTerminate``), killing other scenes'
   contexts (``EGL_BAD_DISPLAY``) and MuJoCo's, whose EGL module initialises the display once
   at import (``EGL_NOT_INITIALIZED`` in the pictures rendered after the cameras).
   :func:`close_renderer` destroys its own context and leaves the display initialised.

:func:`missing_private_names` lists what of this the installed pyrender lacks;
:func:`open_renderer` raises :class:`PyrenderPatchError` naming it and the pyrender version,
and ``tests/render_cams/test_pyrender_patch.py`` fails on it, so that a pyrender upgrade
breaks loudly instead of rendering wrong pixels.
"""

from __future__ import annotations

import inspect
from collections.abc import Mapping
from functools import cache
from pathlib import Path

import numpy as np
import pyrender
from OpenGL import GL
from pyrender.shader_program import ShaderProgramCache

import avatarsim.avatar_models  # noqa: F401  (picks the OpenGL backend before pyrender loads)
from avatarsim.avatar_models import AvatarsimError

# Private names this module relies on, per pyrender class: methods it overrides (with their
# parameters) and attributes it reads or replaces.
OVERRIDDEN = {
    "_configure_main_framebuffer": ("self",),
    "_read_main_framebuffer": ("self", "scene", "flags"),
}
RENDERER_ATTRIBUTES = (
    "_main_fb",
    "_main_fb_dims",
    "_main_fb_ms",
    "_main_cb_ms",
    "_main_db_ms",
    "_program_cache",
)  # of a pyrender.Renderer, set in its constructor (which makes no GL calls)
OFFSCREEN_ATTRIBUTES = ("_renderer", "_platform")  # of a pyrender.OffscreenRenderer
EGL_ATTRIBUTES = ("_egl_display", "_egl_context")  # of pyrender.platforms.egl.EGLPlatform


class PyrenderPatchError(AvatarsimError, RuntimeError):
    """The installed pyrender lacks a private name this module relies on."""


def pyrender_version() -> str:
    from pyrender.version import __version__

    return __version__


def _assigned_in(cls: type, attribute: str) -> bool:
    """Whether ``cls``'s source assigns ``self.<attribute>`` (for classes whose objects need a
    GL context to be made)."""
    return f"self.{attribute} =" in inspect.getsource(cls)


@cache
def missing_private_names() -> tuple[str, ...]:
    """``("Class.name (why)", ...)``: the private pyrender names used here that the installed
    version lacks or has changed; empty when the patch fits."""
    missing = []
    for name, params in OVERRIDDEN.items():
        method = getattr(pyrender.Renderer, name, None)
        if method is None:
            missing.append(f"Renderer.{name} (method gone)")
        elif tuple(inspect.signature(method).parameters) != params:
            missing.append(f"Renderer.{name} (parameters changed, expected {params})")
    renderer = vars(pyrender.Renderer(1, 1))
    missing += [f"Renderer.{n} (attribute gone)" for n in RENDERER_ATTRIBUTES if n not in renderer]
    offscreen = pyrender.OffscreenRenderer
    missing += [
        f"OffscreenRenderer.{n} (attribute gone)"
        for n in OFFSCREEN_ATTRIBUTES
        if not _assigned_in(offscreen, n)
    ]
    from pyrender.platforms.egl import EGLPlatform

    missing += [
        f"EGLPlatform.{n} (attribute gone)"
        for n in EGL_ATTRIBUTES
        if not _assigned_in(EGLPlatform, n)
    ]
    return tuple(missing)


def check_pyrender() -> None:
    """Raise :class:`PyrenderPatchError` unless every private name used here exists."""
    missing = missing_private_names()
    if missing:
        raise PyrenderPatchError(
            f"pyrender {pyrender_version()} no longer has what render_cams/pyrender_patch.py "
            f"relies on: {'; '.join(missing)}. Adapt the patch to this version or pin pyrender "
            "0.1.45."
        )


class BodyProgramCache(ShaderProgramCache):
    """pyrender's shader cache with some shader files replaced.

    Args:
        swaps: pyrender shader file name (e.g. ``"mesh.frag"``) -> absolute path of ours.
    """

    def __init__(self, swaps: Mapping[str, Path]):
        super().__init__()
        self.swaps = dict(swaps)

    def get_program(self, vertex_shader, fragment_shader, geometry_shader=None, defines=None):
        # Absolute paths: pyrender's os.path.join keeps them as they are.
        vertex_shader = str(self.swaps.get(vertex_shader, vertex_shader))
        fragment_shader = str(self.swaps.get(fragment_shader, fragment_shader))
        return super().get_program(vertex_shader, fragment_shader, geometry_shader, defines)


class BodyRenderer(pyrender.Renderer):
    """pyrender's renderer with swapped shaders, single-sampled unless ``antialias``."""

    def __init__(self, width: int, height: int, swaps: Mapping[str, Path], antialias: bool):
        super().__init__(width, height)
        self._program_cache = BodyProgramCache(swaps)
        self.antialias = antialias

    def _configure_main_framebuffer(self):
        size = (self.viewport_width, self.viewport_height)
        fresh = self._main_fb is None or self._main_fb_dims != size
        super()._configure_main_framebuffer()
        if fresh and not self.antialias:
            layouts = ((self._main_cb_ms, GL.GL_RGBA), (self._main_db_ms, GL.GL_DEPTH_COMPONENT24))
            for buffer, layout in layouts:
                GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, buffer)
                GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, layout, *size)

    def _read_main_framebuffer(self, scene, flags):
        """Colour ``(H, W, 3)`` uint8 and depth ``(H, W)`` float32 camera z (0: no hit), read
        from the single-sampled framebuffer directly (no blit)."""
        if self.antialias:
            return super()._read_main_framebuffer(scene, flags)
        width, height = self._main_fb_dims
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, self._main_fb_ms)
        buffer = GL.glReadPixels(0, 0, width, height, GL.GL_DEPTH_COMPONENT, GL.GL_FLOAT)
        window = np.frombuffer(buffer, np.float32).reshape(height, width)[::-1]
        camera = scene.main_camera_node.camera
        near, far = np.float32(camera.znear), np.float32(camera.zfar)
        # Window depth d in [0, 1] -> camera z = 2 n f / (f + n - (2 d - 1)(f - n)); 1: no hit.
        depth = (2 * near * far) / ((far + near) - (2 * window - 1) * (far - near))
        depth[window == 1.0] = 0.0
        if flags & pyrender.RenderFlags.DEPTH_ONLY:
            return depth
        buffer = GL.glReadPixels(0, 0, width, height, GL.GL_RGB, GL.GL_UNSIGNED_BYTE)
        return np.frombuffer(buffer, np.uint8).reshape(height, width, 3)[::-1], depth


def open_renderer(
    width: int, height: int, swaps: Mapping[str, Path], antialias: bool
) -> pyrender.OffscreenRenderer:
    """A new offscreen renderer (its own GL context) drawing with :class:`BodyRenderer`."""
    check_pyrender()
    offscreen = pyrender.OffscreenRenderer(width, height)
    offscreen._renderer = BodyRenderer(width, height, swaps, antialias)  # no GL state yet
    return offscreen


def close_renderer(offscreen: pyrender.OffscreenRenderer) -> None:
    """Release ``offscreen``'s GL context only; an EGL display stays initialised (point 3)."""
    platform = offscreen._platform
    if getattr(platform, "_egl_display", None) is None:
        offscreen.delete()  # a platform without a shared display (OSMesa)
        return
    from OpenGL.EGL import eglDestroyContext

    platform.make_current()
    offscreen._renderer.delete()
    eglDestroyContext(platform._egl_display, platform._egl_context)
    platform._egl_context = platform._egl_display = None
    offscreen._renderer = offscreen._platform = None
