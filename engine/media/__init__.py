"""Sound and pictures as the robot takes them in and gives them out, below speech and vision.

Audio clips (:mod:`~engine.media.audio`) and the ALSA devices that record and play them
(:mod:`~engine.media.audio_devices`); frames and picture files (:mod:`~engine.media.images`)
and the camera that grabs frames (:mod:`~engine.media.camera`); the check of a picture or a
video a person names (:mod:`~engine.media.media_check`). Speech, vision, the simulated vest
and scenarios build on these; nothing here knows about them.
"""
