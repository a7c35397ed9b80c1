"""The MuJoCo model of a :class:`~avatar_models.body.description.BodyDescription`, built by
composition with :class:`mujoco.MjSpec` (:func:`body_spec`) and compiled once per body
(:attr:`BodyDescription.model`); :meth:`mujoco.MjSpec.to_xml` gives the MJCF text for
MuJoCo's viewer.

One MuJoCo body per simulated skeleton joint, named after the joint, at the joint's rest
offset (rest local rotations are the identity, so no body ``quat``). The root body carries a
free joint; every other body three hinges about its local x, y, z axes, declared in the
joint's Euler order so that ``R = R_a(q_a) R_b(q_b) R_c(q_c)`` (MuJoCo composes a body's
joints in declaration order) equals the skeleton's local rotation. Each hinge has its
anatomical range and a position actuator. A chain of joints that share one anatomical range
(:attr:`~avatar_models.body.description.BodyDescription.chains`: spine, neck) has that range
on each of its hinges and, per axis, a limited fixed tendon (:func:`chain_name`) whose length
is the sum of the chain's angles about that axis: the chain's total (to first order; exactly
for a bend about one axis) stays within the range however the rig distributes it over the
joints, while no single joint's share of it is fixed (physics can follow a rig that bends one
neck joint against the others).

Actuator gains: ``kp = 4 g m H / 2``, i.e. a load of mass ``m`` at half the stature ``H``
(about the height of the body's centre of mass) deflects the joint by at most a quarter
radian under gravity. ``m`` is what the joint carries when standing: the whole body for leg
joints (the toes too: the body rolls over them at push-off), the subtree below the joint
otherwise. ``kv = kp * 0.05 s`` (a 50 ms time constant), integrated implicitly
(``implicitfast``) so light distal segments stay stable.

Every number enters the spec rounded to the decimal digits the model has always been written
with (:func:`_decimal`: 9 significant digits, gains 6), so the compiled model is bit for bit
the one the MJCF text of earlier versions compiled to, and results stay reproducible.
"""

from __future__ import annotations

import mujoco
import numpy as np

from avatarsim.avatar_models.body.description import BodyDescription
from avatarsim.avatar_models.body.geometry import Segment, combined_inertial

GRAVITY = 9.81
STIFFNESS_MARGIN = 4.0
DAMPING_TIME_S = 0.05
TIMESTEP_S = 0.002
ARMATURE = 0.02
PLACEHOLDER_MASS_KG = 1e-4
PLACEHOLDER_INERTIA = 1e-8
LEG_ROLES = ("pelvic_girdle", "hip", "knee", "ankle", "toe")
AXIS_VECTORS = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
SEGMENT_RGBA = (0.8, 0.6, 0.45, 1.0)
TEXTURES = (
    ("grid", "2D", "CHECKER", 512, (0.2, 0.3, 0.4), (0.3, 0.4, 0.5)),
    ("sky", "SKYBOX", "GRADIENT", 256, (0.55, 0.65, 0.75), (0.1, 0.12, 0.15)),
)
"""Name, kind (``mjTEXTURE_*``), pattern (``mjBUILTIN_*``), size in pixels and two colours
of the floor's and the sky's textures."""
GEOM_SHAPES = {
    "capsule": mujoco.mjtGeom.mjGEOM_CAPSULE,
    "sphere": mujoco.mjtGeom.mjGEOM_SPHERE,
    "box": mujoco.mjtGeom.mjGEOM_BOX,
}


def hinge_name(joint_name: str, axis: str) -> str:
    """MuJoCo name of the hinge of skeleton joint ``joint_name`` about local ``axis``."""
    return f"{joint_name}:r{axis}"


def chain_name(joint_names, axis: str) -> str:
    """MuJoCo name of the fixed tendon summing a chain's hinges about ``axis``
    (``"Neck+Neck1+Head:ry"``)."""
    return f"{'+'.join(joint_names)}:r{axis}"


