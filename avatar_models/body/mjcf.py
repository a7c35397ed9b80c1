"""MJCF of a :class:`~avatar_models.body.description.BodyDescription`, built with ElementTree.

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
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import mujoco
import numpy as np

from avatar_models.body.description import BodyDescription
from avatar_models.body.geometry import combined_inertial

GRAVITY = 9.81
STIFFNESS_MARGIN = 4.0
DAMPING_TIME_S = 0.05
TIMESTEP_S = 0.002
ARMATURE = 0.02
PLACEHOLDER_MASS_KG = 1e-4
LEG_ROLES = ("pelvic_girdle", "hip", "knee", "ankle", "toe")
AXIS_VECTORS = {"x": "1 0 0", "y": "0 1 0", "z": "0 0 1"}
SEGMENT_RGBA = "0.8 0.6 0.45 1"


def hinge_name(joint_name: str, axis: str) -> str:
    """MuJoCo name of the hinge of skeleton joint ``joint_name`` about local ``axis``."""
    return f"{joint_name}:r{axis}"


def chain_name(joint_names, axis: str) -> str:
    """MuJoCo name of the fixed tendon summing a chain's hinges about ``axis``
    (``"Neck+Neck1+Head:ry"``)."""
    return f"{'+'.join(joint_names)}:r{axis}"


def body_mjcf(desc: BodyDescription) -> str:
    """The MJCF XML string: floor, light, the body, actuators, contact exclusions."""
    root = _model_without_exclusions(desc)
    contact = ET.SubElement(root, "contact")
    for a, b in _adjacent_bodies(desc, ET.tostring(root, encoding="unicode")):
        ET.SubElement(contact, "exclude", body1=a, body2=b)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode")


def _fmt(values) -> str:
    return " ".join(f"{float(v):.9g}" for v in np.ravel(values))


def _model_without_exclusions(desc: BodyDescription) -> ET.Element:
    sk = desc.skeleton
    root = ET.Element("mujoco", model=f"avatarsim_{sk.name or 'body'}")
    ET.SubElement(root, "compiler", angle="radian", autolimits="true")
    ET.SubElement(root, "option", timestep=str(TIMESTEP_S), integrator="implicitfast")
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "joint", type="hinge", armature=str(ARMATURE), limited="true")
    ET.SubElement(default, "geom", condim="3", friction="1 0.005 0.0001", rgba=SEGMENT_RGBA)
    ET.SubElement(default, "site", size="0.01", rgba="0.9 0.1 0.1 1", group="4")
    asset = ET.SubElement(root, "asset")
    ET.SubElement(
        asset,
        "texture",
        name="grid",
        type="2d",
        builtin="checker",
        width="512",
        height="512",
        rgb1="0.2 0.3 0.4",
        rgb2="0.3 0.4 0.5",
    )
    ET.SubElement(asset, "material", name="grid", texture="grid", texrepeat="8 8")
    ET.SubElement(
        asset,
        "texture",
        name="sky",
        type="skybox",
        builtin="gradient",
        width="256",
        height="256",
        rgb1="0.55 0.65 0.75",
        rgb2="0.1 0.12 0.15",
    )
    # A 1024 shadow map (MuJoCo's default is 4096) is plenty for the report's few-hundred-pixel
    # pictures and halves the software (llvmpipe) render time per frame.
    ET.SubElement(ET.SubElement(root, "visual"), "quality", shadowsize="1024")
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(
        world,
        "light",
        name="sun",
        pos="0 0 5",
        dir="0 0 -1",
        directional="true",
        diffuse="0.4 0.4 0.4",
        castshadow="false",
    )
    ET.SubElement(world, "geom", name="floor", type="plane", size="0 0 0.05", material="grid")

    rest = sk.rest_positions()
    bodies: dict[int, ET.Element] = {}
    actuator = ET.Element("actuator")
    for j in desc.simulated_joints:
        j = int(j)
        if j == 0:
            body = ET.SubElement(
                world, "body", name=sk.names[0], pos=_fmt([0, 0, desc.root_height])
            )
            ET.SubElement(body, "freejoint", name="root")
            # A light that follows the body, so renders keep a lit subject and its shadow
            # wherever it walks (the directional "sun" alone leaves it dark far from the origin).
            ET.SubElement(
                body,
                "light",
                name="follow",
                mode="trackcom",
                pos="1.5 -1.5 3",
                dir="-0.4 0.4 -1",
                diffuse="0.6 0.6 0.6",
                castshadow="true",
            )
        else:
            body = ET.SubElement(
                bodies[int(sk.parents[j])], "body", name=sk.names[j], pos=_fmt(sk.offsets[j])
            )
            _add_hinges(desc, j, body, actuator)
        bodies[j] = body
        _add_inertial_and_geoms(desc, j, body)
    for name, j in desc.anatomy.body17.items():
        carrier = int(desc.anatomy.body_of[j])
        ET.SubElement(bodies[carrier], "site", name=name, pos=_fmt(rest[j] - rest[carrier]))
    if desc.chains:
        tendon = ET.SubElement(root, "tendon")
        for chain in desc.chains:
            names = [sk.names[j] for j in chain]
            for axis, (lo, hi) in desc.hinge_ranges[chain[0]].items():
                fixed = ET.SubElement(
                    tendon, "fixed", name=chain_name(names, axis), range=_fmt([lo, hi])
                )
                for name in names:
                    ET.SubElement(fixed, "joint", joint=hinge_name(name, axis), coef="1")
    root.append(actuator)
    return root


def _add_hinges(desc: BodyDescription, j: int, body: ET.Element, actuator: ET.Element) -> None:
    role = desc.anatomy.roles[j]
    load = desc.mass_kg if role in LEG_ROLES else desc.subtree_mass[j]
    kp = STIFFNESS_MARGIN * GRAVITY * load * 0.5 * desc.stature
    for axis in desc.hinge_order(j).lower():
        name = hinge_name(desc.skeleton.names[j], axis)
        lo, hi = desc.hinge_ranges[j][axis]
        ET.SubElement(body, "joint", name=name, axis=AXIS_VECTORS[axis], range=_fmt([lo, hi]))
        ET.SubElement(
            actuator,
            "position",
            name=name,
            joint=name,
            kp=f"{kp:.6g}",
            kv=f"{kp * DAMPING_TIME_S:.6g}",
            ctrlrange=_fmt([lo, hi]),
        )


def _add_inertial_and_geoms(desc: BodyDescription, j: int, body: ET.Element) -> None:
    segments = [s for s in desc.segments if s.body == j]
    if not segments:
        # A body at the end of a zero-length bone: MuJoCo needs some mass on every moving
        # body; its hinges still move the inertia of everything below.
        ET.SubElement(
            body,
            "inertial",
            pos="0 0 0",
            mass=str(PLACEHOLDER_MASS_KG),
            diaginertia="1e-8 1e-8 1e-8",
        )
        return
    mass, com, inertia = combined_inertial(segments)
    full = [
        inertia[0, 0],
        inertia[1, 1],
        inertia[2, 2],
        inertia[0, 1],
        inertia[0, 2],
        inertia[1, 2],
    ]
    ET.SubElement(body, "inertial", pos=_fmt(com), mass=f"{mass:.9g}", fullinertia=_fmt(full))
    for s in segments:
        if s.shape == "capsule":
            ET.SubElement(
                body,
                "geom",
                name=s.name,
                type="capsule",
                fromto=_fmt([s.start, s.end]),
                size=f"{s.radius:.9g}",
            )
        elif s.shape == "sphere":
            ET.SubElement(
                body, "geom", name=s.name, type="sphere", pos=_fmt(s.start), size=f"{s.radius:.9g}"
            )
        else:
            quat = [np.cos(s.heading / 2), 0.0, 0.0, np.sin(s.heading / 2)]
            ET.SubElement(
                body,
                "geom",
                name=s.name,
                type="box",
                pos=_fmt(s.start),
                quat=_fmt(quat),
                size=_fmt(s.half_extents),
            )


def _adjacent_bodies(desc: BodyDescription, xml: str) -> list[tuple[str, str]]:
    """Body pairs that must not collide: parent and child (ankle and toes included), and pairs
    whose geoms already touch in the rest pose (thighs at the crotch, bodies joined by
    zero-length bones)."""
    sk = desc.skeleton
    pairs = {(sk.names[int(sk.parents[j])], sk.names[int(j)]) for j in desc.simulated_joints[1:]}
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for c in data.contact[: data.ncon]:
        b1, b2 = model.geom_bodyid[c.geom1], model.geom_bodyid[c.geom2]
        if b1 and b2:
            pairs.add((model.body(b1).name, model.body(b2).name))
    return sorted(pairs)
