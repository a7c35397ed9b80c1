"""MoveBox (Gonzalez-Franco et al., "MoveBox: Democratizing MoCap for the Microsoft Rocketbox
Avatar Library", §III): Kinect V2 / Azure Kinect capture retargeted onto an avatar rig,
recording and playback, loops, masks, resizing, lip sync and blinking.

- :mod:`.mapping`: Kinect joints -> avatar bones. :mod:`.retarget`: q_absolute, roll.
- :mod:`.confidence`: NotTracked / Inferred. :mod:`.smoothing`: exponential, 30 -> 90 Hz.
- :mod:`.synthesizer`: the ``MoveBox`` method.
"""

from synthesis.movebox.synthesizer import MoveBox, check_stream

__all__ = ["MoveBox", "check_stream"]
