"""MoveBox (Gonzalez-Franco et al., "MoveBox: Democratizing MoCap for the Microsoft Rocketbox
Avatar Library", §III): Kinect V2 / Azure Kinect capture retargeted onto an avatar rig,
recording and playback, loops, masks, resizing, lip sync and blinking.

- :mod:`.mapping`: Kinect joints -> avatar bones. :mod:`.retarget`: q_absolute, roll
  (rest roll, hinge axes, or the sensor's), wrist stabilisation.
- :mod:`.confidence`: NotTracked held, Inferred blended, never seen at rest.
- :mod:`.smoothing`: exponential rotation smoothing onto the 90 Hz display clock.
- :mod:`.synthesizer`: the ``MoveBox`` method (registered as ``movebox``).
- :mod:`.resize`: the avatar sized to the user from head and foot joints.
- :mod:`.recording`: playback on another avatar, crop, loop, BVH/NPZ files.
- :mod:`.similarity`: the joint-comparison index, loop trimming.
- :mod:`.masks`: layers per bone set, composed. :mod:`.face`: lip sync, blinking.
- :mod:`.storytelling`: several takes staged in one scene, an MJCF scene of it.
"""

from avatarsim.synthesis.movebox.synthesizer import MoveBox, check_stream

__all__ = ["MoveBox", "check_stream"]
