"""The robot's speech: audio, voice activity, recognition and voices.

microphone -> :mod:`vad` (Silero) -> :mod:`recognizer` (Whisper biased by the dialogs)
-> dialog matcher; answers -> :mod:`voices` (the Piper-format neural voice, or espeak-ng)
-> speaker. Audio clips and devices live in :mod:`engine.media`.
"""
