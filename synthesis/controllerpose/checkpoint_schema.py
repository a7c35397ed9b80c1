"""The schema of a ControllerPose checkpoint file, checked before anything in it is used.

A checkpoint is data that users pass to each other, so it is read as untrusted input: the
file is unpickled by torch's ``weights_only`` unpickler (tensors and plain Python data only;
no object is constructed from the file, no code runs), and then every field is checked here:

- ``format`` and ``layout`` (:data:`~.features.LAYOUT`) are this version's;
- ``net``: a :class:`~.network.NetConfig` (types and ranges);
- ``best_weights`` (and ``resume["weights"]``): exactly the tensors of the network that
  ``net`` builds, by name, shape and dtype, all finite. The network is built on torch's
  ``meta`` device (no memory), and only after the stored tensors' total size matches
  :meth:`~.network.NetConfig.state_size`, so a config of absurd sizes costs nothing;
- ``normaliser``: four float tensors shaped by the layout, finite, deviations positive;
- ``template_lengths``: ``(17,)``, finite and not negative;
- ``resume``: empty (an untrained checkpoint) or the weights, Adam's state (one moment pair
  shaped like each parameter) and the learning-rate schedule's, with the early-stopping
  counters.

Any departure raises :class:`CheckpointError` naming the file and the field.
"""

from __future__ import annotations

import math
from numbers import Integral, Real
from pathlib import Path
from typing import Any

import torch

from avatarsim.avatar_models import AvatarsimError
from avatarsim.avatar_models.body17 import BODY17
from avatarsim.synthesis.controllerpose.features import LAYOUT
from avatarsim.synthesis.controllerpose.network import ConfigValueError, LiftingNet, NetConfig

FORMAT = 2
"""Version of the file's payload. 1 stored numpy arrays, which only a full unpickler reads."""

RESUME_COUNTERS = {"best_val": Real, "bad_epochs": Integral, "elapsed_s": Real}


class CheckpointError(AvatarsimError, ValueError):
    """A checkpoint that is missing, unreadable, from another feature layout, or whose
    content does not match its schema (module docstring)."""


class _Field:
    """Where in the file a value is, for the error message."""

    def __init__(self, path: Path, name: str) -> None:
        self.path, self.name = path, name

    def __truediv__(self, key: object) -> _Field:
        return _Field(self.path, f"{self.name}[{key!r}]" if self.name else str(key))

    def fail(self, reason: str) -> CheckpointError:
        return CheckpointError(f"{self.path}: {self.name}: {reason}")


def _dict(value: Any, where: _Field) -> dict:
    if not isinstance(value, dict):
        raise where.fail(f"must be a mapping, got {type(value).__name__}")
    return value


def _number(value: Any, where: _Field, kind: type = Real, minimum: float = -math.inf) -> Any:
    if isinstance(value, bool) or not isinstance(value, kind):
        raise where.fail(f"must be a{'n integer' if kind is Integral else ' number'}: {value!r}")
    if not (math.isfinite(value) and value >= minimum):
        raise where.fail(f"must be finite and at least {minimum:g}, got {value}")
    return value


def _finite(tensor: torch.Tensor, where: _Field) -> None:
    if tensor.is_floating_point() and not bool(torch.isfinite(tensor).all()):
        bad = int((~torch.isfinite(tensor)).sum())
        raise where.fail(f"{bad} non-finite value(s) (NaN or inf); the model is unusable")


def _tensor(value: Any, where: _Field, shape: tuple[int, ...]) -> torch.Tensor:
    if not isinstance(value, torch.Tensor) or not value.is_floating_point():
        raise where.fail(f"must be a float tensor, got {type(value).__name__}")
    if tuple(value.shape) != shape:
        raise where.fail(f"shape {tuple(value.shape)}, expected {shape}")
    _finite(value, where)
    return value


def net_config(value: Any, where: _Field) -> NetConfig:
    fields = _dict(value, where)
    try:
        return NetConfig(**{str(k): v for k, v in fields.items()})
    except TypeError as exc:  # an unknown or missing field
        raise where.fail(str(exc).removeprefix("NetConfig.__init__() ")) from None
    except ConfigValueError as exc:
        raise (where / exc.field).fail(exc.reason) from None


def meta_net(net: NetConfig) -> LiftingNet:
    """``LiftingNet(net)`` on the ``meta`` device: names, shapes and dtypes, no memory."""
    with torch.device("meta"):
        return LiftingNet(net)


def weights(value: Any, net: NetConfig, where: _Field) -> dict[str, torch.Tensor]:
    """``value`` as the state dict of ``net``'s network, checked (module docstring)."""
    stored = _dict(value, where)
    for name, tensor in stored.items():
        if not isinstance(tensor, torch.Tensor):
            raise (where / name).fail(f"must be a tensor, got {type(tensor).__name__}")
    size = sum(t.numel() for t in stored.values())
    if size != net.state_size():
        raise where.fail(
            f"{size} numbers in {len(stored)} tensors, but the network of this checkpoint's "
            f"net config ({net}) has {net.state_size()}: the weights belong to another network"
        )
    expected = meta_net(net).state_dict()
    for name in sorted(set(expected) - set(stored)):
        raise (where / name).fail("missing (a layer of the network that the file lacks)")
    for name in sorted(set(stored) - set(expected)):
        raise (where / name).fail("not a layer of this network")
    for name, tensor in stored.items():
        want = expected[name]
        if tuple(tensor.shape) != tuple(want.shape) or tensor.dtype != want.dtype:
            raise (where / name).fail(
                f"layer {name} is {tensor.dtype} {tuple(tensor.shape)}, the network ({net}) "
                f"has {want.dtype} {tuple(want.shape)}"
            )
        _finite(tensor, where / name)
    return stored