def body_spec(desc: BodyDescription) -> mujoco.MjSpec:
    """A new spec of ``desc``: floor, lights, the body, actuators, tendons, contact
    exclusions. The caller owns it (edit a :meth:`~mujoco.MjSpec.copy` of a shared one)."""
    spec = _spec_without_exclusions(desc)
    for a, b in _adjacent_bodies(desc, spec):
        spec.add_exclude(bodyname1=a, bodyname2=b)
    return spec


def _adjacent_bodies(desc: BodyDescription, spec: mujoco.MjSpec) -> list[tuple[str, str]]:
    """Body pairs of ``spec`` that must not collide, sorted: parent and child (ankle and toes
    included), and pairs whose geoms already touch in the rest pose (thighs at the crotch,
    bodies joined by zero-length bones).

    The touching pairs come from MuJoCo's own collision detection at the rest pose, which
    runs only on a compiled model: MuJoCo forces this one compile of a copy of ``spec`` (an
    own narrow phase for capsules, spheres and boxes would have to agree with MuJoCo's on
    every contact at zero distance)."""
    sk = desc.skeleton
    pairs = {(sk.names[int(sk.parents[j])], sk.names[int(j)]) for j in desc.simulated_joints[1:]}
    model = spec.copy().compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for c in data.contact[: data.ncon]:
        b1, b2 = model.geom_bodyid[c.geom1], model.geom_bodyid[c.geom2]
        if b1 and b2:
            pairs.add((model.body(b1).name, model.body(b2).name))
    return sorted(pairs)


def _decimal(values, digits: int = 9) -> list[float]:
    """``values`` flattened, each rounded to ``digits`` significant decimal digits (the
    module docstring says why)."""
    return [float(f"{float(v):.{digits}g}") for v in np.ravel(values)]


def _spec_without_exclusions(desc: BodyDescription) -> mujoco.MjSpec:
    sk = desc.skeleton
    spec = mujoco.MjSpec()
    spec.modelname = f"avatarsim_{sk.name or 'body'}"
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    spec.option.timestep = TIMESTEP_S
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    _set_defaults(spec)
    _add_scenery(spec)

    rest = sk.rest_positions()
    bodies: dict[int, mujoco.MjsBody] = {}
    for j in desc.simulated_joints:
        j = int(j)
        if j == 0:
            body = spec.worldbody.add_body(name=sk.names[0], pos=_decimal([0, 0, desc.root_height]))
            body.add_freejoint(name="root")
            # A light that follows the body, so renders keep a lit subject and its shadow
            # wherever it walks (the directional "sun" alone leaves it dark far from the origin).
            body.add_light(
                name="follow",
                mode=mujoco.mjtCamLight.mjCAMLIGHT_TRACKCOM,
                pos=[1.5, -1.5, 3.0],
                dir=[-0.4, 0.4, -1.0],
                diffuse=[0.6, 0.6, 0.6],
                castshadow=True,
            )
        else:
            body = bodies[int(sk.parents[j])].add_body(
                name=sk.names[j], pos=_decimal(sk.offsets[j])
            )
            _add_hinges(spec, desc, j, body)
        bodies[j] = body
        _add_inertial_and_geoms(desc, j, body)
    for name, j in desc.anatomy.body17.items():
        carrier = int(desc.anatomy.body_of[j])
        bodies[carrier].add_site(name=name, pos=_decimal(rest[j] - rest[carrier]))
    for chain in desc.chains:
        names = [sk.names[j] for j in chain]
        for axis, (lo, hi) in desc.hinge_ranges[chain[0]].items():
            tendon = spec.add_tendon(name=chain_name(names, axis), range=_decimal([lo, hi]))
            for name in names:
                tendon.wrap_joint(hinge_name(name, axis), 1.0)
    return spec


def _set_defaults(spec: mujoco.MjSpec) -> None:
    """Hinges with armature and limits; segment contact and colour; hidden body17 sites."""
    joint, geom, site = spec.default.joint, spec.default.geom, spec.default.site
    joint.type = mujoco.mjtJoint.mjJNT_HINGE
    joint.armature = ARMATURE
    joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
    geom.condim = 3
    geom.friction = [1.0, 0.005, 0.0001]
    geom.rgba = SEGMENT_RGBA
    site.size = [0.01, site.size[1], site.size[2]]
    site.rgba = [0.9, 0.1, 0.1, 1.0]
    site.group = 4


