"""One way to run and score a synthesis method: accuracy against the ground truth and speed.

Every caller that scores a method goes through :func:`score_run`: the scenario stage, the
accuracy protocols (:mod:`synthesis.evaluate`) and the benchmarks. The physics of a method's
output is not here (``sim`` and ``synthesis`` never import each other): ``scripts``
composes it on top of a :class:`MethodScore` (``scripts.method_score``).

Accuracy is measured as CoolMoves §4.1 measures it:

- Error: mean Euclidean distance (cm) between output and ground-truth ``body17`` joints,
  grouped as the paper groups them (hands; upper body = head, neck, arms; lower body =
  pelvis, legs, feet; full body), averaged over frames.
- Hand correlation: Pearson coefficient between the input and the output hands, "X, Y and Z
  positions of the hands as independent time series ... for the entire session", averaged
  over the three axes. We correlate head-relative positions (controller minus headset, the
  signal CoolMoves is given) so that walking forward cannot inflate the number. An axis along
  which the input hand does not move (standard deviation under ``STILL_AXIS_M``, e.g. the
  lateral axis of a generated ladder climb) has no defined coefficient and is left out of
  the mean; otherwise millimetre wobble of the output against a constant input reads as
  "no correlation".
- Both skip the first ``window - 1`` frames (89 ms), before the first full window exists,
  when any window-based method can only show a default pose.

Speed: the wall time of the batch ``run`` and, on request, the latency of every streaming
``step`` (what a VR frame budget is about).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from avatarsim.avatar_models import Motion, body17
from avatarsim.avatar_models.rigs import body17_positions
from avatarsim.render_cams import TrackingStream
from avatarsim.render_cams.device import motion_at_rate
from avatarsim.synthesis.base import (
    SynthesisError,
    Synthesizer,
    TrackingFrame,
    on_clock,
    usable_mask,
)
from avatarsim.synthesis.coolmoves.correlation import pearson
from avatarsim.synthesis.coolmoves.database import HANDS_DRIVE, Drivers, driver_positions
from avatarsim.synthesis.coolmoves.features import WINDOW_SAMPLES

WARM_UP = WINDOW_SAMPLES - 1
STILL_AXIS_M = 1e-3
"""An input hand axis with less spread than this (1 mm) does not move (our choice)."""
GROUPS = {
    "hands": body17.HANDS,
    "upper": body17.UPPER,
    "lower": body17.LOWER,
    "full": body17.BODY17,
}
"""The paper's joint groups, by body17 name."""


def body17_errors_cm(
    output: Motion, truth: Motion, skip: int = WARM_UP, frames: np.ndarray | None = None
) -> dict[str, float]:
    """Mean joint error in cm per group over the frames both motions have (at 90 Hz),
    after the first ``skip`` and, given ``frames`` (``(output.n_frames,)`` bool), only where
    it is True (NaN when no frame is left)."""
    truth = motion_at_rate(truth, output.fps)
    n = min(output.n_frames, truth.n_frames)
    err = np.linalg.norm(body17_positions(output)[:n] - body17_positions(truth)[:n], axis=-1)
    keep = np.arange(n) >= min(skip, n - 1)
    if frames is not None:
        keep &= np.asarray(frames, bool)[:n]
    if not keep.any():
        return {g: float("nan") for g in GROUPS}
    err = err[keep]
    per_joint = 100.0 * err.mean(axis=0)
    return {g: float(per_joint[body17.group_indices(names)].mean()) for g, names in GROUPS.items()}


