"""The shared blackboard: a catalogue of known keys, events, and staged writes.

Producers in other threads *stage* writes; the scheduler commits them between ticks so
every tree in one tick sees one consistent snapshot.
"""

from engine.blackboard.board import Blackboard
from engine.blackboard.catalogue import KeyCatalogue, KeySpec, default_catalogue
from engine.blackboard.events import Event, EventLog

__all__ = ["Blackboard", "Event", "EventLog", "KeyCatalogue", "KeySpec", "default_catalogue"]
