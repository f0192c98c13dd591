"""The shared blackboard: a catalogue of known keys (``catalogue``), events (``events``),
and the board with its staged writes (``board``).

Producers in other threads *stage* writes; the scheduler commits them between ticks so
every tree in one tick sees one consistent snapshot. Import from the modules: the key
catalogue loads no py_trees (the cloud service reads it without the robot's code).
"""
