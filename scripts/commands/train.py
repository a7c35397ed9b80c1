"""``avatarsim train controllerpose --data DIR --out RUN``: train a method's model on a
generated dataset (scripts.controllerpose.training); ``avatarsim train kinect-tracker CONFIG
--out MODEL.npz``: train the Kinect body-part tracker on rendered depth
(render_cams.kinect.training)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from avatarsim.scripts.cli_common import (
    JsonOpt,
    SeedOpt,
    check_outputs,
    console,
    emit_json,
    make_app,
    user_errors,
)

OPTIONS = {"time_budget_s": "--time-budget", "use_vr": "--vr"}
"""Options whose name is not the config field's (``max_epochs`` is ``--max-epochs``)."""


def register(app: typer.Typer) -> None:
    group = make_app()
    group.info.help = "Train a method's model on a generated dataset."
    app.add_typer(group, name="train")

    @group.command()
    @user_errors
    def controllerpose(
        data: Annotated[Path, typer.Option(help="Dataset folder (avatarsim dataset generate).")],
        out: Annotated[Path, typer.Option(help="Run folder (resumed when it holds this run).")],
        max_epochs: Annotated[
            int, typer.Option(help="At most this many epochs (§4.3: 500).")
        ] = 500,
        patience: Annotated[
            int, typer.Option(help="Early stopping: epochs without a better validation loss.")
        ] = 6,
        time_budget: Annotated[
            float, typer.Option(help="Stop after the epoch that passes this many seconds.")
        ] = 1200.0,
        position_weight: Annotated[
            float,
            typer.Option(
                help="Weight of a position loss through FK (beyond the paper; 0: angles only)."
            ),
        ] = 0.0,
        vr: Annotated[
            bool, typer.Option(help="Use the 15 VR features (--no-vr: the §5.3 ablation).")
        ] = True,
        frame_stride: Annotated[
            int, typer.Option(help="Every k-th camera frame (30 Hz) of each sample.")
        ] = 3,
        width: Annotated[int, typer.Option(help="Trunk width.")] = 256,
        blocks: Annotated[int, typer.Option(help="Residual blocks.")] = 2,
        threads: Annotated[int, typer.Option(help="torch CPU threads.")] = 1,
        seed: SeedOpt = 0,
        json_out: JsonOpt = None,
    ) -> None:
        """Train the ControllerPose lifting network (§4.3) on CPU: curves in RUN/loss.png,
        checkpoint in RUN/checkpoint.pt (resumable), summary in RUN/train.json."""
        from avatarsim.avatar_models.errors import AvatarsimError
        from avatarsim.scripts.controllerpose.training import check_fits, run_training
        from avatarsim.synthesis.controllerpose.network import ConfigValueError, NetConfig
        from avatarsim.synthesis.controllerpose.train import TrainConfig

        for name, value in (("--max-epochs", max_epochs), ("--frame-stride", frame_stride)):
            if value < 1:
                raise AvatarsimError(f"{name} must be at least 1, got {value}")
        try:
            net = NetConfig(width=width, blocks=blocks, use_vr=vr)
            config = TrainConfig(
                max_epochs=max_epochs,
                patience=patience,
                position_weight=position_weight,
                time_budget_s=time_budget,
                seed=seed,
                threads=threads,
            )
        except ConfigValueError as exc:
            option = OPTIONS.get(exc.field, "--" + exc.field.replace("_", "-"))
            raise AvatarsimError(f"{option} {exc.reason}") from None
        check_fits(net, config)
        check_outputs(json_out=json_out, out=out)
        summary = run_training(data, out, net, config, frame_stride, console.print)
        best = summary["best_val"]
        console.print(
            f"{out}: {summary['epochs']} epochs in {summary['train_s']:.0f} s, best epoch "
            f"{summary['best_epoch']} (val angle mse {best['val_angle_mse']:.4g} rad², "
            f"position rmse {best['val_position_mse'] ** 0.5 * 100:.2f} cm)"
        )
        emit_json(json_out, summary)

    @group.command("kinect-tracker")
    @user_errors
    def kinect_tracker(
        config: Annotated[
            Path,
            typer.Argument(
                help="Training config (TOML), e.g. render_cams/kinect/models/kinect-tracker.toml."
            ),
        ],
        out: Annotated[Path, typer.Option(help="Model file to write (.npz).")],
        seed: Annotated[
            int | None, typer.Option("--seed", help="Overrides the config's seed.")
        ] = None,
        json_out: JsonOpt = None,
    ) -> None:
        """Train the Kinect body-part tracker (Shotton et al. 2011: depth features, a
        randomised forest, mean-shift joints) on depth frames rendered as CONFIG says; the
        model records the config, seed and a hash of the training data. An existing OUT is
        replaced only when this command wrote it."""
        import dataclasses
        import time

        from rich.progress import Progress

        from avatarsim.render_cams.kinect.training import (
            check_model_output,
            load_training_config,
            render_training_frames,
            train_tracker,
        )

        settings = load_training_config(config)
        if seed is not None:
            settings = dataclasses.replace(settings, seed=seed)
        check_model_output(out)
        check_outputs(json_out=json_out, files={"--out": out})
        start = time.perf_counter()
        with Progress(console=console, transient=True) as progress:
            task = progress.add_task("rendering training frames", total=None)
            data = render_training_frames(
                settings,
                progress=lambda done, total: progress.update(task, completed=done, total=total),
            )
            progress.update(task, description="fitting the forest")
            tracker = train_tracker(settings, data)
        tracker.save(out)
        summary = {
            "model": str(out),
            "config": str(config),
            "seed": settings.seed,
            "data_hash": tracker.meta["data_hash"],
            "frames": tracker.meta["frames"],
            "nodes": int(len(tracker.forest.feature)),
            "bytes": out.stat().st_size,
            "train_s": round(time.perf_counter() - start, 1),
        }
        console.print(
            f"{out}: {summary['frames']} frames, {summary['nodes']} nodes, "
            f"{summary['bytes'] / 1e6:.2f} MB in {summary['train_s']:.0f} s "
            f"(data hash {summary['data_hash']})"
        )
        emit_json(json_out, summary)
