"""Fisheye cameras on the VR controllers (ControllerPose §4): model, rendering, rig, keypoints,
bad frames, calibration, stitching, records and sequences; one concept per module."""
