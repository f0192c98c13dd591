"""The robot's speech and sight, assembled from its config, and what ``vest devices`` says
of them.

:mod:`~engine.robot_io.robot_speech` joins the microphone, the listener, the voice and the
speaker (the simulated room's on the simulated vest, ALSA devices on a robot);
:mod:`~engine.robot_io.robot_vision` and :mod:`~engine.robot_io.hand_watcher` join the
camera and the hand model. They stand above :mod:`engine.hardware` (whose config and device
health they read), :mod:`engine.speech`, :mod:`engine.vision` and :mod:`engine.sim`, which
know nothing of them.
"""
