"""One account of every session: typed events, the stream that carries them, and the
producers that turn the blackboard's commits into events (:mod:`engine.session.events`)."""
