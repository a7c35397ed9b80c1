"""ControllerPose's application side: datasets into examples (:mod:`.data`), the training
run (:mod:`.training`), the evaluation (:mod:`.evaluation`) and the device recordings the
synthesiser reads (:mod:`.recording`). The method itself is :mod:`synthesis.controllerpose`."""