def _adam_state(value: Any, net: NetConfig, where: _Field) -> dict:
    """Adam's ``state_dict()``: one parameter group over every parameter, each parameter's
    moments shaped like it."""
    state = _dict(value, where)
    shapes = [tuple(p.shape) for p in meta_net(net).parameters()]
    groups = state.get("param_groups")
    if not isinstance(groups, list) or len(groups) != 1 or not isinstance(groups[0], dict):
        raise (where / "param_groups").fail("must be a list of one parameter group")
    if groups[0].get("params") != list(range(len(shapes))):
        raise (where / "param_groups").fail(f"must cover the {len(shapes)} parameters in order")
    moments = _dict(state.get("state"), where / "state")
    for index, entry in moments.items():
        if not isinstance(index, int) or not 0 <= index < len(shapes):
            raise (where / "state" / index).fail("not a parameter of this network")
        entry = _dict(entry, where / "state" / index)
        for key in ("exp_avg", "exp_avg_sq"):
            _tensor(entry.get(key), where / "state" / index / key, shapes[index])
        step = entry.get("step")
        if not isinstance(step, torch.Tensor) or step.numel() != 1:
            raise (where / "state" / index / "step").fail("must be a one-number tensor")
    return state


def _schedule_state(value: Any, where: _Field) -> dict:
    """A ``LambdaLR`` ``state_dict()``: the keys a fresh one has, each of the same kind (its
    ``load_state_dict`` sets them as attributes)."""
    state = _dict(value, where)
    optimiser = torch.optim.Adam([torch.nn.Parameter(torch.zeros(1))])
    fresh = torch.optim.lr_scheduler.LambdaLR(optimiser, lambda step: 1.0).state_dict()
    if set(state) != set(fresh):
        raise where.fail(f"keys {sorted(state)}, expected {sorted(fresh)}")
    for key, reference in fresh.items():
        if isinstance(reference, list | tuple) != isinstance(state[key], list | tuple) or (
            isinstance(reference, Real) and not isinstance(state[key], Real)
        ):
            raise (where / key).fail(f"must be like {reference!r}, got {state[key]!r}")
    return state


def resume_state(value: Any, net: NetConfig, where: _Field) -> dict[str, Any]:
    resume = _dict(value, where)
    if not resume:
        return resume
    for key, kind in RESUME_COUNTERS.items():
        _number(resume.get(key), where / key, kind, 0.0)
    weights(resume.get("weights"), net, where / "weights")
    _adam_state(resume.get("optimiser"), net, where / "optimiser")
    _schedule_state(resume.get("schedule"), where / "schedule")
    return resume


def history(value: Any, where: _Field) -> list[dict[str, float]]:
    if not isinstance(value, list):
        raise where.fail(f"must be a list, got {type(value).__name__}")
    for k, record in enumerate(value):
        for key, number in _dict(record, where / k).items():
            if isinstance(number, bool) or not isinstance(number, Real):
                raise (where / k / key).fail(f"must be a number, got {number!r}")
    return value


def check_payload(payload: Any, path: Path) -> dict[str, Any]:
    """The checked payload of the checkpoint file ``path`` (module docstring), with ``net``
    as a :class:`NetConfig`.

    Raises:
        CheckpointError: naming the field that does not match.
    """
    root = _Field(path, "")
    if not isinstance(payload, dict) or payload.get("layout") != LAYOUT:
        found = payload.get("layout") if isinstance(payload, dict) else None
        raise CheckpointError(
            f"{path}: feature layout {found} is not this version's {LAYOUT}; retrain with "
            "avatarsim train controllerpose"
        )
    if payload.get("format") != FORMAT:
        raise (root / "format").fail(
            f"{payload.get('format')!r}, this avatarsim reads {FORMAT}; retrain with "
            "avatarsim train controllerpose"
        )
    net = net_config(payload.get("net"), root / "net")
    slots = (LAYOUT["skeleton_slots"], LAYOUT["per_skeleton"])
    shapes = {
        "skeleton_mean": slots,
        "skeleton_std": slots,
        "vr_mean": (LAYOUT["vr_features"],),
        "vr_std": (LAYOUT["vr_features"],),
    }
    normaliser = _dict(payload.get("normaliser"), root / "normaliser")
    if set(normaliser) != set(shapes):
        raise (root / "normaliser").fail(f"keys {sorted(normaliser)}, expected {sorted(shapes)}")
    for key, shape in shapes.items():
        tensor = _tensor(normaliser[key], root / "normaliser" / key, shape)
        if key.endswith("_std") and not bool((tensor > 0).all()):
            raise (root / "normaliser" / key).fail("deviations must be positive")
    lengths = _tensor(payload.get("template_lengths"), root / "template_lengths", (len(BODY17),))
    if bool((lengths < 0).any()):
        raise (root / "template_lengths").fail("bone lengths must not be negative")
    if not isinstance(payload.get("manifest_sha256"), str):
        raise (root / "manifest_sha256").fail("must be a string")
    _dict(payload.get("train"), root / "train")
    _number(payload.get("epoch"), root / "epoch", Integral, 0)
    return {
        **payload,
        "net": net,
        "best_weights": weights(payload.get("best_weights"), net, root / "best_weights"),
        "history": history(payload.get("history"), root / "history"),
        "resume": resume_state(payload.get("resume"), net, root / "resume"),
    }
