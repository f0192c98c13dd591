"""The composition root: the one place that builds a whole running robot from its plan
(:func:`~engine.composition.session_root.build_session`)."""
