"""The simulated vest: register-level models of the vest's chips behind real bus interfaces.

Each model takes its register map from the chip's driver side
(``engine/drivers/<chip>_registers.py``), so the model and the driver cannot disagree on
an address or a bit; the room, the camera and the Maestro emulator are here too. Nothing
in :mod:`engine.drivers` imports this package.
"""