def _add_scenery(spec: mujoco.MjSpec) -> None:
    """The checkered floor, the sky and the sun."""
    for name, kind, pattern, size, rgb1, rgb2 in TEXTURES:
        spec.add_texture(
            name=name,
            type=getattr(mujoco.mjtTexture, f"mjTEXTURE_{kind}"),
            builtin=getattr(mujoco.mjtBuiltin, f"mjBUILTIN_{pattern}"),
            width=size,
            height=size,
            rgb1=rgb1,
            rgb2=rgb2,
        )
    material = spec.add_material(name="grid", texrepeat=[8.0, 8.0])
    material.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "grid"
    # A 1024 shadow map (MuJoCo's default is 4096) is plenty for the report's few-hundred-pixel
    # pictures and halves the software (llvmpipe) render time per frame.
    spec.visual.quality.shadowsize = 1024
    spec.worldbody.add_light(
        name="sun",
        pos=[0.0, 0.0, 5.0],
        dir=[0.0, 0.0, -1.0],
        type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
        diffuse=[0.4, 0.4, 0.4],
        castshadow=False,
    )
    spec.worldbody.add_geom(
        name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[0.0, 0.0, 0.05], material="grid"
    )


def _add_hinges(spec: mujoco.MjSpec, desc: BodyDescription, j: int, body: mujoco.MjsBody):
    role = desc.anatomy.roles[j]
    load = desc.mass_kg if role in LEG_ROLES else desc.subtree_mass[j]
    kp = STIFFNESS_MARGIN * GRAVITY * load * 0.5 * desc.stature
    (kp_6,), (kv_6,) = _decimal([kp], 6), _decimal([kp * DAMPING_TIME_S], 6)
    for axis in desc.hinge_order(j).lower():
        name = hinge_name(desc.skeleton.names[j], axis)
        limits = _decimal(desc.hinge_ranges[j][axis])
        body.add_joint(name=name, axis=AXIS_VECTORS[axis], range=limits)
        actuator = spec.add_actuator(
            name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT, ctrlrange=limits
        )
        actuator.set_to_position(kp=kp_6, kv=kv_6)


def _add_inertial_and_geoms(desc: BodyDescription, j: int, body: mujoco.MjsBody) -> None:
    segments = [s for s in desc.segments if s.body == j]
    body.explicitinertial = True
    if not segments:
        # A body at the end of a zero-length bone: MuJoCo needs some mass on every moving
        # body; its hinges still move the inertia of everything below.
        body.ipos = [0.0, 0.0, 0.0]
        body.mass = PLACEHOLDER_MASS_KG
        body.inertia = [PLACEHOLDER_INERTIA] * 3
        return
    mass, com, inertia = combined_inertial(segments)
    body.ipos = _decimal(com)
    body.mass = _decimal([mass])[0]
    body.fullinertia = _decimal(inertia[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]])
    for s in segments:
        _add_geom(body, s)


def _add_geom(body: mujoco.MjsBody, s: Segment) -> None:
    """The primitive of segment ``s`` on ``body``: a capsule from start to end, a sphere at
    start, a box at start turned by its heading about Z."""
    geom = body.add_geom(name=s.name, type=GEOM_SHAPES[s.shape])
    if s.shape == "capsule":
        geom.fromto = _decimal([s.start, s.end])
        geom.size = [_decimal([s.radius])[0], 0.0, 0.0]
    elif s.shape == "sphere":
        geom.pos = _decimal(s.start)
        geom.size = [_decimal([s.radius])[0], 0.0, 0.0]
    else:
        geom.pos = _decimal(s.start)
        geom.quat = _decimal([np.cos(s.heading / 2), 0.0, 0.0, np.sin(s.heading / 2)])
        geom.size = _decimal(s.half_extents)
