"""Dialogs: what the robot hears and answers, written in YAML by therapists."""

from engine.dialogs.library import DialogLibrary
from engine.dialogs.model import Dialog, DialogRule, Match

__all__ = ["Dialog", "DialogLibrary", "DialogRule", "Match"]