def hand_correlation(
    output: Motion, stream: TrackingStream, drivers: Drivers = HANDS_DRIVE, skip: int = WARM_UP
) -> dict[str, float]:
    """Pearson correlation of input and output head-relative hands, mean over x, y, z."""
    clocked = on_clock(stream)
    idx = [clocked.device(d) for d in drivers.devices]
    ok = usable_mask(clocked)[:, idx].all(axis=1)
    n = min(output.n_frames, clocked.n_samples)
    ok = ok[:n].copy()
    ok[:skip] = False
    if ok.sum() < 3:
        raise SynthesisError(
            f"hand correlation needs at least 3 tracked frames after the first {skip} "
            f"(window warm-up); this stream has {int(ok.sum())}: use a longer clip"
        )
    given = clocked.positions[:n, idx[1:]] - clocked.positions[:n, idx[:1]]
    head, sides = driver_positions(output[:n], drivers)
    produced = sides - head[:, None]
    r = pearson(given[ok], produced[ok], axis=0)  # (2, 3)
    moving = np.std(given[ok], axis=0) >= STILL_AXIS_M
    mean = np.sum(r * moving, axis=1) / np.maximum(moving.sum(axis=1), 1)
    return {"left": float(mean[0]), "right": float(mean[1])}


def step_times_ms(synth: Synthesizer, stream: TrackingStream) -> tuple[np.ndarray, np.ndarray]:
    """Wall time and CPU time of this thread (ms) of each ``step`` over every sample of
    ``stream`` in order, ``(T,)`` each, after a ``reset``; the frames are built beforehand so
    that only ``step`` is timed. On a loaded machine the wall time also counts the waits for
    a core; the CPU time is what the step itself costs."""
    frames = [TrackingFrame.from_stream(stream, i) for i in range(stream.n_samples)]
    synth.reset()
    wall, cpu = np.empty(len(frames)), np.empty(len(frames))
    for i, frame in enumerate(frames):
        start, start_cpu = time.perf_counter_ns(), time.thread_time_ns()
        synth.step(frame)
        cpu[i] = time.thread_time_ns() - start_cpu
        wall[i] = time.perf_counter_ns() - start
    return 1e-6 * wall, 1e-6 * cpu


def step_latencies_ms(synth: Synthesizer, stream: TrackingStream) -> np.ndarray:
    """Wall time (ms) of each ``step`` over every sample of ``stream`` in order ``(T,)``
    (:func:`step_times_ms`)."""
    return step_times_ms(synth, stream)[0]


@dataclass(frozen=True, eq=False)
class MethodScore:
    """One method's run on one ground-truth motion, scored.

    Attributes:
        method: the synthesiser's name. output: its motion (one frame per clock tick).
        err_cm: mean body17 error per group (``hands``, ``upper``, ``lower``, ``full``).
        hand_corr: input-output hand correlation (``left``, ``right``).
        seconds: wall time of the batch ``run``.
        step_ms: ``(T,)`` latency of each streaming ``step``, when measured.
    """

    method: str
    output: Motion
    err_cm: dict[str, float]
    hand_corr: dict[str, float]
    seconds: float
    step_ms: np.ndarray | None = None

    @property
    def frames(self) -> int:
        return self.output.n_frames

    def row(self) -> dict:
        """The JSON-ready numbers: ``err_cm``, ``hand_corr``, ``frames``, ``seconds`` and,
        when steps were timed, ``step_ms_p50`` and ``step_ms_p99``."""
        out = {
            "err_cm": self.err_cm,
            "hand_corr": self.hand_corr,
            "frames": self.frames,
            "seconds": self.seconds,
        }
        if self.step_ms is not None:
            out["step_ms_p50"] = float(np.percentile(self.step_ms, 50))
            out["step_ms_p99"] = float(np.percentile(self.step_ms, 99))
        return out


def score_run(
    synth: Synthesizer, truth: Motion, stream: TrackingStream, time_steps: bool = False
) -> MethodScore:
    """Run ``synth`` on ``stream`` (sampled from ``truth``) and score its output against
    ``truth``; ``time_steps`` also times a streaming pass (:func:`step_latencies_ms`)."""
    start = time.perf_counter()
    output = synth.run(stream)
    seconds = time.perf_counter() - start
    return MethodScore(
        synth.name,
        output,
        body17_errors_cm(output, truth),
        hand_correlation(output, stream),
        seconds,
        step_latencies_ms(synth, stream) if time_steps else None,
    )
