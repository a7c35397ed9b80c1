"""Fisheye cameras on the VR controllers (ControllerPose §4): model, rendering, rig, keypoints,
bad frames, calibration, stitching, records; :mod:`.device` (the ``FisheyeRig`` device) and
:mod:`.sequence` (a recording on disk); one concept per module. Nothing is imported here, so
that the camera model and geometry load without pyrender."""
