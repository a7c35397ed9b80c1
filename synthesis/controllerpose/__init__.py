"""ControllerPose (Ahuja et al., UIST 2022): inside-out body capture with VR controller
cameras. The camera side (fisheye, compositing, 2D keypoints) is :mod:`render_cams.fisheye`;
this package lifts the keypoints plus the VR stream to a full body (§4.3).

One concept per module: :mod:`.features` (§4.3's input vector), :mod:`.examples` (recordings
into training examples), :mod:`.normaliser`, :mod:`.network` (the multi-input MLP),
:mod:`.fk` (the differentiable FK layer over :mod:`avatar_models.body17_angles`),
:mod:`.train`, :mod:`.checkpoint`, :mod:`.evaluate` (§5.3's normalised errors, the
nearest-neighbour baseline) and :mod:`.synthesizer` (the method, with IK and foot grounding).
"""
