"""Teaching the hand model: synthetic pictures of hands in rooms, data sets, the network,
its training and its evaluation (``vest gesture train``, ``scripts/train-hand-model``).

Apart from :mod:`engine.vision`, which only reads frames with a trained model, so the robot
loads none of this; the simulated camera draws its hands with :mod:`synthetic_hands`.
"""
