"""CoolMoves' accuracy evaluation (§4.1): cross-subject and cross-trial protocols per class,
with the IK baseline side by side, hand correlation, the ablation and throughput.

One concept per module: :mod:`.trials` (labelled ground-truth motions, from the generator or
a mocap folder), :mod:`.folds` (the protocols' leave-one-group-out folds and each fold's
database) and :mod:`.protocol` (running and aggregating them). Scoring a run is
:func:`synthesis.scoring.score_run`, shared with the scenarios and the benchmarks.
"""

from avatarsim.synthesis.evaluate.folds import PROTOCOLS, Fold, database_for, folds
from avatarsim.synthesis.evaluate.protocol import (
    ABLATION,
    EVALUABLE,
    PAPER,
    evaluate_fold,
    ik_baseline_for,
    ik_rig_for,
    run_protocol,
    summarise,
)
from avatarsim.synthesis.evaluate.trials import (
    PAPER_ACTIVITIES,
    TAKE_VARIATION,
    EvaluationError,
    Trial,
    builtin_trials,
    library_trials,
    turned,
)

__all__ = [
    "ABLATION",
    "EVALUABLE",
    "PAPER",
    "PAPER_ACTIVITIES",
    "PROTOCOLS",
    "TAKE_VARIATION",
    "EvaluationError",
    "Fold",
    "Trial",
    "builtin_trials",
    "database_for",
    "evaluate_fold",
    "folds",
    "ik_baseline_for",
    "ik_rig_for",
    "library_trials",
    "run_protocol",
    "summarise",
    "turned",
]
